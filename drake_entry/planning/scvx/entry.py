"""The entry problem of paper 001 as a ``ConvexifiableProblem``: free final time, lossless
bank convexification, path and DRS constraints, Lobatto segment discretisation.

Decision vector z (scaled): the states x_k (6 per node, ``STATE_SCALE``), the controls
u_k = (u1, u2) = (cos sigma, sin sigma) relaxed to |u| <= 1 (eqs. 37-42), and t_f / 1000 s.
Normalised time s in [0, 1] with dx/ds = t_f f(x, u) (time dilation). The dynamics are the
project's one set of equations (``dynamics.equations_of_motion_lift_components``, paper 001
eqs. 1-7 with 40-41); their Jacobians come from AutoDiff of that code, never a second copy.

Defects: on each segment of a ``SegmentMesh`` (Lobatto IIIA, ``nodes_per_segment`` LGL
nodes; 2 nodes per segment is the paper's trapezoid, Sec. IV.B),
    x_j - x_0 - sum_k I[j, k] t_f f(x_k, u_k) = 0.

Constraints: bank-magnitude bounds on u (eqs. 43-44, hard), |u| <= 1 (eq. 42, hard cone);
buffered (eq. 24) at every node: heat flux <= q_max (eq. 9), total load <= n_max (eq. 10),
flight-path bounds (eq. 70); at the DRS point: geodetic altitude window (eq. 64), V <= M a
(eq. 65), V sin(gamma) >= V_v,min (eq. 66), and a cone ||miss|| <= site radius (eqs. 67-68)
with a buffer. Hard bounds on the other states (eq. 70) and the fixed entry state.

Objectives (paper 001 Table 2, lossless forms): 'heat_load' (integral of q dt, scaled by
500 MJ/m^2), 'time' (t_f). The heading regulariser lambda_chi integral chi dt (eq. 45)
drives |u| to 1; its sign follows the geometry (``heading_regulariser_sign``).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
import scipy.sparse as sp
from pydrake.autodiffutils import AutoDiffXd, ExtractGradient, ExtractValue, InitializeAutoDiff

from ...atmosphere import Atmosphere
from ...constraints import total_load_factor
from ...dynamics import STATE_NAMES, air_data, aero_accelerations, equations_of_motion_lift_components
from ...errors import ScenarioError
from ...planet import Earth
from ...pseudospectral import SegmentMesh
from ...scalar import lift, value_of
from ...vehicles import Vehicle
from .engine import ConvexifiableProblem, Evaluation, Linearisation
from .mission import ScvxMission

STATE_SCALE = np.array([1e5, 1.0, 0.1, 7e3, 0.1, 0.5])  # m, rad, rad, m/s, rad, rad
TIME_SCALE = 1000.0  # s
HEAT_LOAD_SCALE = 5e8  # J/m^2 (500 MJ/m^2)
OBJECTIVES = ("heat_load", "time")
PATH_NAMES = ("heat flux", "total load", "flight-path lower bound", "flight-path upper bound")
EVENT_NAMES = ("DRS altitude lower bound", "DRS altitude upper bound", "DRS Mach", "DRS vertical speed")
NODE_OUTPUTS = 10  # xdot (6), heat flux, total load, speed of sound, geodetic altitude


def heading_regulariser_sign(x0, site_lat: float) -> float:
    """Sign of lambda_chi in eq. 45 from the geometry (paper 001 Sec. IV.B: 'counterclockwise in
    north direction (positive sign) or clockwise in south direction'): +1 when the site lies
    north of the entry point, -1 when south. On the nominal mission +1 closes the lossless gap
    (0.11 against 0.32 with -1, weight 0.02; tests/test_scvx.py)."""
    return 1.0 if site_lat >= x0[2] else -1.0


@dc.dataclass
class EntryProblemSettings:
    """Discretisation and objective of the entry problem.

    Attributes:
      segments, nodes_per_segment: the Lobatto mesh (2 nodes per segment: trapezoid).
      objective: one of OBJECTIVES.
      heading_weight: |lambda_chi| of eq. 45 as a fraction of the scaled objective per
        radian of mean heading (0 disables the regulariser).
      heading_sign: +1, -1, or 0 for the geometric rule ``heading_regulariser_sign``.
    """

    segments: int = 33
    nodes_per_segment: int = 4
    objective: str = "heat_load"
    heading_weight: float = 0.02
    heading_sign: float = 0.0

    def __post_init__(self):
        if self.objective not in OBJECTIVES:
            raise ScenarioError(f"EntryProblemSettings.objective = '{self.objective}'; allowed: {', '.join(OBJECTIVES)}")
        if not 0.0 <= self.heading_weight <= 10.0:
            raise ScenarioError(f"EntryProblemSettings.heading_weight = {self.heading_weight} must be in [0, 10]")
        if self.heading_sign not in (-1.0, 0.0, 1.0):
            raise ScenarioError(f"EntryProblemSettings.heading_sign = {self.heading_sign} must be -1, 0 or +1")


class EntryProblem(ConvexifiableProblem):
    """Paper 001's entry problem (lossless bank) on a Lobatto segment mesh; see the module doc."""

    n_x, n_u = 6, 2

    def __init__(self, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission,
                 settings: EntryProblemSettings, final_time_guess: float):
        self.vehicle, self.planet, self.atmosphere, self.mission, self.settings = (
            vehicle, planet, atmosphere, mission, settings)
        self.mesh = SegmentMesh(settings.segments, settings.nodes_per_segment)
        self.alpha = mission.alpha_schedule()
        self.x0 = mission.entry_state(planet)
        self.site_lon, self.site_lat = mission.site(planet)
        limits = vehicle.limits
        if not (math.isfinite(limits.heat_flux_max) and math.isfinite(limits.total_load_max)):
            raise ScenarioError(f"vehicle '{vehicle.name}' needs finite heat_flux_max_kW_m2 and total_load_max_g "
                                f"for the SCvx planner")
        n, nx, nu = self.mesh.n_nodes, self.n_x, self.n_u
        self.n_nodes = n
        self.n_z = n * (nx + nu) + 1
        self._x = slice(0, n * nx)
        self._u = slice(n * nx, n * (nx + nu))
        self.i_tf = n * (nx + nu)
        self.scale = np.concatenate([np.tile(STATE_SCALE, n), np.ones(n * nu), [TIME_SCALE]])
        self._set_bounds(final_time_guess)
        self.n_defects = settings.segments * (settings.nodes_per_segment - 1) * nx
        self.n_path = (n - 1) * len(PATH_NAMES)
        self.n_inequalities = self.n_path + len(EVENT_NAMES)
        sign = settings.heading_sign or heading_regulariser_sign(self.x0, self.site_lat)
        self.heading_lambda = sign * settings.heading_weight / final_time_guess  # per rad s, scaled objective
        self._gamma_bounds = np.radians(mission.flight_path_bounds_deg)

    # ----- layout -------------------------------------------------------------------------
    def _set_bounds(self, tf_guess):
        m, n = self.mission, self.n_nodes
        deg = math.radians
        x_lo = np.array([-2e3, -4 * math.pi, -deg(89.0), 10.0, -deg(89.0), deg(m.heading_bounds_deg[0])])
        x_hi = np.array([200e3, 4 * math.pi, deg(89.0), 12e3, deg(60.0), deg(m.heading_bounds_deg[1])])
        bank_max = self.vehicle.bank_limit
        u_lo = np.array([math.cos(bank_max), -math.sin(min(bank_max, math.pi / 2))])
        u_hi = np.array([math.cos(deg(m.bank_min_deg)), math.sin(min(bank_max, math.pi / 2))])
        lower = np.concatenate([np.tile(x_lo, n), np.tile(u_lo, n), [0.3 * tf_guess]])
        upper = np.concatenate([np.tile(x_hi, n), np.tile(u_hi, n), [3.0 * tf_guess]])
        lower[:self.n_x] = upper[:self.n_x] = self.x0  # the entry state is fixed
        self.lower, self.upper = lower / self.scale, upper / self.scale

    def pack(self, X, U, tf) -> np.ndarray:
        """Scaled z from states (n, 6), controls (n, 2) and t_f [s], SI."""
        return np.concatenate([np.ravel(X), np.ravel(U), [tf]]) / self.scale

    def unpack(self, z):
        """(X (n, 6), U (n, 2), t_f [s]) SI from scaled z."""
        v = np.asarray(z, float) * self.scale
        return (v[self._x].reshape(-1, self.n_x), v[self._u].reshape(-1, self.n_u), float(v[self.i_tf]))

    # ----- the physics at one node ------------------------------------------------------
    def alpha_of(self, V):
        """alpha(V) [rad] for float or AutoDiffXd V (the C2 schedule and its slope)."""
        value, slope, _ = self.alpha.derivatives(value_of(V))
        return lift([V], value, [slope])

    def node_outputs(self, x, u):
        """[xdot (6), heat flux W/m^2, total load g, speed of sound m/s, geodetic altitude m]
        at state x and relaxed control u (eqs. 1-10, 40-41). Any scalar type."""
        rho, a = air_data(x, self.planet, self.atmosphere)
        alpha = self.alpha_of(x[3])
        _, L, D = aero_accelerations(x, alpha, rho, a, self.vehicle)
        xdot = equations_of_motion_lift_components(x, L * u[0], L * u[1], D, self.planet)
        q = self.vehicle.heat_flux(rho, x[3])
        n = total_load_factor(L, D, self.planet.g0)
        return [*xdot, q, n, a, self.planet.atmospheric_altitude(x[0], x[2])]

    def _nodes(self, X, U, gradients: bool):
        """Node outputs (n, NODE_OUTPUTS) and, with gradients, their Jacobians
        (n, NODE_OUTPUTS, 8) with respect to (x, u)."""
        n = self.n_nodes
        values = np.empty((n, NODE_OUTPUTS))
        if not gradients:
            for k in range(n):
                values[k] = self.node_outputs(X[k], U[k])
            return values, None
        jac = np.empty((n, NODE_OUTPUTS, self.n_x + self.n_u))
        for k in range(n):
            v = InitializeAutoDiff(np.concatenate([X[k], U[k]]))[:, 0]
            out = np.array(self.node_outputs(v[:6], v[6:]), dtype=object)
            for i, o in enumerate(out):
                if not isinstance(o, AutoDiffXd):
                    out[i] = AutoDiffXd(float(o), np.zeros(8))
            values[k] = ExtractValue(out)[:, 0]
            jac[k] = ExtractGradient(out)
        return values, jac

    # ----- evaluation ---------------------------------------------------------------------
    def _evaluate(self, z, gradients: bool):
        X, U, tf = self.unpack(z)
        nodes, jac = self._nodes(X, U, gradients)
        mesh, nx = self.mesh, self.n_x
        seg = mesh.segment_nodes
        I = mesh.integration  # (m-1, m)
        F = tf * nodes[:, :nx]  # dx/ds
        defects = (X[seg[:, 1:]] - X[seg[:, :1]] - np.einsum("jk,skc->sjc", I, F[seg])) / STATE_SCALE
        q, load, a, hstar = nodes[1:, 6], nodes[1:, 7], nodes[:, 8], nodes[:, 9]
        gam = X[1:, 4]
        lim, m = self.vehicle.limits, self.mission
        g_lo, g_hi = self._gamma_bounds
        path = np.stack([q / lim.heat_flux_max - 1.0, load / lim.total_load_max - 1.0,
                         (g_lo - gam) / 0.1, (gam - g_hi) / 0.1], axis=1)
        xf = X[-1]
        events = np.array([(m.final_altitude_m[0] - hstar[-1]) / 1e3, (hstar[-1] - m.final_altitude_m[1]) / 1e3,
                           (xf[3] - m.final_mach_max * a[-1]) / 100.0,
                           (m.final_vertical_speed_min_m_s - xf[3] * math.sin(xf[4])) / 100.0])
        w = mesh.weights
        if self.settings.objective == "heat_load":
            base = w @ nodes[:, 6] / HEAT_LOAD_SCALE
        else:
            base = 1.0 / TIME_SCALE
        objective = tf * (base + self.heading_lambda * (w @ X[:, 5]))
        ev = Evaluation(float(objective), defects.ravel(), np.concatenate([path.ravel(), events]),
                        np.array([max(0.0, self.site_miss(xf) - m.site_radius_m) / 1e3]))
        if not gradients:
            return ev
        return self._linearise(ev, X, U, tf, nodes, jac, base)

    def evaluate(self, z) -> Evaluation:
        return self._evaluate(z, gradients=False)

    def linearise(self, z) -> Linearisation:
        return self._evaluate(z, gradients=True)

    def site_miss(self, xf) -> float:
        """Distance [m] of state xf from the site as the site cone measures it (eqs. 67-68)."""
        return self.planet.reference_radius * math.hypot(math.cos(self.site_lat) * (xf[1] - self.site_lon),
                                                         xf[2] - self.site_lat)

    def _col_x(self, node, comp):
        return node * self.n_x + comp

    def _col_u(self, node, comp):
        return self._u.start + node * self.n_u + comp

    def _linearise(self, ev, X, U, tf, nodes, jac, base) -> Linearisation:
        n, nx, nu = self.n_nodes, self.n_x, self.n_u
        mesh = self.mesh
        seg = mesh.segment_nodes
        n_seg, m = seg.shape
        I = mesh.integration
        var_cols = np.concatenate([self._col_x(np.arange(n)[:, None], np.arange(nx)[None, :]),
                                   self._col_u(np.arange(n)[:, None], np.arange(nu)[None, :])], axis=1)  # (n, 8)
        # --- defects: rows (segment, j, component) --------------------------------------
        rows_base = (np.arange(n_seg)[:, None] * (m - 1) + np.arange(m - 1)[None, :]) * nx  # (s, j)
        r_idx, c_idx, vals = [], [], []
        comp = np.arange(nx)
        for sign, node in ((1.0, seg[:, 1:]), (-1.0, np.repeat(seg[:, :1], m - 1, axis=1))):
            r_idx.append((rows_base[..., None] + comp).ravel())
            c_idx.append(self._col_x(node[..., None], comp).ravel())
            vals.append(np.full(rows_base.size * nx, sign))
        # -I[j,k] t_f d f(x_k, u_k) / d(x_k, u_k): shape (s, j, k, c, v)
        dF = tf * jac[:, :nx, :]  # (n, 6, 8)
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
        row_scale = np.tile(1.0 / STATE_SCALE, self.n_defects // nx)
        v = v * row_scale[r] * self.scale[c]
        C = sp.csc_matrix((v, (r, c)), shape=(self.n_defects, self.n_z))
        # --- path and event inequalities ----------------------------------------------------
        lim, mi = self.vehicle.limits, self.mission
        k = np.arange(1, n)
        path_rows = (k - 1) * len(PATH_NAMES)
        r_idx = [np.repeat(path_rows, 8), np.repeat(path_rows + 1, 8), path_rows + 2, path_rows + 3]
        c_idx = [var_cols[k].ravel(), var_cols[k].ravel(), self._col_x(k, 4), self._col_x(k, 4)]
        vals = [(jac[k, 6, :] / lim.heat_flux_max).ravel(), (jac[k, 7, :] / lim.total_load_max).ravel(),
                np.full(n - 1, -1.0 / 0.1), np.full(n - 1, 1.0 / 0.1)]
        e0 = self.n_path
        xf, jf = X[-1], jac[-1]
        fcols = var_cols[-1]
        r_idx += [np.full(8, e0), np.full(8, e0 + 1), np.full(8, e0 + 2), np.full(2, e0 + 3)]
        c_idx += [fcols, fcols, fcols, self._col_x(n - 1, np.array([3, 4]))]
        d_mach = -mi.final_mach_max * jf[8, :]
        d_mach[3] += 1.0
        vals += [-jf[9, :] / 1e3, jf[9, :] / 1e3, d_mach / 100.0,
                 -np.array([math.sin(xf[4]), xf[3] * math.cos(xf[4])]) / 100.0]
        r = np.concatenate(r_idx)
        c = np.concatenate(c_idx)
        v = np.concatenate(vals) * self.scale[c]
        G = sp.csc_matrix((v, (r, c)), shape=(self.n_inequalities, self.n_z))
        # --- objective ------------------------------------------------------------------------
        w = mesh.weights
        grad = np.zeros(self.n_z)
        if self.settings.objective == "heat_load":
            np.add.at(grad, var_cols.ravel(), (tf * w[:, None] * jac[:, 6, :] / HEAT_LOAD_SCALE).ravel())
        grad[self._col_x(np.arange(n), 5)] += tf * self.heading_lambda * w
        grad[self.i_tf] = base + self.heading_lambda * (w @ X[:, 5])
        grad *= self.scale
        return Linearisation(ev, grad, C, G)

    # ----- convex constraints -------------------------------------------------------------
    def add_convex_constraints(self, prog, z):
        """|u_k| <= 1 at every node (eq. 42) and the site cone with its buffer (eqs. 67-68)."""
        U = z[self._u].reshape(-1, self.n_u)
        A = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        b = np.array([1.0, 0.0, 0.0])
        for k in range(self.n_nodes):
            prog.AddLorentzConeConstraint(A, b, U[k])
        buffer = prog.NewContinuousVariables(1, "site_buffer")
        R, d = self.planet.reference_radius, 1e3  # cone rows in km
        lon_f, lat_f = z[self._col_x(self.n_nodes - 1, 1)], z[self._col_x(self.n_nodes - 1, 2)]
        A = np.array([[0.0, 0.0, 1.0],
                      [R * math.cos(self.site_lat) * STATE_SCALE[1] / d, 0.0, 0.0],
                      [0.0, R * STATE_SCALE[2] / d, 0.0]])
        b = np.array([self.mission.site_radius_m / d, -R * math.cos(self.site_lat) * self.site_lon / d,
                      -R * self.site_lat / d])
        prog.AddLorentzConeConstraint(A, b, np.array([lon_f, lat_f, buffer[0]]))
        return buffer

    # ----- diagnosis ------------------------------------------------------------------------
    def node_time(self, node: int, tf: float | None = None) -> str:
        s = self.mesh.s[node]
        return f"node {node} (s = {s:.3f})" if tf is None else f"node {node}, t = {s * tf:.0f} s"

    def describe_defect(self, i: int) -> str:
        seg, rest = divmod(i, (self.settings.nodes_per_segment - 1) * self.n_x)
        j, c = divmod(rest, self.n_x)
        node = self.mesh.segment_nodes[seg, j + 1]
        return f"{STATE_NAMES[c]} equation, segment {seg}, {self.node_time(node)}"

    def describe_inequality(self, i: int) -> str:
        if i >= self.n_path:
            return EVENT_NAMES[i - self.n_path] + " at the DRS point"
        node, c = divmod(i, len(PATH_NAMES))
        return f"{PATH_NAMES[c]} at {self.node_time(node + 1)}"

    def describe_convex(self, i: int) -> str:
        return f"landing-site cone (miss <= {self.mission.site_radius_m / 1e3:g} km)"
