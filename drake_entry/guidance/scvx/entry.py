"""The entry problem of paper 001 as a ``ConvexifiableProblem``: free final time, the four
control formulations of its Table 3, the objectives of its Table 2, path and DRS constraints,
Lobatto segment discretisation.

Formulations (``FORMULATIONS``):
  'lossless'    states (h, lon, lat, V, gamma, psi); controls u = (u1, u2) = (cos, sin) of the
                bank relaxed to |u| <= 1 (eqs. 37-45); alpha(V) from the mission's law.
  'hybrid'      lossless bank, alpha a state with its rate a control (eqs. 56-57).
  'direct_bank' sigma a state, its rate the control (eqs. 34-36); alpha(V).
  'direct'      sigma and alpha states, their rates the controls (eqs. 54-55): the form of the
                paper's Tables 2 and 4-7.
With the bank a state the flown bank is exactly the planned one (no lossless gap) and its rate
is bounded (eq. 36, vehicle ``bank_rate_limit``); |sigma| >= sigma_min (eq. 43) is not imposed
there (a non-convex set), as in the paper.

Decision vector z (scaled): the states x_k (``n_x`` per node), the controls u_k (``n_u``),
t_f / 1000 s, then the objective's epigraph variables, if any. Normalised time s in [0, 1]
with dx/ds = t_f f(x, u) (time dilation). The dynamics are the project's one set of equations
(``dynamics.equations_of_motion_lift_components``, paper 001 eqs. 1-7 with 40-41); their
Jacobians come from AutoDiff of that code, never a second copy.

Defects: on each segment of a ``SegmentMesh`` (Lobatto IIIA, ``nodes_per_segment`` LGL
nodes; 2 nodes per segment is the paper's trapezoid, Sec. IV.B),
    x_j - x_0 - sum_k I[j, k] t_f f(x_k, u_k) = 0.

Constraints: control bounds (eqs. 36, 43-44, hard), |u| <= 1 (eq. 42, hard cone, lossless);
buffered (eq. 24) at every node: heat flux <= q_max (eq. 9), total load <= n_max (eq. 10), or
the normal load (paper 000 eq. 35) for a vehicle that limits only that, dynamic pressure <=
the vehicle's limit where it states one (paper 000 eq. 34; inactive rows otherwise) (all less
the settings' path_margin),
flight-path bounds (eq. 70); at the DRS point: geodetic altitude window (eq. 64, narrowed by
the mission's final_altitude_margin_m), M_min a <= V <= M a
(eq. 64; M_min 0 in paper 001, a TAEM box's lower Mach otherwise), V sin(gamma) >= V_v,min (eq. 65, linearised as eq. 66)
and, where the mission sets one, V sin(gamma) <= V_v,max (not in paper 001: a glide's final
descent made definite, so that the flight's altitude stop falls where the plan ends), and a cone ||miss|| <= site radius (eq. 69)
with a buffer. Hard bounds on the other states (eq. 70) and the fixed entry state.

Objectives (paper 001 Table 2, ``OBJECTIVES``; the min-max ones through an epigraph variable
mu with mu >= f_k at every node): 'heat_load' (integral of q dt), 'control_effort' (integral of
the rate norm |(sigma_dot, alpha_dot)| dt, a cone per node), 'max_control_rate' (max of that
norm), 'max_flight_path_rate' (max |gamma_dot|), 'max_heat_flux', 'max_load', 'time' (t_f),
'miss' (DRS distance to the site, a cone). With the lossless bank the heading regulariser
lambda_chi integral chi dt (eq. 45) drives |u| to 1; its sign follows the geometry
(``heading_regulariser_sign``). The regulariser does not always close the gap 1 - |u| (0.1-0.2
on the nominal mission where gamma or q bind, and a gap is lift the real bank cannot dump):
``max_lossless_gap`` (< 1) adds the non-convex floor |u_k| >= 1 - gap at every node as a
buffered inequality, linearised each iteration to u_bar . u / |u_bar| >= 1 - gap (an inner
approximation: |u| is convex, so it lies above its tangent); the heading regulariser is then
not needed and is off. ``lossless_rate_limit`` bounds the bank's turn between nodes by the
vehicle's rate limit, |u_k+1 - u_k| <= sigma_dot_max (s_k+1 - s_k) t_f (a chord of the unit
circle is shorter than its arc: convex, a cone per node pair, buffered): the relaxed bank
otherwise reverses within one node interval, where the flown bank (atan2 of the interpolated
u) passes through the lift-up direction the plan never saw.
"""
from __future__ import annotations

import functools
import math

import numpy as np
import scipy.sparse as sp
from pydrake.autodiffutils import AutoDiffXd, ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.symbolic import Expression, Variable, uninterpreted_function

from drake_entry.errors import ScenarioError, UnsupportedScalarError
from drake_entry.guidance.scvx.engine import ConvexifiableProblem, Evaluation, Linearisation
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.settings import (
    FORMULATIONS,
    RATE_OBJECTIVES,
    EntryProblemSettings,
)
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.constraints import dynamic_pressure, signed_normal_load_factor, total_load_factor
from drake_entry.models.dynamics import STATE_NAMES, aero_accelerations, air_data, equations_of_motion_lift_components
from drake_entry.models.expression_tape import ExpressionTape, TracedAtmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.scalar import is_symbolic, lift, value_of
from drake_entry.models.vehicles import Vehicle
from drake_entry.planning.pseudospectral import SegmentMesh

__all__ = ["POSITION_SCALE", "SIGMA_SCALE", "ALPHA_SCALE", "SIGMA_RATE_SCALE", "ALPHA_RATE_SCALE", "TIME_SCALE",
           "HEAT_LOAD_SCALE", "GAMMA_RATE_SCALE", "MISS_SCALE", "PATH_NAMES", "EVENT_NAMES",
           "heading_regulariser_sign", "EntryProblem"]

POSITION_SCALE = np.array([1e5, 1.0, 0.1, 7e3, 0.1, 0.5])  # m, rad, rad, m/s, rad, rad
SIGMA_SCALE, ALPHA_SCALE = 1.0, 0.5  # rad
SIGMA_RATE_SCALE, ALPHA_RATE_SCALE = 0.1, 0.02  # rad/s
TIME_SCALE = 1000.0  # s
HEAT_LOAD_SCALE = 5e8  # J/m^2 (500 MJ/m^2)
GAMMA_RATE_SCALE = 1e-3  # rad/s
MISS_SCALE = 1e4  # m


PATH_NAMES = ("heat flux", "total load", "dynamic pressure", "flight-path lower bound", "flight-path upper bound")
EVENT_NAMES = ("DRS altitude lower bound", "DRS altitude upper bound", "DRS Mach", "DRS vertical speed",
               "DRS Mach lower bound")
#: |u| below which the bank-norm floor's gradient takes the direction (1, 0)
_NORM_FLOOR = 1e-3


def heading_regulariser_sign(x0, site_lat: float) -> float:
    """Sign of lambda_chi in eq. 45 from the geometry (paper 001 Sec. IV.B: 'counterclockwise in
    north direction (positive sign) or clockwise in south direction'): +1 when the site lies
    north of the entry point, -1 when south. On the nominal mission +1 closes the lossless gap
    (0.11 against 0.32 with -1, weight 0.02; tests/test_scvx.py)."""
    return 1.0 if site_lat >= x0[2] else -1.0


class EntryProblem(ConvexifiableProblem):
    """Paper 001's entry problem on a Lobatto segment mesh; see the module doc.

    Attributes: formulation (a Formulation), n_x, n_u (states and controls per node),
    i_sigma, i_alpha (state indices of sigma and alpha, or None), n_aux (epigraph variables)."""

    def __init__(self, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission,
                 settings: EntryProblemSettings, final_time_guess: float):
        self.vehicle, self.planet, self.atmosphere, self.mission, self.settings = (
            vehicle, planet, atmosphere, mission, settings)
        self.formulation = f = FORMULATIONS[settings.formulation]
        self.mesh = SegmentMesh(settings.segments, settings.nodes_per_segment)
        self.alpha = mission.alpha_schedule()
        self.x0 = mission.entry_state(planet)
        self.site_lon, self.site_lat = mission.site(planet)
        limits = vehicle.limits
        self.load_kind, self.load_max = limits.planned_load()  # the total load, else the normal
        if not (math.isfinite(limits.heat_flux_max) and math.isfinite(self.load_max)):
            raise ScenarioError(f"vehicle '{vehicle.name}' needs a finite heat_flux_max_kW_m2 and a finite "
                                f"total_load_max_g or normal_load_max_g for the SCvx planner")
        # layout of the states and controls per node
        state_scale, control_scale = list(POSITION_SCALE), []
        self.i_sigma = self.i_alpha = None
        if f.bank == "rate":
            self.i_sigma = len(state_scale)
            state_scale.append(SIGMA_SCALE)
        if f.alpha == "rate":
            self.i_alpha = len(state_scale)
            state_scale.append(ALPHA_SCALE)
        self.rate_controls = []  # (control index, state index) of the rate controls
        if f.bank == "lossless":
            control_scale += [1.0, 1.0]
        else:
            self.rate_controls.append((len(control_scale), self.i_sigma))
            control_scale.append(SIGMA_RATE_SCALE)
        if f.alpha == "rate":
            self.rate_controls.append((len(control_scale), self.i_alpha))
            control_scale.append(ALPHA_RATE_SCALE)
        self.state_scale, self.control_scale = np.array(state_scale), np.array(control_scale)
        self.n_x, self.n_u = nx, nu = len(state_scale), len(control_scale)
        self.out_q, self.out_n, self.out_a, self.out_h, self.out_p = nx, nx + 1, nx + 2, nx + 3, nx + 4
        self.n_outputs = nx + 5
        n = self.n_nodes = self.mesh.n_nodes
        objective = settings.objective
        self.n_aux = n if objective == "control_effort" else (0 if objective in ("heat_load", "time") else 1)
        self.aux_scale = {"control_effort": 1.0, "max_control_rate": 0.01, "max_flight_path_rate": GAMMA_RATE_SCALE,
                          "max_heat_flux": limits.heat_flux_max, "max_load": self.load_max,
                          "miss": MISS_SCALE}.get(objective, 1.0)
        self._x = slice(0, n * nx)
        self._u = slice(n * nx, n * (nx + nu))
        self.i_tf = n * (nx + nu)
        self._aux = slice(self.i_tf + 1, self.i_tf + 1 + self.n_aux)
        self.n_z = self.i_tf + 1 + self.n_aux
        self.scale = np.concatenate([np.tile(self.state_scale, n), np.tile(self.control_scale, n), [TIME_SCALE],
                                     np.full(self.n_aux, self.aux_scale)])
        self._set_bounds(final_time_guess)
        self.n_defects = settings.segments * (settings.nodes_per_segment - 1) * nx
        self.n_path = (n - 1) * len(PATH_NAMES)
        # the node output a min-max objective bounds (mu >= sign * output_k for each sign), or None
        self._epigraph_output = {"max_flight_path_rate": 4, "max_heat_flux": self.out_q,
                                 "max_load": self.out_n}.get(objective)
        self._epigraph_signs = (1.0, -1.0) if objective == "max_flight_path_rate" else (1.0,)
        self.n_epigraph = 0 if self._epigraph_output is None else len(self._epigraph_signs) * n
        self.n_bank_floor = n if (f.bank == "lossless" and settings.max_lossless_gap < 1.0) else 0
        #: the DRS point's rows: EVENT_NAMES, then an upper bound on the vertical speed where the
        #: mission sets one (``final_vertical_speed_max_m_s``)
        self.event_names = EVENT_NAMES + (() if mission.final_vertical_speed_max_m_s is None
                                          else ("DRS vertical speed upper bound",))
        self.n_inequalities = self.n_path + self.n_epigraph + len(self.event_names) + self.n_bank_floor
        sign = settings.heading_sign or heading_regulariser_sign(self.x0, self.site_lat)
        weight = settings.heading_weight if (f.bank == "lossless" and not self.n_bank_floor) else 0.0
        self.heading_lambda = sign * weight / final_time_guess  # per rad s, scaled objective
        self._gamma_bounds = np.radians(mission.flight_path_bounds_deg) + np.radians(
            settings.flight_path_margins_deg) * np.array([1.0, -1.0])
        self.rate_chords = f.bank == "lossless" and settings.lossless_rate_limit
        #: heat flux [W/m^2], load [g] and dynamic pressure [Pa] bounds at nodes 1..n-1 (n - 1
        #: each; inf where the vehicle states no dynamic-pressure limit): the vehicle's less the
        #: path margin, ramped in over the first path_margin_ramp_s of the final-time guess
        t_nodes = self.mesh.s[1:] * final_time_guess
        ramp_s = settings.path_margin_ramp_s
        margin = settings.path_margin * (np.minimum(1.0, t_nodes / ramp_s) if ramp_s > 0 else np.ones_like(t_nodes))
        self.node_limits = ((1.0 - margin) * limits.heat_flux_max, (1.0 - margin) * self.load_max,
                            (1.0 - margin) * limits.dynamic_pressure_max)

    # ----- layout -------------------------------------------------------------------------
    def _set_bounds(self, tf_guess):
        m, n, v = self.mission, self.n_nodes, self.vehicle
        deg = math.radians
        bank_max = v.bank_limit - deg(self.settings.bank_margin_deg)
        x_lo = [-2e3, -4 * math.pi, -deg(89.0), 10.0, -deg(89.0), deg(m.heading_bounds_deg[0])]
        x_hi = [200e3, 4 * math.pi, deg(89.0), 12e3, deg(60.0), deg(m.heading_bounds_deg[1])]
        u_lo, u_hi = [], []
        if self.formulation.bank == "lossless":
            u_lo += [math.cos(bank_max), -math.sin(min(bank_max, math.pi / 2))]
            u_hi += [math.cos(deg(m.bank_min_deg)), math.sin(min(bank_max, math.pi / 2))]
        else:
            x_lo.append(-bank_max)
            x_hi.append(bank_max)
            u_lo.append(-v.bank_rate_limit)
            u_hi.append(v.bank_rate_limit)
        if self.formulation.alpha == "rate":
            x_lo.append(deg(m.alpha_bounds_deg[0]))
            x_hi.append(deg(m.alpha_bounds_deg[1]))
            u_lo.append(-deg(m.alpha_rate_limit_deg_s))
            u_hi.append(deg(m.alpha_rate_limit_deg_s))
        lower = np.concatenate([np.tile(x_lo, n), np.tile(u_lo, n), [0.3 * tf_guess], np.zeros(self.n_aux)])
        upper = np.concatenate([np.tile(x_hi, n), np.tile(u_hi, n), [3.0 * tf_guess],
                                np.full(self.n_aux, 1e3 * self.aux_scale)])
        lower[:6] = upper[:6] = self.x0  # the entry position and velocity are fixed
        for index, held in ((self.i_sigma, m.entry_bank_deg), (self.i_alpha, m.entry_alpha_deg)):
            if index is not None and held is not None:  # the attitude being flown (descent abort)
                lower[index] = upper[index] = deg(held)
        self.lower, self.upper = lower / self.scale, upper / self.scale

    def pack(self, X, U, tf) -> np.ndarray:
        """Scaled z from states (n, n_x), controls (n, n_u) and t_f [s], SI; the epigraph
        variables are set to the objective's value there (the tightest feasible)."""
        z = np.concatenate([np.ravel(X), np.ravel(U), [tf], np.zeros(self.n_aux)]) / self.scale
        if self.n_aux:
            z[self._aux] = self._tightest_aux(np.asarray(X, float), np.asarray(U, float))
        return z

    def unpack(self, z):
        """(X (n, n_x), U (n, n_u), t_f [s]) SI from scaled z."""
        v = np.asarray(z, float) * self.scale
        return (v[self._x].reshape(-1, self.n_x), v[self._u].reshape(-1, self.n_u), float(v[self.i_tf]))

    def rates(self, U) -> np.ndarray:
        """(n, k) the rate controls [rad/s] (sigma_dot and/or alpha_dot) of controls U."""
        return np.asarray(U)[:, [c for c, _ in self.rate_controls]]

    def _tightest_aux(self, X, U) -> np.ndarray:
        objective = self.settings.objective
        if objective == "control_effort":
            return np.linalg.norm(self.rates(U), axis=1) / self.aux_scale
        if objective == "max_control_rate":
            return np.array([np.linalg.norm(self.rates(U), axis=1).max() / self.aux_scale])
        if objective == "miss":
            return np.array([self.site_miss(X[-1]) / self.aux_scale])
        nodes, _ = self._nodes(X, U, gradients=False)
        bounded = max((sign * nodes[:, self._epigraph_output]).max() for sign in self._epigraph_signs)
        return np.array([bounded / self.aux_scale])

    # ----- the physics at one node ------------------------------------------------------
    def alpha_of(self, V):
        """alpha(V) [rad] of the mission's law for float or AutoDiffXd V (the C2 schedule and
        its slope); for a symbolic V the uninterpreted function ``alpha_schedule(V)``, which the
        node tape evaluates with the schedule's array path (``_alpha_schedule``)."""
        if is_symbolic(V):
            return uninterpreted_function("alpha_schedule", [V])
        value, slope, _ = self.alpha.derivatives(value_of(V))
        return lift([V], value, [slope])

    def bank_and_alpha(self, x, u):
        """(cos sigma, sin sigma) — relaxed (u1, u2) for the lossless bank — and alpha [rad] at a
        node, any scalar type."""
        if self.formulation.bank == "lossless":
            c, s = u[0], u[1]
        else:
            c, s = np.cos(x[self.i_sigma]), np.sin(x[self.i_sigma])
        alpha = x[self.i_alpha] if self.i_alpha is not None else self.alpha_of(x[3])
        return c, s, alpha

    def node_outputs(self, x, u, atmosphere: Atmosphere | None = None):
        """[xdot (n_x), heat flux W/m^2, load g (total or normal: ``load_kind``), speed of sound m/s, geodetic
        altitude m, dynamic pressure Pa] at state x and control u (eqs. 1-10, 34-41, 54-57). Any scalar type; ``atmosphere``
        replaces the problem's (the tape's trace)."""
        position = x[:6]
        rho, a = air_data(position, self.planet, atmosphere or self.atmosphere)
        c, s, alpha = self.bank_and_alpha(x, u)
        _, L, D = aero_accelerations(position, alpha, rho, a, self.vehicle)
        xdot = list(equations_of_motion_lift_components(position, L * c, L * s, D, self.planet))
        for control, _state in self.rate_controls:
            xdot.append(u[control])
        q = self.vehicle.heat_flux(rho, x[3])
        n = (total_load_factor(L, D, self.planet.g0) if self.load_kind == "total"
             else signed_normal_load_factor(L, D, alpha, self.planet.g0))
        return [*xdot, q, n, a, self.planet.atmospheric_altitude(x[0], x[2]), dynamic_pressure(rho, x[3])]

    @functools.cached_property
    def tape(self) -> ExpressionTape | None:
        """node_outputs of every node at once (an ExpressionTape of its symbolic form, the
        atmosphere its own array path), or None when a model has no symbolic form (the nodes
        are then evaluated one by one)."""
        xs = [Variable(f"x{i}") for i in range(self.n_x)]
        us = [Variable(f"u{i}") for i in range(self.n_u)]
        atmosphere = TracedAtmosphere(self.atmosphere)
        try:
            with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
                outputs = self.node_outputs([Expression(v) for v in xs], [Expression(v) for v in us], atmosphere)
            return ExpressionTape(outputs, xs + us, {**atmosphere.functions, "alpha_schedule": self._alpha_schedule})
        except (UnsupportedScalarError, TypeError):
            return None

    def _alpha_schedule(self, V):
        """(alpha(V), [d alpha / d V]) on an array of speeds [m/s] (the tape's alpha_schedule)."""
        return self.alpha(V), [self.alpha.slope(V)]

    def _nodes(self, X, U, gradients: bool):
        """Node outputs (n, n_outputs) and, with gradients, their Jacobians
        (n, n_outputs, n_x + n_u) with respect to (x, u)."""
        if self.tape is not None:
            return self._nodes_by_tape(X, U, gradients)
        return self._nodes_one_by_one(X, U, gradients)

    def _nodes_by_tape(self, X, U, gradients: bool):
        points = np.hstack([np.asarray(X, float), np.asarray(U, float)])
        if not gradients:
            return self.tape(points), None
        return self.tape(points, gradients=True)

    def _nodes_one_by_one(self, X, U, gradients: bool):
        n, nx, nv = self.n_nodes, self.n_x, self.n_x + self.n_u
        values = np.empty((n, self.n_outputs))
        if not gradients:
            for k in range(n):
                values[k] = self.node_outputs(X[k], U[k])
            return values, None
        jac = np.empty((n, self.n_outputs, nv))
        for k in range(n):
            v = InitializeAutoDiff(np.concatenate([X[k], U[k]]))[:, 0]
            out = np.array(self.node_outputs(v[:nx], v[nx:]), dtype=object)
            for i, o in enumerate(out):
                if not isinstance(o, AutoDiffXd):
                    out[i] = AutoDiffXd(float(o), np.zeros(nv))
            values[k] = ExtractValue(out)[:, 0]
            jac[k] = ExtractGradient(out)
        return values, jac

    # ----- evaluation ---------------------------------------------------------------------
    def _evaluate(self, z, gradients: bool):
        X, U, tf = self.unpack(z)
        aux = np.asarray(z, float)[self._aux]
        nodes, jac = self._nodes(X, U, gradients)
        mesh, nx = self.mesh, self.n_x
        seg = mesh.segment_nodes
        F = tf * nodes[:, :nx]  # dx/ds
        defects = (X[seg[:, 1:]] - X[seg[:, :1]] - np.einsum("jk,skc->sjc", mesh.integration, F[seg])) / self.state_scale
        q, load, a, hstar = nodes[:, self.out_q], nodes[:, self.out_n], nodes[:, self.out_a], nodes[:, self.out_h]
        gam = X[1:, 4]
        m = self.mission
        g_lo, g_hi = self._gamma_bounds
        q_max, n_max, p_max = self.node_limits
        path = np.stack([q[1:] / q_max - 1.0, load[1:] / n_max - 1.0, nodes[1:, self.out_p] / p_max - 1.0,
                         (g_lo - gam) / 0.1, (gam - g_hi) / 0.1], axis=1)
        objective = self.settings.objective
        if self.n_epigraph:
            epigraph = np.concatenate([sign * nodes[:, self._epigraph_output] for sign in self._epigraph_signs])
            epigraph = epigraph / self.aux_scale - aux[0]
        else:
            epigraph = np.zeros(0)
        xf = X[-1]
        h_lo, h_hi = m.drs_altitude_window(self.formulation.bank)
        events = np.array([(h_lo - hstar[-1]) / 1e3, (hstar[-1] - h_hi) / 1e3,
                           (xf[3] - m.final_mach_max * a[-1]) / 100.0,
                           (m.final_vertical_speed_min_m_s - xf[3] * math.sin(xf[4])) / 100.0,
                           (m.final_mach_min * a[-1] - xf[3]) / 100.0]
                          + ([] if m.final_vertical_speed_max_m_s is None
                             else [(xf[3] * math.sin(xf[4]) - m.final_vertical_speed_max_m_s) / 100.0]))
        floor = (1.0 - self.settings.max_lossless_gap) - np.hypot(U[:, 0], U[:, 1]) if self.n_bank_floor else np.zeros(0)
        w = mesh.weights
        if objective == "heat_load":
            value = tf * (w @ q) / HEAT_LOAD_SCALE
        elif objective == "time":
            value = tf / TIME_SCALE
        elif objective == "control_effort":
            value = tf * (w @ aux)
        else:
            value = aux[0]
        value += tf * self.heading_lambda * (w @ X[:, 5])
        convex = [max(0.0, self.site_miss(xf) - m.site_radius_m) / 1e3]
        if self.rate_chords:
            convex += list(np.maximum(self.bank_turns(U) - self.bank_turn_limits(tf), 0.0))
        ev = Evaluation(float(value), defects.ravel(), np.concatenate([path.ravel(), epigraph, events, floor]),
                        np.array(convex))
        if not gradients:
            return ev
        return self._linearise(ev, X, U, tf, aux, nodes, jac)

    def evaluate(self, z) -> Evaluation:
        return self._evaluate(z, gradients=False)

    def linearise(self, z) -> Linearisation:
        return self._evaluate(z, gradients=True)

    def bank_turns(self, U) -> np.ndarray:
        """|u_k+1 - u_k| of the lossless bank between consecutive nodes (n - 1,)."""
        return np.linalg.norm(np.diff(np.asarray(U)[:, :2], axis=0), axis=1)

    def bank_turn_limits(self, tf: float) -> np.ndarray:
        """sigma_dot_max (t_k+1 - t_k) [rad] between consecutive nodes at final time tf [s]."""
        return self.vehicle.bank_rate_limit * np.diff(self.mesh.s) * tf

    def site_miss(self, xf) -> float:
        """Distance [m] of state xf from the site as the site cone measures it (eq. 69)."""
        return self.planet.reference_radius * math.hypot(math.cos(self.site_lat) * (xf[1] - self.site_lon),
                                                         xf[2] - self.site_lat)

    def _col_x(self, node, comp):
        return node * self.n_x + comp

    def _col_u(self, node, comp):
        return self._u.start + node * self.n_u + comp

    def _linearise(self, ev, X, U, tf, aux, nodes, jac) -> Linearisation:
        n, nx, nu = self.n_nodes, self.n_x, self.n_u
        nv = nx + nu
        mesh = self.mesh
        seg = mesh.segment_nodes
        n_seg, m = seg.shape
        I = mesh.integration
        var_cols = np.concatenate([self._col_x(np.arange(n)[:, None], np.arange(nx)[None, :]),
                                   self._col_u(np.arange(n)[:, None], np.arange(nu)[None, :])], axis=1)  # (n, nv)
        # --- defects: rows (segment, j, component) --------------------------------------
        rows_base = (np.arange(n_seg)[:, None] * (m - 1) + np.arange(m - 1)[None, :]) * nx  # (s, j)
        r_idx, c_idx, vals = [], [], []
        comp = np.arange(nx)
        for sign, node in ((1.0, seg[:, 1:]), (-1.0, np.repeat(seg[:, :1], m - 1, axis=1))):
            r_idx.append((rows_base[..., None] + comp).ravel())
            c_idx.append(self._col_x(node[..., None], comp).ravel())
            vals.append(np.full(rows_base.size * nx, sign))
        # -I[j,k] t_f d f(x_k, u_k) / d(x_k, u_k): shape (s, j, k, c, v)
        dF = tf * jac[:, :nx, :]  # (n, nx, nv)
        block = -I[None, :, :, None, None] * dF[seg][:, None, :, :, :]
        rr = np.broadcast_to(rows_base[:, :, None, None, None] + comp[None, None, None, :, None], block.shape)
        cc = np.broadcast_to(var_cols[seg][:, None, :, None, :], block.shape)
        r_idx.append(rr.ravel())
        c_idx.append(cc.ravel())
        vals.append(block.ravel())
        # d/d t_f: -sum_k I[j,k] f_k
        f_tf = -np.einsum("jk,skc->sjc", I, nodes[seg][..., :nx])
        r_idx.append((rows_base[..., None] + comp).ravel())
        c_idx.append(np.full(f_tf.size, self.i_tf))
        vals.append(f_tf.ravel())
        r = np.concatenate(r_idx)
        c = np.concatenate(c_idx)
        v = np.concatenate(vals)
        row_scale = np.tile(1.0 / self.state_scale, self.n_defects // nx)
        v = v * row_scale[r] * self.scale[c]
        C = sp.csc_matrix((v, (r, c)), shape=(self.n_defects, self.n_z))
        # --- path, epigraph and event inequalities (rows of scaled-z coefficients) -----------
        mi = self.mission
        k = np.arange(1, n)
        path_rows = (k - 1) * len(PATH_NAMES)
        r_idx = [np.repeat(path_rows, nv), np.repeat(path_rows + 1, nv), np.repeat(path_rows + 2, nv),
                 path_rows + 3, path_rows + 4]
        c_idx = [var_cols[k].ravel(), var_cols[k].ravel(), var_cols[k].ravel(), self._col_x(k, 4), self._col_x(k, 4)]
        q_max, n_max, p_max = self.node_limits
        vals = [(jac[k, self.out_q, :] / q_max[:, None]).ravel(), (jac[k, self.out_n, :] / n_max[:, None]).ravel(),
                (jac[k, self.out_p, :] / p_max[:, None]).ravel(), np.full(n - 1, -1.0 / 0.1), np.full(n - 1, 1.0 / 0.1)]
        objective = self.settings.objective
        e0 = self.n_path
        if self.n_epigraph:
            for i, sign in enumerate(self._epigraph_signs):
                rows = e0 + i * n + np.arange(n)
                r_idx += [np.repeat(rows, nv), rows]
                c_idx += [var_cols.ravel(), np.full(n, self._aux.start)]
                vals += [(sign * jac[:, self._epigraph_output, :] / self.aux_scale).ravel(),
                         np.full(n, -1.0 / self.scale[self._aux.start])]
        e0 += self.n_epigraph
        xf, jf = X[-1], jac[-1]
        fcols = var_cols[-1]
        r_idx += [np.full(nv, e0), np.full(nv, e0 + 1), np.full(nv, e0 + 2), np.full(2, e0 + 3), np.full(nv, e0 + 4)]
        c_idx += [fcols, fcols, fcols, self._col_x(n - 1, np.array([3, 4])), fcols]
        d_mach = -mi.final_mach_max * jf[self.out_a, :]
        d_mach[3] += 1.0
        d_mach_min = mi.final_mach_min * jf[self.out_a, :]
        d_mach_min[3] -= 1.0
        vals += [-jf[self.out_h, :] / 1e3, jf[self.out_h, :] / 1e3, d_mach / 100.0,
                 -np.array([math.sin(xf[4]), xf[3] * math.cos(xf[4])]) / 100.0, d_mach_min / 100.0]
        if len(self.event_names) > len(EVENT_NAMES):  # the vertical speed's upper bound
            r_idx.append(np.full(2, e0 + len(EVENT_NAMES)))
            c_idx.append(self._col_x(n - 1, np.array([3, 4])))
            vals.append(np.array([math.sin(xf[4]), xf[3] * math.cos(xf[4])]) / 100.0)
        if self.n_bank_floor:  # d(1 - gap - |u_k|)/du_k = -u_k / |u_k|
            norm = np.hypot(U[:, 0], U[:, 1])
            direction = np.where(norm[:, None] > _NORM_FLOOR, U[:, :2] / np.maximum(norm, _NORM_FLOOR)[:, None],
                                 np.array([1.0, 0.0]))
            rows = e0 + len(self.event_names) + np.arange(n)
            r_idx.append(np.repeat(rows, 2))
            c_idx.append(self._col_u(np.arange(n)[:, None], np.arange(2)[None, :]).ravel())
            vals.append(-direction.ravel())
        r = np.concatenate(r_idx)
        c = np.concatenate(c_idx)
        v = np.concatenate(vals) * self.scale[c]
        G = sp.csc_matrix((v, (r, c)), shape=(self.n_inequalities, self.n_z))
        # --- objective (gradient in SI, scaled at the end) -------------------------------------
        w = mesh.weights
        grad = np.zeros(self.n_z)
        if objective == "heat_load":
            np.add.at(grad, var_cols.ravel(), (tf * w[:, None] * jac[:, self.out_q, :] / HEAT_LOAD_SCALE).ravel())
            grad[self.i_tf] = (w @ nodes[:, self.out_q]) / HEAT_LOAD_SCALE
        elif objective == "time":
            grad[self.i_tf] = 1.0 / TIME_SCALE
        elif objective == "control_effort":
            grad[self._aux] = tf * w / self.aux_scale
            grad[self.i_tf] = w @ aux
        else:
            grad[self._aux] = 1.0 / self.aux_scale
        grad[self._col_x(np.arange(n), 5)] += tf * self.heading_lambda * w
        grad[self.i_tf] += self.heading_lambda * (w @ X[:, 5])
        grad *= self.scale
        return Linearisation(ev, grad, C, G)

    # ----- convex constraints -------------------------------------------------------------
    def add_convex_constraints(self, prog, z):
        """|u_k| <= 1 at every node (eq. 42, lossless bank), the epigraph cones of the rate and
        miss objectives, the site cone with its buffer (eq. 69), and the lossless bank's
        rate chords with theirs (module doc)."""
        U = z[self._u].reshape(-1, self.n_u)
        if self.formulation.bank == "lossless":
            A = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
            b = np.array([1.0, 0.0, 0.0])
            for k in range(self.n_nodes):
                prog.AddLorentzConeConstraint(A, b, U[k, :2])
        objective = self.settings.objective
        if objective in RATE_OBJECTIVES:
            # mu_k (or mu) >= |rates_k| in SI, each side in units of aux_scale
            cols = [c for c, _ in self.rate_controls]
            A = np.zeros((1 + len(cols), 1 + len(cols)))
            A[0, 0] = 1.0
            for i, c in enumerate(cols):
                A[1 + i, 1 + i] = self.control_scale[c] / self.aux_scale
            aux = z[self._aux]
            for k in range(self.n_nodes):
                mu = aux[k] if objective == "control_effort" else aux[0]
                prog.AddLorentzConeConstraint(A, np.zeros(len(A)), np.concatenate([[mu], U[k, cols]]))
        lon_f, lat_f = z[self._col_x(self.n_nodes - 1, 1)], z[self._col_x(self.n_nodes - 1, 2)]
        R, d = self.planet.reference_radius, 1e3  # cone rows in km
        miss_rows = np.array([[R * math.cos(self.site_lat) * POSITION_SCALE[1] / d, 0.0],
                              [0.0, R * POSITION_SCALE[2] / d]])
        miss_offset = np.array([-R * math.cos(self.site_lat) * self.site_lon / d, -R * self.site_lat / d])
        buffers = prog.NewContinuousVariables(1 + (self.n_nodes - 1 if self.rate_chords else 0), "convex_buffer")
        A = np.zeros((3, 3))
        A[0, 2] = 1.0
        A[1:, :2] = miss_rows
        prog.AddLorentzConeConstraint(A, np.concatenate([[self.mission.site_radius_m / d], miss_offset]),
                                      np.array([lon_f, lat_f, buffers[0]]))
        if objective == "miss":
            A = np.zeros((3, 3))
            A[0, 2] = self.aux_scale / d
            A[1:, :2] = miss_rows
            prog.AddLorentzConeConstraint(A, np.concatenate([[0.0], miss_offset]),
                                          np.array([lon_f, lat_f, z[self._aux][0]]))
        if self.rate_chords:  # |u_k+1 - u_k| <= sigma_dot_max ds_k t_f + buffer_k
            limits = self.bank_turn_limits(TIME_SCALE)  # per unit of the scaled t_f
            A = np.zeros((3, 6))
            A[0, 1] = 1.0
            A[1:, 2:4], A[1:, 4:6] = -np.eye(2), np.eye(2)
            for k in range(self.n_nodes - 1):
                A[0, 0] = limits[k]
                prog.AddLorentzConeConstraint(A, np.zeros(3), np.concatenate(
                    [[z[self.i_tf], buffers[1 + k]], U[k, :2], U[k + 1, :2]]))
        return buffers

    def tighten(self, z) -> np.ndarray:
        """z with the epigraph variable of a min-max objective at the objective's value there
        (``pack``'s choice). The control-effort variables are left to the sub-problem (tightened,
        the nominal converged to 56.3 deg instead of 53.7)."""
        if self.n_aux != 1:
            return z
        X, U, _ = self.unpack(z)
        z = np.array(z, float)
        z[self._aux] = np.clip(self._tightest_aux(X, U), self.lower[self._aux], self.upper[self._aux])
        return z

    def trust_region_variables(self) -> np.ndarray:
        """All but the epigraph variable of a min-max objective (it enters the objective and
        its constraints linearly; with a trust region the max fell by the radius per iteration
        and the min-max plans did not converge in 60). The control-effort variables stay
        bounded: the objective multiplies them by t_f."""
        mask = np.ones(self.n_z, bool)
        if self.n_aux == 1:
            mask[self._aux] = False
        return mask

    def correction_variables(self) -> np.ndarray:
        """The states only: the second-order correction re-satisfies the dynamics with the
        controls and t_f of the step (moving the controls too by least norm opens the lossless
        gap: the min-max-load plan then converged at 1.30 g with gap 0.24 instead of 1.17 g)."""
        mask = np.zeros(self.n_z, bool)
        mask[self._x] = True
        return mask

    # ----- diagnosis ------------------------------------------------------------------------
    @property
    def state_names(self) -> tuple:
        extra = (["bank"] if self.i_sigma is not None else []) + (["alpha"] if self.i_alpha is not None else [])
        return (*STATE_NAMES, *extra)

    def node_time(self, node: int) -> str:
        return f"node {node} (s = {self.mesh.s[node]:.3f})"

    def describe_defect(self, i: int) -> str:
        seg, rest = divmod(i, (self.settings.nodes_per_segment - 1) * self.n_x)
        j, c = divmod(rest, self.n_x)
        node = self.mesh.segment_nodes[seg, j + 1]
        return f"{self.state_names[c]} equation, segment {seg}, {self.node_time(node)}"

    def describe_inequality(self, i: int) -> str:
        events = self.n_path + self.n_epigraph
        if i >= events + len(self.event_names):
            node = i - events - len(self.event_names)
            return f"bank-norm floor |u| >= {1.0 - self.settings.max_lossless_gap:g} at {self.node_time(node)}"
        if i >= self.n_path + self.n_epigraph:
            return self.event_names[i - self.n_path - self.n_epigraph] + " at the DRS point"
        if i >= self.n_path:
            node = (i - self.n_path) % self.n_nodes
            return f"{self.settings.objective} epigraph at {self.node_time(node)}"
        node, c = divmod(i, len(PATH_NAMES))
        name = PATH_NAMES[c] if c != 1 else f"{self.load_kind} load"
        return f"{name} at {self.node_time(node + 1)}"

    def describe_convex(self, i: int) -> str:
        if i > 0:
            return (f"bank-rate limit between {self.node_time(i - 1)} and {self.node_time(i)} "
                    f"(|u_k+1 - u_k| <= {math.degrees(self.vehicle.bank_rate_limit):g} deg/s x dt)")
        return f"landing-site cone (miss <= {self.mission.site_radius_m / 1e3:g} km)"
