"""Drag-energy entry guidance by pseudospectral convex optimisation (paper 000, Sec. VI).

The reference drag profile D(E) is planned in the inverse variable I = 1/D on LGL nodes in
energy (eq. 82). Then the range constraint is linear (eq. 83, with the ground-range
correction below), the corridor is a box (eq. 86), the initial drag and slope are linear
(eq. 84, corrected to I0' = -D0'/D0^2), and smoothness is two second-order cones:
||D1 I|| <= s', ||D2 I|| <= s'', minimise s' + s'' (eqs. 90-92). One SOCP, no initial
guess, solved with Clarabel (default) or SCS through Drake's MathematicalProgram.

Derivatives in the cones are taken in the normalised LGL variable tau (so s' and s''
are commensurate: in J/kg the I'' term would be about 1e7 times smaller than I'), and I
is scaled by a reference drag for conditioning.

Range: eq. 71 (R = -int dE / D) neglects cos(gamma) and R/r. We weight each node with
kappa = R_E cos(gamma) / r from the extracted states and re-solve (``range_iterations``),
so the ground range of the extracted trajectory equals the range to go.

After the solve, states and bank are extracted node by node on first use (eqs. 93-96):
altitude and speed from (E, D), gamma from D' (eq. 94), u_FF (eq. 95) and sigma (eq. 96),
with the bank saturated explicitly at [0, sigma_max] (flags returned).

The drag's reach (not paper 000's; ``DragEnergyProblem.reach_margin``): the SOCP bounds D but
not D'' = a_D + b_D u, which only the bank moves, so on a low-L/D vehicle the smoothest profile
may ask for more than full lift down. With a reach margin the profile is re-solved with each
node's u_FF (eq. 95) and sin(gamma) (eq. 94) linearised about the last solve and held in the
bank's range, inside a trust region (``_within_reach``).
"""
from __future__ import annotations

import dataclasses as dc
import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.solvers import ClarabelSolver, MathematicalProgram, ScsSolver, SolverOptions
from scipy.optimize import brentq

from drake_entry.errors import ScenarioError
from drake_entry.guidance.drag_energy.corridor import Corridor, compute_corridor
from drake_entry.guidance.drag_energy.drag_dynamics import (
    AlphaProfile,
    DragDynamics,
    DragTerms,
    drag_acceleration,
    drag_dynamics,
)
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.geodesy import bearing
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.models.vehicles import Vehicle
from drake_entry.planning.pseudospectral import LGL
from drake_entry.planning.result import PlanResult

__all__ = ["SOLVERS", "DragEnergyProblem", "Extraction", "DragEnergyReference", "plan", "SCS_OPTIONS", "solve_socp",
           "extract", "altitude_speed_from_drag", "DragEnergyPlanner", "reach_excess", "REACH_GAMMA_DEG"]

SOLVERS = {"clarabel": ClarabelSolver, "scs": ScsSolver}


@dataclass
class DragEnergyProblem:
    """One planning request.

    Attributes:
      vehicle, planet, atmosphere: models (the planner uses central gravity, eq. 37).
      alpha: angle-of-attack schedule in energy [rad vs J/kg].
      corridor: drag corridor covering [E_f, E_0] (drake_entry.guidance.drag_energy.corridor).
      E0, Ef: initial and final energy [J/kg], E0 > Ef.
      D0, D0_prime: drag [m/s^2] and dD/dE [1/m] at E0 (eqs. 72-74).
      range_to_go: ground distance to fly [m].
      Df, Df_prime: optional terminal drag and slope (eq. 85).
      lat0, latf, heading0, headingf: [rad] linear profiles for the Earth-rate term (eq. 50).
      n_nodes: LGL nodes. range_iterations: see module doc.
      solver: 'clarabel' (default) or 'scs' (``SCS_OPTIONS``; ``python benchmarks/run.py socp``:
        smooth to 0.7 % of Clarabel's eq. 92 at 20-40 nodes, 15x its time at 40; at 80 and 160
        nodes feasible but rough, eq. 92 6x and 84x, as SCS's tolerance is reached first).
      sigma_max: bank limit for extraction [rad].
    """

    vehicle: Vehicle
    planet: Earth
    atmosphere: Atmosphere
    alpha: Schedule
    corridor: Corridor
    E0: float
    Ef: float
    D0: float
    D0_prime: float
    range_to_go: float
    Df: float | None = None
    Df_prime: float | None = None
    lat0: float = 0.0
    latf: float = 0.0
    heading0: float = 0.0
    headingf: float = 0.0
    n_nodes: int = 40
    solver: str = "clarabel"
    range_iterations: int = 2
    sigma_max: float = math.radians(89.0)
    # a D0 outside the (margin-reduced) corridor by less than this fraction is projected onto it
    initial_tolerance: float = 0.03
    # first guess of the ground-range weight kappa(E) (e.g. from the previous plan), or None
    kappa_guess: object = None
    # corridor centring (not paper 000's; 0: the paper's smoothness alone): the weight of the least
    # share m of the corridor's width in I = 1/D that the profile keeps from both bounds, in the
    # cost s' + s'' - centring * m (eq. 92 is dimensionless in the scaled I: see _add_centring)
    centring: float = 0.0
    # the drag's reach (not paper 000's; None: the paper's SOCP, whose profile may ask for a D''
    # no bank gives): every node's feedforward u_FF (eq. 95) held in the bank's range of u less
    # this share of L/D on each side, by linearising u_FF about the previous solve inside a
    # trust region (successive convexification, at most ``reach_iterations`` more solves)
    reach_margin: float | None = None
    reach_iterations: int = 8

    def validate(self):
        if not self.E0 > self.Ef:
            raise ScenarioError(f"DragEnergyProblem needs E0 > Ef, got E0={self.E0:.6g}, Ef={self.Ef:.6g} J/kg")
        if not (self.corridor.energy[0] <= self.Ef and self.E0 <= self.corridor.energy[-1] + 1.0):
            raise ScenarioError(f"corridor covers [{self.corridor.energy[0]:.6g}, {self.corridor.energy[-1]:.6g}] "
                             f"J/kg, not [{self.Ef:.6g}, {self.E0:.6g}]")
        if self.solver not in SOLVERS:
            raise ScenarioError(f"solver '{self.solver}' is unknown; allowed: {', '.join(SOLVERS)}")
        if not 5 <= self.n_nodes <= 400:
            raise ScenarioError(f"n_nodes must be in [5, 400], got {self.n_nodes}")
        if self.reach_margin is not None and not 0.0 <= self.reach_margin <= 0.45:
            raise ScenarioError(f"reach_margin must be in [0, 0.45] (a share of L/D), got {self.reach_margin}")
        if not self.D0 > 0 or not self.range_to_go > 0:
            raise ScenarioError(f"D0 and range_to_go must be > 0 (got {self.D0}, {self.range_to_go})")


@dataclass
class Extraction:
    """States and bank at the nodes (eqs. 93-96). Arrays over nodes, SI / rad."""

    h: np.ndarray
    V: np.ndarray
    gamma: np.ndarray
    u_ff: np.ndarray
    sigma: np.ndarray
    saturated: np.ndarray  # True where |u_FF| exceeded what the bank can give
    lift_to_drag: np.ndarray


@dataclass
class DragEnergyReference(PlanResult):
    """Result of ``plan``: the reference D(E) and everything needed to fly it. ``objective``
    is s' + s'' of eq. 92 [s^2/m] (norms of the tau-derivatives of I); ``evaluate(E)``
    gives D, D', D''."""

    variable = "energy"

    problem: DragEnergyProblem
    lgl: LGL | None = None
    I: np.ndarray | None = None  # 1/D at the nodes [s^2/m]
    kappa: np.ndarray | None = None
    solver: str = ""
    binding: list = field(default_factory=list)  # which bounds bind, where (diagnosis)
    corridor_share: float = math.nan  # centring: the share of the corridor's width kept from each bound
    reach_excess: float = math.nan  # the drag's reach: the largest u_FF past its range, a share of L/D (0: met)
    _nodal: np.ndarray | None = field(default=None, repr=False)
    _extraction: Extraction | None = field(default=None, repr=False)

    @property
    def extraction(self) -> Extraction | None:
        """States and bank at the nodes (eqs. 93-96), extracted on first use (None unless
        solved). The closed loop tracks D(E) alone, so its re-plans never pay for them."""
        if self._extraction is None and self.I is not None:
            self._extraction = extract(self.problem, self.lgl, self.I)
        return self._extraction

    # -- the profile and its energy derivatives -----------------------------------------
    @property
    def energy(self) -> np.ndarray:
        return self.lgl.x

    @property
    def D(self) -> np.ndarray:
        return 1.0 / self.I

    def profile(self, E):
        """(D, D', D'') at energies E (eqs. 87-88 from the interpolated I(E); held at the ends).
        Arrays of the shape of ``np.atleast_1d(E)``."""
        if self._nodal is None:  # I, I', I'' at the nodes, once
            self._nodal = np.vstack([self.I, self.lgl.D1 @ self.I, self.lgl.D2 @ self.I]).T
        if np.ndim(E) == 0:  # the guidance's once-a-period call: one barycentric row (eq. 9)
            op = self.lgl
            E = min(max(float(E), self.problem.Ef), self.problem.E0)
            d = (2.0 * E - (op.a + op.b)) / (op.b - op.a) - op.tau
            if d.all():
                w = op.bary / d
                I, I1, I2 = ((w @ self._nodal) / w.sum()).tolist()
            else:  # on a node
                I, I1, I2 = self._nodal[int(np.argmin(np.abs(d)))].tolist()
        else:
            E = np.clip(np.atleast_1d(np.asarray(E, float)), self.problem.Ef, self.problem.E0)
            I, I1, I2 = (self.lgl.interpolation(E) @ self._nodal).T
        D, D1, D2 = _from_inverse(I, I1, I2)
        return np.atleast_1d(D), np.atleast_1d(D1), np.atleast_1d(D2)

    def evaluate(self, at) -> dict:
        """{'drag_m_s2', 'drag_slope_1_m' (dD/dE), 'drag_curvature_s2_m3' (d2D/dE2)} at energies [J/kg]."""
        D, Dp, Dpp = self.profile(np.atleast_1d(np.asarray(at, float)))
        return {"drag_m_s2": D, "drag_slope_1_m": Dp, "drag_curvature_s2_m3": Dpp}

    def kappa_at(self, E) -> np.ndarray:
        """Ground-range weight kappa = R cos(gamma)/r interpolated at energies E."""
        return np.interp(E, self.energy[::-1], self.kappa[::-1])

    def range_flown(self) -> float:
        """Ground range of the profile [m] (eq. 83 with kappa)."""
        return float(-self.lgl.weights @ (self.kappa * self.I))

    def corridor_violation(self, n_dense: int = 2000) -> dict:
        """Largest relative excursion outside the corridor on a dense energy grid (between
        nodes too), and where (normalised energy e = (E0 - E)/(E0 - Ef))."""
        p = self.problem
        E = np.linspace(p.E0, p.Ef, n_dense)
        D = self.profile(E)[0]
        lo, hi = p.corridor.bounds(E)
        over = D / hi - 1.0
        under = 1.0 - D / lo
        e = (p.E0 - E) / (p.E0 - p.Ef)
        return {"above_max": float(max(over.max(), 0.0)), "above_max_at_e": float(e[over.argmax()]),
                "below_min": float(max(under.max(), 0.0)), "below_min_at_e": float(e[under.argmax()])}


def _alpha_profile(alpha: Schedule, E: float) -> AlphaProfile:
    return AlphaProfile(*alpha.derivatives(E))


def plan(problem: DragEnergyProblem) -> DragEnergyReference:
    """Solve the drag-energy SOCP (eqs. 82-92) and extract states and bank (eqs. 93-96).

    Never raises for an infeasible request: the result says which bound binds and where.
    """
    problem.validate()
    p = problem
    op = LGL(p.n_nodes, p.E0, p.Ef)
    D_lo, D_hi = p.corridor.bounds(op.x)
    note = ""
    D0_in = min(max(p.D0, D_lo[0]), D_hi[0])
    if D0_in != p.D0 and abs(D0_in / p.D0 - 1.0) <= p.initial_tolerance:
        note = f" (initial drag {p.D0:.4g} projected onto the corridor bound {D0_in:.4g} m/s^2)"
        p = dc.replace(p, D0=D0_in)
    diag = _diagnose(p, op, D_lo, D_hi)
    if diag:
        return DragEnergyReference(success=False, message="; ".join(d["message"] for d in diag), problem=p, lgl=op,
                                   binding=diag)
    # ground-range weights: the guess, or eq. 71's kappa = 1 until the first extraction
    kappa = np.ones(p.n_nodes) if p.kappa_guess is None else np.asarray(p.kappa_guess(op.x), float)
    ref = None
    total_build = total_solve = 0.0
    total_iterations = 0
    iterations = max(1, p.range_iterations)
    for k in range(iterations):
        ref = solve_socp(p, op, D_lo, D_hi, kappa)
        total_build += ref.build_time
        total_solve += ref.solve_time
        total_iterations += ref.iterations
        if not ref.success:
            break
        ref.kappa = kappa  # the weights this solve satisfied exactly (eq. 83)
        if k + 1 < iterations:  # the next solve's weights from this one's states
            x = ref.extraction
            kappa = p.planet.reference_radius * np.cos(x.gamma) / p.planet.radius(x.h)
    if ref.success and p.reach_margin is not None:
        ref, spent = _within_reach(p, op, D_lo, D_hi, ref)
        total_build, total_solve, total_iterations = (total_build + spent[0], total_solve + spent[1],
                                                      total_iterations + spent[2])
    ref.build_time, ref.solve_time, ref.iterations = total_build, total_solve, total_iterations
    ref.message += note
    if ref.success:
        ref.binding = _binding(ref, D_lo, D_hi)
    return ref


#: SCS options of the drag-energy SOCP on its conditioned form (``solve_socp``): eps 1e-5 meets
#: the planner's own check (``_check_solution``) with eq. 92 within 0.7 % of Clarabel's at
#: 20-40 nodes in 800-4 925 iterations (3-48 ms); see docs/methods/drag-energy.md
SCS_OPTIONS = {"eps_abs": 1e-5, "eps_rel": 1e-5, "max_iters": 100000}


def solve_socp(p: DragEnergyProblem, op: LGL, D_lo, D_hi, kappa, reach: tuple | None = None) -> DragEnergyReference:
    """One SOCP of eqs. 82-92 on the LGL operator ``op`` with corridor bounds D_lo, D_hi [m/s^2]
    at its nodes and fixed range weights kappa (``plan`` iterates it and extracts the states).

    Conditioned for a first-order solver (SCS measures its residuals relative to the largest
    row): the range row (eq. 83) is divided by the range to go [m], the initial-drag rows
    (eq. 84-85) by their largest entry, and each cone of eq. 91 by its operator's 2-norm (|D2|
    is 3e5 at 40 nodes), the cost weighted to stay eq. 92 divided by |D2|; unconditioned, SCS
    needed 28 000 iterations at 40 nodes and did not converge at 80. Clarabel (interior point)
    solves the plain form: conditioned, its optimum moved by up to 3e-4 (relative, within its
    tolerance on this flat optimum) and the closed-loop campaign rows by up to 327 m.

    ``reach``: (A, lo, hi, I_lo, I_hi) adds lo <= A I <= hi and the trust region I_lo <= I <= I_hi
    (I in s^2/m: ``_within_reach``'s linearised drag reach)."""
    conditioned = p.solver == "scs"
    t0 = time.perf_counter()
    n = p.n_nodes
    scale = p.D0  # I_hat = I * scale is O(1)
    prog = MathematicalProgram()
    I = prog.NewContinuousVariables(n, "I")
    s = prog.NewContinuousVariables(2, "s")
    prog.AddBoundingBoxConstraint(scale / D_hi, scale / D_lo, I)  # eq. 86
    if reach is not None:  # the linearised reach of the drag and its trust region (_within_reach)
        A_u, u_lo, u_hi, I_lo, I_hi = reach
        slack = prog.NewContinuousVariables(len(u_lo), "reach_slack")  # exact penalty: always feasible
        prog.AddBoundingBoxConstraint(0.0, np.inf, slack)
        eye = np.eye(len(u_lo))
        prog.AddLinearConstraint(np.hstack([A_u / scale, eye]), u_lo, np.full(len(u_lo), np.inf),
                                 np.concatenate([I, slack]))
        prog.AddLinearConstraint(np.hstack([A_u / scale, -eye]), np.full(len(u_lo), -np.inf), u_hi,
                                 np.concatenate([I, slack]))
        prog.AddLinearCost(np.full(len(u_lo), REACH_PENALTY), 0.0, slack)
        prog.AddBoundingBoxConstraint(scale * I_lo, scale * I_hi, I)
    # eq. 83 with the ground-range weights kappa: R = -sum w_i kappa_i I_i (divided by R if conditioned)
    R = p.range_to_go if conditioned else 1.0
    prog.AddLinearEqualityConstraint((-op.weights * kappa / (scale * R))[None, :], [p.range_to_go / R], I)
    # eq. 84 (corrected): I0 = 1/D0, dI/dtau(-1) = (dE/dtau) * (-D0'/D0^2)
    half = (op.b - op.a) / 2.0
    A0 = np.vstack([np.eye(n)[0], op.D1_tau[0]])
    b0 = np.array([1.0, half * (-p.D0_prime / p.D0**2) * scale])
    if p.Df is not None:  # eq. 85
        A0 = np.vstack([A0, np.eye(n)[-1]])
        b0 = np.append(b0, scale / p.Df)
        if p.Df_prime is not None:
            A0 = np.vstack([A0, op.D1_tau[-1]])
            b0 = np.append(b0, half * (-p.Df_prime / p.Df**2) * scale)
    row = np.abs(A0).max(axis=1) if conditioned else np.ones(len(A0))
    prog.AddLinearEqualityConstraint(A0 / row[:, None], b0 / row, I)
    # eq. 91: ||D1 I|| / |D1| <= s1, ||D2 I|| / |D2| <= s2 as Lorentz cones on [s_k, I] (norms 1 if plain)
    norms = np.array([np.linalg.norm(Dk, 2) for Dk in (op.D1_tau, op.D2_tau)]) if conditioned else np.ones(2)
    for k, Dk in enumerate((op.D1_tau, op.D2_tau)):
        A = np.zeros((n + 1, n + 1))
        A[0, 0] = 1.0
        A[1:, 1:] = Dk / norms[k]
        prog.AddLorentzConeConstraint(A, np.zeros(n + 1), np.concatenate([[s[k]], I]))
    prog.AddLinearCost(norms / norms[1], 0.0, s)  # eq. 92 (divided by |D2| if conditioned)
    m = (_add_centring(prog, op, I, scale / D_hi, scale / D_lo, p.centring / norms[1])  # as eq. 92's cost
         if p.centring > 0.0 else None)
    t1 = time.perf_counter()
    result = _solve(prog, p.solver)
    t2 = time.perf_counter()
    ok = result.is_success()
    details = result.get_solver_details()
    iters = int(getattr(details, "iterations", getattr(details, "iter", 0)) or 0)
    msg = "optimal" if ok else f"{p.solver} returned {result.get_solution_result().name}"
    I_sol = result.GetSolution(I) / scale if ok else None
    if ok:  # check the answer ourselves: some solvers report "solved inaccurate" as success
        problem_msg = _check_solution(p, op, I_sol, D_lo, D_hi, kappa)
        if problem_msg:
            ok, msg = False, f"{p.solver} returned an inaccurate solution: {problem_msg}"
    return DragEnergyReference(success=ok, message=msg, problem=p, lgl=op, I=I_sol if ok else None, solver=p.solver,
                               build_time=t1 - t0, solve_time=t2 - t1, iterations=iters,
                               objective=_smoothness(op, I_sol) if ok else math.nan,
                               corridor_share=float(result.GetSolution(m)[0]) if ok and m is not None else math.nan)


#: the trust region of the reach iterations: each node's I within this share of the last solve's
REACH_TRUST = 0.25
#: the weight of the reach rows' slack (u and sin(gamma) units) beside eq. 92's cost: large, so
#: a solve within reach has no slack, and one out of it moves as far toward it as the trust allows
REACH_PENALTY = 1.0e4
#: the steepest flight-path angle [deg] a plan within reach may ask for (eq. 94)
REACH_GAMMA_DEG = 60.0
#: a plan is within reach when no node's u_FF leaves its range by more than this share of L/D
#: and none descends more than this [rad] steeper than REACH_GAMMA_DEG
REACH_TOLERANCE = 1.0e-3


def _u_range(p: DragEnergyProblem, ld: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The range of u = (L/D) cos(sigma) a plan may ask for at nodes of lift-to-drag ``ld``: the
    bank's [0, sigma_max], less ``reach_margin`` L/D on each side (left to the tracking law)."""
    m = p.reach_margin or 0.0
    return ld * (math.cos(p.sigma_max) + m), ld * (1.0 - m)


def _reach_shortfall(p: DragEnergyProblem, x: Extraction) -> tuple[np.ndarray, np.ndarray]:
    """(each node's share of L/D by which u_FF (eq. 95) leaves ``_u_range`` (<= 0 within it),
    whether the node's descent is steeper than REACH_GAMMA_DEG by more than REACH_TOLERANCE rad)."""
    lo, hi = _u_range(p, x.lift_to_drag)
    with np.errstate(invalid="ignore"):
        past = np.maximum((x.u_ff - hi) / x.lift_to_drag, (lo - x.u_ff) / x.lift_to_drag)
    return past, np.abs(x.gamma) > math.radians(REACH_GAMMA_DEG) + REACH_TOLERANCE


def reach_excess(p: DragEnergyProblem, x: Extraction) -> float:
    """The largest share of L/D by which the profile's u_FF (eq. 95) leaves ``_u_range`` (0 when
    every node is within it; inf where the profile asks for a descent steeper than
    REACH_GAMMA_DEG). Within reach: at most REACH_TOLERANCE (``_out_of_reach`` names the nodes
    past it)."""
    past, steep = _reach_shortfall(p, x)
    return float(max(0.0, np.nanmax(np.where(steep, np.inf, past))))


def _reach_rows(p: DragEnergyProblem, op: LGL, I: np.ndarray, x: Extraction) -> tuple:
    """u_FF and sin(gamma) at every node linearised in I about the profile I [s^2/m] (extraction
    ``x``): both depend on I through I_k, I'_k, I''_k alone (eqs. 87-88, 93-95); their partials
    by forward differences, each row then e_k, D1[k], D2[k] combined. sin(gamma) is held within
    sin(REACH_GAMMA_DEG) (eq. 94's D' of a steeper descent leaves no vertical control: b_D is
    cos(gamma)'s), u_FF within ``_u_range`` where gamma is (elsewhere u_FF is not defined).
    Returns (A, lo, hi, I_lo, I_hi): the rows of lo <= A I <= hi, and the trust region
    (REACH_TRUST)."""
    n = op.n_nodes
    I1, I2 = op.D1 @ I, op.D2 @ I
    span = p.E0 - p.Ef
    u_lo, u_hi = _u_range(p, x.lift_to_drag)
    s_max = math.sin(math.radians(REACH_GAMMA_DEG))
    rows, lo, hi = [], [], []
    for k in range(n):
        base = (I[k], I1[k], I2[k])
        ref = _node_state(p, op, k, *_from_inverse(*base), x.h[k])
        steps = (1e-6 * I[k], 1e-6 * (abs(I1[k]) + I[k] / span), 1e-6 * (abs(I2[k]) + I[k] / span**2))
        grads = []
        for j, step in enumerate(steps):
            v = list(base)
            v[j] += step
            out = _node_state(p, op, k, *_from_inverse(*v), x.h[k])
            grads.append(((out[3] - ref[3]) / step, (out[6] - ref[6]) / step))
        for q, (value, low, high) in enumerate(((ref[3], u_lo[k], u_hi[k]), (ref[6], -s_max, s_max))):
            if q == 0 and abs(ref[6]) >= s_max:
                continue
            row = grads[0][q] * np.eye(n)[k] + grads[1][q] * op.D1[k] + grads[2][q] * op.D2[k]
            offset = value - row @ I  # value(I) ~ value_ref + row (I - I_ref)
            rows.append(row)
            lo.append(low - offset)
            hi.append(high - offset)
    return np.array(rows), np.array(lo), np.array(hi), I * (1.0 - REACH_TRUST), I * (1.0 + REACH_TRUST)


def _from_inverse(I, I1, I2) -> tuple:
    """(D, D', D'') from I = 1/D and its energy derivatives I', I'' (eqs. 87-88; scalars or arrays)."""
    return 1.0 / I, -I1 / I**2, 2.0 * I1**2 / I**3 - I2 / I**2


def _within_reach(p: DragEnergyProblem, op: LGL, D_lo, D_hi, ref: DragEnergyReference) -> tuple:
    """The profile re-solved until its u_FF is within ``_u_range`` at every node (REACH_TOLERANCE),
    at most ``reach_iterations`` more SOCPs, each linearised about the last (``_reach_rows``).
    Returns (the last successful reference, with ``reach_excess`` set and the message saying
    whether the reach was met; (build, solve, iterations) spent)."""
    spent = [0.0, 0.0, 0]
    excess = reach_excess(p, ref.extraction)
    for _ in range(p.reach_iterations):
        if excess <= REACH_TOLERANCE:
            break
        new = solve_socp(p, op, D_lo, D_hi, ref.kappa, reach=_reach_rows(p, op, ref.I, ref.extraction))
        spent = [spent[0] + new.build_time, spent[1] + new.solve_time, spent[2] + new.iterations]
        if not new.success:
            ref.message += f"; the drag's reach not met ({new.message})"
            break
        new.kappa = ref.kappa
        ref, excess = new, reach_excess(p, new.extraction)
    ref.reach_excess = excess
    if excess > REACH_TOLERANCE:
        ref.message += f"; {_out_of_reach(p, op, ref.extraction)}"
    return ref, spent


def _out_of_reach(p: DragEnergyProblem, op: LGL, x: Extraction) -> str:
    """Where a profile leaves the drag's reach (``reach_excess`` above REACH_TOLERANCE): each such
    node's normalised energy, u_FF in L/D and flight-path angle."""
    past, steep = _reach_shortfall(p, x)
    out = (past > REACH_TOLERANCE) | steep
    e = (p.E0 - op.x) / (p.E0 - p.Ef)
    nodes = ", ".join(f"e = {e[k]:.3f} (u_FF {x.u_ff[k] / x.lift_to_drag[k]:+.3g} L/D, gamma "
                      f"{math.degrees(x.gamma[k]):.1f} deg)" for k in np.flatnonzero(out))
    return f"the drag's reach not met at {nodes}"


def _solve(prog: MathematicalProgram, solver_name: str):
    """Solve with Clarabel (fast options, then its defaults on a stall) or SCS (``SCS_OPTIONS``)."""
    solver = SOLVERS[solver_name]()
    options = SolverOptions()
    if solver_name == "scs":
        for k, v in SCS_OPTIONS.items():
            options.SetOption(solver.solver_id(), k, v)
        return solver.Solve(prog, None, options)
    # Clarabel's iterative refinement of each KKT solve took about 30 % of the solve time here
    # and moved the 40-node solution by 5e-9 (relative); _check_solution verifies the result.
    # Without it Clarabel stalled (InsufficientProgress) in about 1 of 170 re-plans: then
    # the problem is solved again with Clarabel's defaults.
    options.SetOption(solver.solver_id(), "iterative_refinement_enable", False)
    drake_log = logging.getLogger("drake")
    level = drake_log.level
    drake_log.setLevel(logging.WARNING)  # the fast attempt's rare stall is expected: no INFO line
    try:
        result = solver.Solve(prog, None, options)
    finally:
        drake_log.setLevel(level)
    return result if result.is_success() else solver.Solve(prog, None, SolverOptions())


def _add_centring(prog, op: LGL, I_top, I_hi, I_lo, weight: float):
    """The corridor-centring term (not paper 000's): a margin m in [0, 1/2], every node's scaled
    I at least m r_k of the corridor's width in I inside both bounds, and the cost -weight * m
    beside eq. 92. The ramp r_k grows from 0 at the first and last nodes (fixed by eqs. 84-85)
    to 1 a tenth of the energy span in. Eq. 92's s' + s'' is taken on I scaled by D0 and in the
    normalised tau, so both terms are dimensionless; at 40 nodes a weight of 1000 keeps about
    four fifths of the largest margin the range allows (Lu 2014's CAV-H at engagement: m = 0.24
    of a largest 0.30), 100 about three fifths. Returns m."""
    m = prog.NewContinuousVariables(1, "m")
    prog.AddBoundingBoxConstraint(0.0, 0.5, m)
    e = (op.x - op.x[0]) / (op.x[-1] - op.x[0])
    ramp = np.clip(np.minimum(e, 1.0 - e) / 0.1, 0.0, 1.0)
    width = I_lo - I_hi
    n = len(op.x)
    k = np.flatnonzero(ramp > 0.0)
    A = np.zeros((len(k), n + 1))
    A[np.arange(len(k)), k] = 1.0
    A[:, n] = -ramp[k] * width[k]  # I_k - m r_k w_k >= I_hi
    prog.AddLinearConstraint(A, I_hi[k], np.full(len(k), np.inf), np.concatenate([I_top, m]))
    A[:, n] = ramp[k] * width[k]  # I_k + m r_k w_k <= I_lo
    prog.AddLinearConstraint(A, np.full(len(k), -np.inf), I_lo[k], np.concatenate([I_top, m]))
    prog.AddLinearCost([-weight], 0.0, m)
    return m


def _smoothness(op: LGL, I) -> float:
    """The objective of eq. 92 at I [s^2/m]: ||D1 I|| + ||D2 I|| (tau derivatives)."""
    return float(np.linalg.norm(op.D1_tau @ I) + np.linalg.norm(op.D2_tau @ I))


def _check_solution(p: DragEnergyProblem, op: LGL, I, D_lo, D_hi, kappa, tol: float = 1e-3,
                    tol_range: float = 1e-5) -> str:
    """'' if I satisfies the corridor (eq. 86) within ``tol`` (relative; the corridor already
    carries its safety margin), the range (eq. 83) within ``tol_range`` and the initial
    drag (eq. 84), else what fails where."""
    D = 1.0 / I
    e = (p.E0 - op.x) / (p.E0 - p.Ef)
    over = D / D_hi - 1.0
    under = 1.0 - D / D_lo
    if over.max() > tol:
        k = int(over.argmax())
        return f"D_max exceeded by {100 * over[k]:.3g} % at e = {e[k]:.3f}"
    if under.max() > tol:
        k = int(under.argmax())
        return f"D_min undercut by {100 * under[k]:.3g} % at e = {e[k]:.3f}"
    rng = float(-op.weights @ (kappa * I))
    if abs(rng / p.range_to_go - 1.0) > tol_range:
        return f"range {rng / 1e3:.3f} km instead of {p.range_to_go / 1e3:.3f} km"
    if abs(I[0] * p.D0 - 1.0) > tol_range:
        return f"initial drag {1 / I[0]:.5g} instead of {p.D0:.5g} m/s^2"
    return ""


def _reachable_range(op: LGL, D) -> float:
    """Range [m] flown on the profile D at the nodes (eq. 83 with kappa = 1)."""
    return float(-op.weights @ (1.0 / D))


def _diagnose(p: DragEnergyProblem, op: LGL, D_lo, D_hi) -> list:
    """Name the bound that makes the request infeasible before calling the solver."""
    out = []
    e = (p.E0 - op.x) / (p.E0 - p.Ef)
    empty = D_lo > D_hi
    if empty.any():
        k = int(np.flatnonzero(empty)[0])
        E = float(op.x[k])
        limit = _binding_limit(p.corridor, E)
        out.append({"bound": "corridor", "where_e": float(e[k]), "limit": limit,
                    "message": f"corridor empty (D_min > D_max) from e = {e[k]:.3f} to {e[empty][-1]:.3f}: at "
                               f"e = {e[k]:.3f} (E = {E / 1e6:.3f} MJ/kg) the {limit.replace('_', ' ')} limit "
                               f"caps the drag at {D_hi[k]:.3g} m/s^2, below the "
                               f"{D_lo[k]:.3g} m/s^2 the equilibrium glide needs (margin {p.corridor.margin:g} "
                               f"included): reduce the margin, change alpha(E) or move the interface"})
        return out
    if not D_lo[0] <= p.D0 <= D_hi[0]:
        side = "above D_max" if p.D0 > D_hi[0] else "below D_min"
        out.append({"bound": "initial_drag", "where_e": 0.0,
                    "message": f"initial drag {p.D0:.4g} m/s^2 is {side} "
                               f"[{D_lo[0]:.4g}, {D_hi[0]:.4g}] at E0"})
    if p.Df is not None and not D_lo[-1] <= p.Df <= D_hi[-1]:
        side = "above D_max" if p.Df > D_hi[-1] else "below D_min"
        out.append({"bound": "terminal_drag", "where_e": 1.0,
                    "message": f"terminal drag {p.Df:.4g} m/s^2 is {side} [{D_lo[-1]:.4g}, {D_hi[-1]:.4g}] "
                               f"at Ef (e.g. the q limit at the nominal terminal point)"})
    R_min = _reachable_range(op, D_hi)
    R_max = _reachable_range(op, D_lo)
    if p.range_to_go < R_min:
        out.append({"bound": "D_max", "where_e": None,
                    "message": f"range to go {p.range_to_go / 1e3:.1f} km is shorter than the corridor allows "
                               f"({R_min / 1e3:.1f} km flying on D_max everywhere): the upper bound binds"})
    elif p.range_to_go > R_max:
        out.append({"bound": "D_min", "where_e": None,
                    "message": f"range to go {p.range_to_go / 1e3:.1f} km is longer than the corridor allows "
                               f"({R_max / 1e3:.1f} km flying on D_min everywhere): the lower bound binds"})
    return out


def _binding_limit(corridor, E: float) -> str:
    """The upper bound (heat_flux, normal_load, dynamic_pressure, total_load) that sets D_max at E [J/kg]."""
    names = list(corridor.upper)
    caps = [float(np.interp(E, corridor.energy, corridor.upper[n])) for n in names]
    return names[int(np.argmin(caps))]


def _binding(ref: DragEnergyReference, D_lo, D_hi, tol: float = 1e-4) -> list:
    """Where the solution rides a corridor bound (at nodes)."""
    D = ref.D
    e = (ref.problem.E0 - ref.energy) / (ref.problem.E0 - ref.problem.Ef)
    out = []
    for name, mask in (("D_max", D >= D_hi * (1 - tol)), ("D_min", D <= D_lo * (1 + tol))):
        if mask.any():
            out.append({"bound": name, "nodes": int(mask.sum()), "e": e[mask].round(4).tolist()})
    return out


def extract(p: DragEnergyProblem, op: LGL, I: np.ndarray) -> Extraction:
    """States and bank at the nodes (eqs. 93-96)."""
    n = op.n_nodes
    D, Dp, Dpp = _drag_derivatives(op, I)
    out = {k: np.zeros(n) for k in ("h", "V", "gamma", "u_ff", "sigma", "ld")}
    sat = np.zeros(n, bool)
    lo = math.cos(p.sigma_max)
    h = slope = None
    for i, E in enumerate(op.x):
        h, V, gamma, u, ld, slope, _ = _node_state(p, op, i, D[i], Dp[i], Dpp[i], h, slope)
        ratio = u / ld
        sat[i] = ratio > 1.0 or ratio < lo
        sigma = math.acos(min(max(ratio, lo), 1.0))  # eq. 96, saturated
        for k, v in (("h", h), ("V", V), ("gamma", gamma), ("u_ff", u), ("sigma", sigma), ("ld", ld)):
            out[k][i] = v
    return Extraction(out["h"], out["V"], out["gamma"], out["u_ff"], out["sigma"], sat, out["ld"])


def _drag_derivatives(op: LGL, I: np.ndarray) -> tuple:
    """(D, D', D'') at the nodes from I = 1/D [s^2/m] (eqs. 87-88)."""
    return _from_inverse(I, op.D1 @ I, op.D2 @ I)


def _node_state(p: DragEnergyProblem, op: LGL, i: int, D: float, Dp: float, Dpp: float, h_guess=None,
                slope_guess=None) -> tuple:
    """(h [m], V [m/s], gamma [rad], u_FF, L/D, the secant slope, sin(gamma) as eq. 94 gives it
    (past +-1 where D' asks for a descent steeper than vertical)) at node i of a profile with
    drag D, D', D'' there: altitude and speed from (E, D) (eq. 93), gamma from D' (eq. 94),
    u_FF (eq. 95), the latitude and heading linear in energy (eq. 50)."""
    E = float(op.x[i])
    frac = (p.E0 - E) / (p.E0 - p.Ef)
    alpha = _alpha_profile(p.alpha, E)
    lat = p.lat0 + frac * (p.latf - p.lat0)
    heading = p.heading0 + frac * (p.headingf - p.heading0)
    h, V, slope = _altitude_speed(E, D, alpha.alpha, p.vehicle, p.planet, p.atmosphere, h_guess=h_guess,
                                  slope_guess=slope_guess, lat=lat)
    terms = DragTerms(h, V, alpha, p.vehicle, p.planet, p.atmosphere, lat=lat, heading=heading)
    sin_gamma = (Dp - terms.a_Dgamma) / terms.b_Dgamma  # eq. 94, past +-1 where D' asks for it
    gamma = math.asin(min(max(sin_gamma, -1.0), 1.0))
    dd = terms.at(gamma, lat=lat, heading=heading)
    return h, V, gamma, dd.feedforward(Dpp), dd.lift_to_drag, slope, sin_gamma  # eq. 95


def altitude_speed_from_drag(E: float, D: float, alpha: float, vehicle: Vehicle, planet: Earth,
                             atmosphere: Atmosphere, h_floor: float = 0.0, h_guess: float | None = None,
                             lat: float = 0.0):
    """(state altitude h, V) on energy level E where the drag equals D (eq. 93), to 1e-4 m, the
    air read at ``planet.atmospheric_altitude(h, lat)`` (lat [rad]).

    With ``h_guess`` (the neighbouring node's altitude) a secant iteration on ln D, nearly
    linear in h, converges in a few model evaluations; Brent's bracketed method is the
    fallback and the default."""
    return _altitude_speed(E, D, alpha, vehicle, planet, atmosphere, h_floor, h_guess, lat=lat)[:2]


def _altitude_speed(E, D, alpha, vehicle, planet, atmosphere, h_floor=0.0, h_guess=None, slope_guess=None,
                    lat: float = 0.0):
    """altitude_speed_from_drag and the last secant slope d ln D / dh [1/m] (None after
    Brent), which starts the next node's secant one model evaluation closer."""
    h_top = min(planet.mu / (-E) - planet.reference_radius - 1.0,
                float(planet.state_altitude(atmosphere.h_max, lat)))

    def f(h):
        V = math.sqrt(max(2.0 * (E + planet.mu / planet.radius(h)), 0.0))
        return drag_acceleration(float(planet.atmospheric_altitude(h, lat)), V, alpha, vehicle, atmosphere) - D

    h_lo = float(planet.state_altitude(h_floor, lat))  # the air's floor as a state altitude
    found = _secant_log_drag(f, D, h_guess, h_lo, h_top, slope_guess) if h_guess is not None else None
    h, slope = found if found is not None else (brentq(f, h_lo, h_top, xtol=1e-4), None)
    return h, math.sqrt(2.0 * (E + planet.mu / planet.radius(h))), slope


def _secant_log_drag(f, D: float, h0: float, lo: float, hi: float, slope: float | None = None,
                     tol: float = 1e-4, iterations: int = 12):
    """(root of f(h) + D = D, last slope) by secant steps on ln(f(h) + D) - ln D, the first
    step a Newton step with ``slope`` when given; None unless it converges in [lo, hi]."""
    def g(h):
        v = f(h) + D
        return math.log(v / D) if v > 0.0 else None

    a = min(max(h0, lo), hi)
    ga = g(a)
    if ga is None:
        return None
    if abs(ga) < 1e-12:
        return a, slope
    step = -ga / slope if slope is not None and slope < 0.0 else 200.0
    b = min(max(a + step, lo), hi)
    gb = g(b)
    for _ in range(iterations):
        if gb is None or gb == ga or a == b:
            return None
        s = (gb - ga) / (b - a)
        c = b - gb / s
        if not lo <= c <= hi:
            return None
        if abs(c - b) < tol:
            return c, s
        a, ga, b, gb = b, gb, c, g(c)
    return None


class DragEnergyPlanner:
    """Plans drag-energy references from navigation states for one mission.

    The corridor depends only on energy (alpha is scheduled in energy), so it is computed
    once here and shared by every plan, every re-plan and every Monte-Carlo sample.
    """

    def __init__(self, *, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, alpha: Schedule,
                 target_lon: float, target_lat: float, E_entry: float, E_final: float, n_nodes: int = 40,
                 solver: str = "clarabel", margin: float = 0.03, corridor_points: int = 300,
                 sigma_max: float | None = None, terminal_drag: float | None = None,
                 terminal_state: tuple | None = None, replan_start: str = "flown", centring: float = 0.0,
                 range_offset: float = 0.0, entry_lat: float | None = None, reach_margin: float | None = None):
        """``entry_lat`` [rad]: where the corridor reads the air (``lat_of_E``); None reads it at
        the state altitude (the same on a spherical planet). ``terminal_drag`` (D_f of eq. 85)
        is taken within the corridor at E_final (SPHYNX's DRS point, Mach 0.5 at 11.5 km
        geodetic, lies under the equilibrium glide: the plan ends on the corridor's floor)."""
        if alpha.variable != "energy":
            raise ScenarioError(f"the drag-energy planner needs alpha scheduled in energy, got '{alpha.variable}'")
        self.vehicle, self.atmosphere, self.alpha = vehicle, atmosphere, alpha
        self.planet = planet.with_(j2=0.0)  # paper 000 eq. 37: central gravity in the planner
        self.target = (target_lon, target_lat)
        self.E_entry, self.E_final = E_entry, E_final
        self.terminal_drag = terminal_drag  # D_f of eq. 85, or None (free)
        self.terminal_state = terminal_state  # (h_f [m], V_f [m/s]): where D_f is taken (sensed re-plans)
        self.n_nodes, self.solver = n_nodes, solver
        self.replan_start = replan_start  # DragEnergy.replan_start: "flown" or "reference"
        self.centring = centring  # DragEnergy.corridor_centring
        self.range_offset = float(range_offset)  # DragEnergy.range_offset_m
        self.reach_margin = reach_margin  # DragEnergy.reach_margin
        self.sigma_max = vehicle.bank_limit if sigma_max is None else sigma_max
        E = np.linspace(E_final, E_entry + 0.02 * (E_entry - E_final), corridor_points)
        self.margin = margin
        self.entry_lat = entry_lat
        self.corridor = self._corridor(E, vehicle)
        if terminal_drag is not None:  # D_f within the corridor, as a re-plan in the sensed air takes it
            D_lo, D_hi = self.corridor.bounds(np.array([E_final]))
            self.terminal_drag = float(min(max(terminal_drag, D_lo[0]), D_hi[0]))
        self._sensed: tuple = (None, None)  # (rounded scales, their overrides): the last one asked

    def lat_of_E(self, E: float) -> float:
        """The latitude [rad] the corridor reads the air at, at energy E [J/kg]: linear in energy
        from the entry's to the target's (as eq. 50's Earth-rate term takes it); the target's
        below E_final, the entry's above E_entry. On an oblate planet the geodetic offset of the
        air changes with it (SPHYNX: 5.3 km at the entry's 29.8 deg, 7.7 km at the site's 36.8)."""
        share = min(max((self.E_entry - E) / (self.E_entry - self.E_final), 0.0), 1.0)
        return self.entry_lat + share * (self.target[1] - self.entry_lat)

    def _corridor(self, energies, vehicle: Vehicle) -> Corridor:
        """The corridor of ``vehicle`` on ``energies`` [J/kg] with this planner's alpha, margin and
        air (``lat_of_E`` when the entry latitude is known)."""
        return compute_corridor(energies, self.alpha, vehicle, self.planet, self.atmosphere, margin=self.margin,
                                lat_of_E=None if self.entry_lat is None else self.lat_of_E)

    def sensed(self, scales) -> dict:
        """The ``problem`` overrides of a re-plan in the flight's sensed air: the vehicle with
        its lift and drag coefficients times ``scales`` = (k_L, k_D) and its q and heat-rate
        limits divided by the sensed density ratio (models.acceleration_ratios.sensed_vehicle),
        the corridor of that vehicle (the drag each limit allows, in the drag the accelerometer
        senses) and the terminal drag (eq. 85) at the terminal state, within that corridor.
        Scales are rounded to 1e-3 and the last set is kept, so a flight whose ratios have
        settled computes its corridor once."""
        from drake_entry.models.acceleration_ratios import sensed_vehicle

        key = tuple(round(float(k), 3) for k in scales)
        if key == (1.0, 1.0):
            return {}
        if self._sensed[0] != key:
            vehicle = sensed_vehicle(self.vehicle, key)
            corridor = self._corridor(self.corridor.energy, vehicle)
            found = {"vehicle": vehicle, "corridor": corridor}
            if self.terminal_drag is not None and self.terminal_state is not None:
                h_f, V_f = self.terminal_state
                D_lo, D_hi = corridor.bounds(np.array([self.E_final]))
                D_f = drag_acceleration(float(self.planet.atmospheric_altitude(h_f, self.target[1])), V_f,
                                        self.alpha(self.E_final), vehicle, self.atmosphere)
                found["Df"] = float(min(max(D_f, D_lo[0]), D_hi[0]))
            self._sensed = (key, found)
        return dict(self._sensed[1])

    @staticmethod
    def from_scenario(scenario) -> "DragEnergyPlanner":
        g = scenario.guidance
        vehicle = scenario.make_vehicle()
        h_f, V_f, Ef = scenario.guidance_terminal_state()
        alpha = scenario.schedule("alpha")
        planet, lat_f = scenario.make_planet(), math.radians(scenario.target.latitude_deg)
        D_f = (drag_acceleration(float(planet.atmospheric_altitude(h_f, lat_f)), V_f, alpha(Ef), vehicle,
                                 scenario.make_atmosphere()) if g.terminal_drag else None)
        return DragEnergyPlanner(
            vehicle=vehicle, planet=planet, atmosphere=scenario.make_atmosphere(),
            alpha=alpha, target_lon=math.radians(scenario.target.longitude_deg),
            target_lat=lat_f, E_entry=scenario.entry_energy(), E_final=Ef,
            n_nodes=g.n_nodes, solver=g.solver, margin=g.corridor_margin, corridor_points=g.corridor_points,
            terminal_drag=D_f, terminal_state=(h_f, V_f), replan_start=g.replan_start,
            centring=g.corridor_centring, range_offset=g.range_offset_m,
            entry_lat=float(scenario.initial_state()[2]), reach_margin=g.reach_margin)

    def energy(self, x) -> float:
        return float(self.planet.specific_energy(x[0], x[3]))

    def drag_state(self, x, sensed_drag: float | None = None) -> DragDynamics:
        """D, D', a_D, b_D at state x for the scheduled alpha(E) (eqs. 40-63), the air read where
        the plant reads it (DragTerms).

        With ``sensed_drag`` (the accelerometer's drag acceleration [m/s^2]) the terms are
        evaluated at that drag (DragTerms: exact for a constant density or drag-coefficient
        factor), and the feedback acts on the true drag. (Scaling the model's D', a_D and b_D by
        sensed / model instead, as this did before, multiplied the feedback's gain by model /
        sensed: b_D does not depend on the density level.)
        """
        E = self.energy(x)
        drag = sensed_drag if sensed_drag is not None and sensed_drag > 0 else None
        return drag_dynamics(x[0], x[3], x[4], _alpha_profile(self.alpha, E), self.vehicle, self.planet,
                             self.atmosphere, lat=x[2], heading=x[5], drag=drag)

    def range_to_go(self, x) -> float:
        """The range [m] a plan from state x flies: the great-circle distance to the target plus
        ``range_offset`` (DragEnergy.range_offset_m), never below a tenth of that distance."""
        distance = float(self.planet.great_circle_distance(x[1], x[2], *self.target))
        return max(distance + self.range_offset, 0.1 * distance)

    def problem(self, x, sensed_drag: float | None = None, **overrides) -> DragEnergyProblem:
        """The planning request from state x [h, lon, lat, V, gamma, psi] (and sensed drag)."""
        d = self.drag_state(x, sensed_drag)
        kw = dict(vehicle=self.vehicle, planet=self.planet, atmosphere=self.atmosphere, alpha=self.alpha,
                  corridor=self.corridor, E0=self.energy(x), Ef=self.E_final, D0=d.D, D0_prime=d.D_prime,
                  range_to_go=self.range_to_go(x), lat0=float(x[2]), latf=self.target[1],
                  heading0=float(x[5]), headingf=bearing(x[1], x[2], *self.target), Df=self.terminal_drag,
                  n_nodes=self.n_nodes, solver=self.solver, sigma_max=self.sigma_max, centring=self.centring,
                  reach_margin=self.reach_margin)
        kw.update(overrides)
        return DragEnergyProblem(**kw)

    def plan_from_state(self, x, previous: DragEnergyReference | None = None, sensed_drag: float | None = None,
                        **overrides) -> DragEnergyReference:
        """Plan from state x; a successful ``previous`` plan seeds kappa(E), so one SOCP suffices.
        With ``replan_start`` "reference" a re-plan (``previous`` given) starts at the previous
        reference's drag and slope at the flight's energy (eq. 84 at the reference), so the
        tracking law keeps correcting its error: started at the flown drag, every re-plan adopts
        the error and a drift of the drag (a phugoid on a long glide) is planned around."""
        if previous is not None and previous.success and previous.kappa is not None:
            overrides = {"kappa_guess": previous.kappa_at, "range_iterations": 1, **overrides}
        if previous is not None and previous.success and self.replan_start == "reference":
            D, D_prime, _ = previous.profile(self.energy(x))
            overrides = {"D0": float(D[0]), "D0_prime": float(D_prime[0]), **overrides}
        return plan(self.problem(x, sensed_drag, **overrides))
