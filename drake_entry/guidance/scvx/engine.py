"""Successive convexification (SCvx) on Drake ``MathematicalProgram`` SOCPs (paper 001 Sec. III).

A ``ConvexifiableProblem`` states a non-convex problem in scaled variables z: a smooth
objective J(z), equality defects c(z) = 0 (the discretised dynamics), smooth inequalities
g(z) <= 0 (path and event constraints) and convex constraints it adds to the SOCP itself
(cones, some with a buffer). Each iteration solves

    min  J(zb) + dJ (z - zb) + w_nu |nu|_1 + w_xi (sum xi + sum convex buffers)
    s.t. c(zb) + C (z - zb) + nu = 0            virtual controls (eq. 23)
         g(zb) + G (z - zb) - xi <= 0, xi >= 0  virtual buffers (eq. 24)
         convex constraints, lower <= z <= upper, |z - zb|_inf <= r  (hard trust region; not on
                                                 variables entering linearly, e.g. epigraphs)

which is CP4's L_a (eq. 28) with l1 penalties; the merit is the augmented objective J_a
(eq. 27): J + w_nu |c|_1 + w_xi (sum max(0, g) + convex violations). The trust radius r
adapts with rho = actual / predicted decrease of J_a (eq. 22; thresholds rho0 <= rho1 <= rho2,
factor 2), optionally after a golden-section line search on J_a along the step (eq. 29, with
the (alpha4 - alpha1) correction). Each trial point is tightened (epigraph variables at their
constraints' value, ``tighten``), corrected to second order and, once accepted and nearly
feasible, projected onto its constraints (``feasibility_projection``). Convergence is judged
on the predicted decrease AND the defects and constraint violations, never on the step alone:
a collapsing trust region also gives a small step; at a point feasible within the tolerances
the predicted decrease counts only what goes beyond removing its remaining penalty (some 600
defects each below 1e-7 weigh 1e-3 in J_a, five times the tolerance, and no step removes them
all). Two exceptions are named in the message: a feasible point where the trust region
reaches its floor with a predicted decrease within ``FLOOR_DECREASE_FACTOR`` of the tolerance
(the linear model still promises a little, no step realises it), and a stationary point a
little outside the tolerances that one projection onto its constraints puts inside them with
its objective unchanged (``restore_feasibility``; last bits of the SOCP solver decide which
side of 1e-6 such a point lands, and they differ between machines).

The SOCP is built once per problem size; each iteration only updates the coefficients of
its linear constraints, cost and bounds (``UpdateCoefficients``, ``set_bounds``).
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from pydrake.solvers import ClarabelSolver, LorentzConeConstraint, MathematicalProgram, ScsSolver, SolverOptions

from drake_entry.guidance.scvx.settings import ScvxSettings

__all__ = ["GOLDEN", "FLOOR_DECREASE_FACTOR", "PROJECTION_STEPS", "Evaluation", "Linearisation",
           "ConvexifiableProblem", "CLARABEL_DEFAULTS", "SCS_DEFAULTS", "SCS_REFINE_FACTOR", "SCS_EPS_FLOOR",
           "STEP_FORM", "IterationRecord", "ScvxOutcome", "merit", "max_defect", "max_violation",
           "within_tolerances", "diagnose", "ShiftedCone", "ScvxSubproblem", "defect_correction",
           "constraint_correction", "project_accepted", "restore_feasibility", "golden_section", "solve_scvx"]

GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0  # Phi of eq. 29
#: a feasible point where the trust region reaches its floor is converged when the predicted
#: decrease is within this factor of ``decrease_tolerance`` (said so in the message)
FLOOR_DECREASE_FACTOR = 10.0
#: Newton projections of an accepted point at most (``ScvxSettings.feasibility_projection``):
#: one left the 66 x 4 nominal 1.35e-6 over the heat-flux bound, a second met it
PROJECTION_STEPS = 3


@dc.dataclass(frozen=True)
class Evaluation:
    """The non-convex problem at one z: scaled objective, defects (= 0), inequalities (<= 0)
    and the violations of its buffered convex constraints (>= 0)."""

    objective: float
    defects: np.ndarray
    inequalities: np.ndarray
    convex_violations: np.ndarray


@dc.dataclass(frozen=True)
class Linearisation:
    """First-order model at z: the evaluation and the gradients (Jacobians sparse)."""

    evaluation: Evaluation
    objective_gradient: np.ndarray
    defect_jacobian: sp.spmatrix
    inequality_jacobian: sp.spmatrix


class ConvexifiableProblem:
    """What the SCvx engine needs from a problem (all in scaled variables z).

    Attributes set by subclasses: ``n_z``, ``lower``, ``upper`` (hard bounds), ``n_defects``,
    ``n_inequalities``."""

    n_z: int
    lower: np.ndarray
    upper: np.ndarray
    n_defects: int
    n_inequalities: int

    def evaluate(self, z) -> Evaluation:
        raise NotImplementedError

    def linearise(self, z) -> Linearisation:
        raise NotImplementedError

    def add_convex_constraints(self, prog: MathematicalProgram, z) -> np.ndarray:
        """Add the convex constraints on the decision variables z; return the buffer
        variables (one per entry of ``Evaluation.convex_violations``, >= 0, penalised)."""
        return np.empty(0, dtype=object)

    def correction_variables(self) -> np.ndarray:
        """Boolean mask of the variables the second-order correction may move (default: all;
        the engine never moves a variable its bounds fix)."""
        return np.ones(self.n_z, bool)

    def tighten(self, z) -> np.ndarray:
        """z with its epigraph variables (if any) set to the tightest value their constraints
        allow at z (default: z unchanged). The engine tightens every trial point: with l1
        penalty weights above 1 this never raises the merit, and it makes the merit of a
        min-max objective the true maximum."""
        return z

    def trust_region_variables(self) -> np.ndarray:
        """Boolean mask of the variables the trust region bounds (default: all). A variable
        that enters the objective and every constraint linearly (an epigraph variable) has an
        exact linear model and needs none: bounding it only limits its decrease to the radius
        per iteration."""
        return np.ones(self.n_z, bool)

    def describe_defect(self, i: int) -> str:
        return f"defect {i}"

    def describe_inequality(self, i: int) -> str:
        return f"inequality {i}"

    def describe_convex(self, i: int) -> str:
        return f"convex constraint {i}"


#: Clarabel options of the SCvx sub-problems unless ``solver_options`` overrides them:
#: iterative refinement off halves the solve time (59 -> 32 ms per SOCP on the nominal, same
#: IPM iterations, cost equal to 1e-7) and the plan (476.4 MJ/m^2) is unchanged
CLARABEL_DEFAULTS = {"iterative_refinement_enable": False}
#: SCS options of the SCvx sub-problems unless ``solver_options`` overrides them: a loose start
#: (the early steps need no accuracy; SCS's iterations grow fast as eps falls), tightened by
#: ``SCS_REFINE_FACTOR`` whenever an answer is too inexact to be a step, down to
#: ``SCS_EPS_FLOOR`` (docs/methods/scvx.md, "SCS")
SCS_DEFAULTS = {"eps_abs": 1e-4, "eps_rel": 1e-4, "max_iters": 100000}
SCS_REFINE_FACTOR = 10.0
SCS_EPS_FLOOR = 1e-7
#: sub-problem variables by solver: the step z - zb (True) or z. In the step its right-hand sides
#: are the defects and violations themselves (c, not C zb - c), which go to zero at convergence,
#: so SCS's tolerance, relative to the largest one, tightens with them (on z it stalled at
#: defects 0.37, on the step it reaches 2e-6). Clarabel solves z: on the step its (more exact)
#: answers cost 8 % more SCvx iterations over the paper001 benchmark (66 x 4 mesh 30 instead of 21).
STEP_FORM = {"clarabel": False, "scs": True}
@dc.dataclass
class IterationRecord:
    """One SCvx iteration: merit J_a before, predicted and actual decrease, rho, step
    length alpha, trust radius used, accepted, largest defect and violation after, times [s]."""

    merit: float
    predicted: float
    actual: float
    rho: float
    alpha: float
    trust_radius: float
    accepted: bool
    max_defect: float
    max_violation: float
    socp_time: float
    model_time: float
    solver_iterations: int


@dc.dataclass
class ScvxOutcome:
    """The engine's answer: the last accepted z, its evaluation, whether it converged, why,
    and the iteration history."""

    z: np.ndarray
    evaluation: Evaluation
    converged: bool
    message: str
    history: list
    socp_time: float
    model_time: float

    @property
    def iterations(self) -> int:
        return len(self.history)


def merit(ev: Evaluation, s: ScvxSettings) -> float:
    """J_a of eq. 27 with l1 penalties."""
    return (ev.objective + s.virtual_control_weight * np.abs(ev.defects).sum()
            + s.buffer_weight * (np.maximum(ev.inequalities, 0.0).sum() + ev.convex_violations.sum()))


def max_defect(ev: Evaluation) -> float:
    """Largest scaled dynamics defect."""
    return float(np.abs(ev.defects).max(initial=0.0))


def max_violation(ev: Evaluation) -> float:
    g = ev.inequalities.max(initial=-np.inf)
    c = ev.convex_violations.max(initial=0.0)
    return float(max(g, c, 0.0))


def within_tolerances(ev: Evaluation, s: ScvxSettings) -> bool:
    """Defects and constraint violations all within the settings' tolerances."""
    return max_defect(ev) <= s.defect_tolerance and max_violation(ev) <= s.constraint_tolerance


def diagnose(problem: ConvexifiableProblem, ev: Evaluation) -> str:
    """Which constraint is violated most, and where."""
    parts = []
    if ev.defects.size:
        i = int(np.argmax(np.abs(ev.defects)))
        parts.append(f"largest dynamics defect {abs(ev.defects[i]):.3g} ({problem.describe_defect(i)})")
    if ev.inequalities.size and ev.inequalities.max() > 0:
        i = int(np.argmax(ev.inequalities))
        parts.append(f"largest violation {ev.inequalities[i]:.3g} ({problem.describe_inequality(i)})")
    if ev.convex_violations.size and ev.convex_violations.max() > 0:
        i = int(np.argmax(ev.convex_violations))
        parts.append(f"convex violation {ev.convex_violations[i]:.3g} ({problem.describe_convex(i)})")
    return "; ".join(parts) if parts else "no constraint violated"


class ShiftedCone:
    """A Lorentz cone the problem added on z, kept true on the sub-problem's step variables
    y = z - zb (``STEP_FORM``): A z + b = A y + (A zb + b), so each iteration only shifts its b."""

    def __init__(self, prog: MathematicalProgram, binding, y):
        self.evaluator = binding.evaluator()
        if not isinstance(self.evaluator, LorentzConeConstraint):
            raise TypeError(f"ConvexifiableProblem.add_convex_constraints added a "
                            f"{type(self.evaluator).__name__}; the SCvx engine shifts Lorentz cones only")
        self.A = np.asfortranarray(self.evaluator.A().toarray())
        self.b = np.array(self.evaluator.b())
        position = {prog.FindDecisionVariableIndex(v): i for i, v in enumerate(y)}
        index = [position.get(j, -1) for j in prog.FindDecisionVariableIndices(binding.variables())]
        self.columns = np.array([c for c, i in enumerate(index) if i >= 0], int)
        self.step_index = np.array([i for i in index if i >= 0], int)

    def shift(self, zb: np.ndarray):
        """Re-centre the cone at zb."""
        self.evaluator.UpdateCoefficients(self.A, self.b + self.A[:, self.columns] @ zb[self.step_index])


class ScvxSubproblem:
    """The convex sub-problem, built once; ``solve`` updates its coefficients and solves it.
    Its variables are y = z - origin: z itself (origin 0) for an interior-point solver, the step
    z - zb (origin zb) for a first-order one (``STEP_FORM``)."""

    def __init__(self, problem: ConvexifiableProblem, settings: ScvxSettings):
        self.problem, self.settings = problem, settings
        nz, nc, ng = problem.n_z, problem.n_defects, problem.n_inequalities
        prog = self.prog = MathematicalProgram()
        self.step_form = STEP_FORM[settings.solver]
        self.y = prog.NewContinuousVariables(nz, "y")  # z - origin
        self.nu = prog.NewContinuousVariables(2 * nc, "nu")  # nu+ then nu-
        self.xi = prog.NewContinuousVariables(ng, "xi")
        self.buffers = problem.add_convex_constraints(prog, self.y)
        # the problem's cones, stated on z, re-centred each iteration when y is the step
        self._cones = [ShiftedCone(prog, b, self.y) for b in prog.GetAllConstraints()] if self.step_form else []
        slack = np.concatenate([self.nu, self.xi, self.buffers])
        prog.AddBoundingBoxConstraint(0.0, np.inf, slack)
        self.box = prog.AddBoundingBoxConstraint(problem.lower, problem.upper, self.y).evaluator()
        eye_c = sp.identity(nc, format="csc")
        self._eye_nu = sp.hstack([eye_c, -eye_c], format="csc")
        self.dynamics = prog.AddLinearEqualityConstraint(
            sp.csc_matrix((nc, nz + 2 * nc)), np.zeros(nc), np.concatenate([self.y, self.nu])).evaluator()
        self._neg_eye_g = -sp.identity(ng, format="csc")
        self.path = prog.AddLinearConstraint(
            sp.csc_matrix((ng, nz + ng)), np.full(ng, -np.inf), np.zeros(ng),
            np.concatenate([self.y, self.xi])).evaluator() if ng else None
        self._penalty = np.concatenate([np.full(2 * nc, settings.virtual_control_weight),
                                        np.full(ng + len(self.buffers), settings.buffer_weight)])
        self.cost = prog.AddLinearCost(np.zeros(nz + slack.size), 0.0, np.concatenate([self.y, slack])).evaluator()
        self._bounded = problem.trust_region_variables()
        if settings.solver == "clarabel":
            self.solver = ClarabelSolver()
        else:
            self.solver = ScsSolver()
        defaults = CLARABEL_DEFAULTS if settings.solver == "clarabel" else SCS_DEFAULTS
        self.option_values = {**defaults, **settings.solver_options}
        self._set_options()

    def _set_options(self):
        self.options = SolverOptions()
        for k, v in self.option_values.items():
            self.options.SetOption(self.solver.solver_id(), k, v)

    def refine(self) -> bool:
        """Ask an inexact (first-order) solver for a more accurate answer: SCS's eps_abs and
        eps_rel divided by ``SCS_REFINE_FACTOR`` down to ``SCS_EPS_FLOOR``. False when there is
        nothing left to tighten (Clarabel, or SCS at the floor)."""
        if self.settings.solver != "scs":
            return False
        eps = {k: self.option_values[k] for k in ("eps_abs", "eps_rel")}
        if max(eps.values()) <= SCS_EPS_FLOOR:
            return False
        for k, v in eps.items():
            self.option_values[k] = max(v / SCS_REFINE_FACTOR, SCS_EPS_FLOOR)
        self._set_options()
        return True

    def solve(self, zb: np.ndarray, lin: Linearisation, radius: float):
        """Solve the sub-problem around zb; returns (z*, predicted L_a, solver iterations) or
        (None, message, 0) when the solver fails."""
        p, ev = self.problem, lin.evaluation
        origin = zb if self.step_form else np.zeros_like(zb)
        d = zb - origin  # the current point in y
        C = lin.defect_jacobian  # c + C (y - d) + nu = 0 (eq. 23)
        self.dynamics.UpdateCoefficients(sp.hstack([C, self._eye_nu], format="csc"), C @ d - ev.defects)
        if self.path is not None:  # g + G (y - d) - xi <= 0 (eq. 24)
            G = lin.inequality_jacobian
            self.path.UpdateCoefficients(sp.hstack([G, self._neg_eye_g], format="csc"),
                                         np.full(p.n_inequalities, -np.inf), G @ d - ev.inequalities)
        for cone in self._cones:
            cone.shift(zb)
        lo = np.where(self._bounded, np.maximum(p.lower, zb - radius), p.lower) - origin
        hi = np.where(self._bounded, np.minimum(p.upper, zb + radius), p.upper) - origin
        self.box.set_bounds(lo, np.maximum(hi, lo))
        self.cost.UpdateCoefficients(np.concatenate([lin.objective_gradient, self._penalty]), 0.0)
        result = self.solver.Solve(self.prog, None, self.options)
        details = result.get_solver_details()
        its = int(getattr(details, "iterations", getattr(details, "iter", 0)) or 0)
        if not result.is_success():
            return None, f"{self.solver.solver_id().name()} returned {result.get_solution_result().name}", its
        # clipped: a first-order solver meets the bounds only to its tolerance
        z = np.clip(origin + result.GetSolution(self.y), p.lower, p.upper)
        return z, self.model_merit(zb, lin, z, result.GetSolution(self.buffers)), its

    def model_merit(self, zb, lin: Linearisation, z, buffers) -> float:
        """L_a (eq. 28) of the linear model at z: the penalties evaluated from z itself, not
        read from the solver's slack variables (a first-order solver such as SCS meets the
        slacks' equalities only to its tolerance; predicted decreases from them were off by
        more than the merit itself)."""
        ev, dz = lin.evaluation, z - zb
        model = Evaluation(ev.objective + lin.objective_gradient @ dz, ev.defects + lin.defect_jacobian @ dz,
                           ev.inequalities + lin.inequality_jacobian @ dz, np.maximum(buffers, 0.0))
        return merit(model, self.settings)


def defect_correction(jacobian: sp.spmatrix, residuals: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The least-norm change dz of the free variables (boolean mask ``free``) with
    C dz = -residuals: a second-order correction of an SQP step (Nocedal & Wright, Sec. 15.4),
    C the rows of the current linearisation to re-satisfy (the defects', and those of the
    inequalities violated at the trial point), ``residuals`` their values at the trial point."""
    Cf = sp.csc_matrix(jacobian)[:, free]
    n = Cf.shape[1]
    # the KKT system [I C^T; C -delta I] keeps C's sparsity (C C^T is dense through the t_f
    # column); the tiny -delta I makes it quasi-definite, so dependent rows do not make it singular
    kkt = sp.bmat([[sp.identity(n), Cf.T], [Cf, -1e-12 * sp.identity(Cf.shape[0])]], format="csc")
    solution = spla.splu(kkt).solve(np.concatenate([np.zeros(n), -np.asarray(residuals, float)]))
    dz = np.zeros(len(free))
    dz[free] = solution[:n]
    return dz


def constraint_correction(lin: Linearisation, ev: Evaluation, free) -> np.ndarray:
    """``defect_correction`` with the rows of ``lin`` for the defects and for the inequalities
    ``ev`` violates, cancelling ``ev``'s residuals: the second-order correction of a trial point
    (``lin`` at the step's start) or a Newton projection (``lin`` at ``ev``'s own point)."""
    violated = ev.inequalities > 0.0
    rows = sp.vstack([lin.defect_jacobian, lin.inequality_jacobian[violated]], format="csc")
    return defect_correction(rows, np.concatenate([ev.defects, ev.inequalities[violated]]), free)


def project_accepted(problem: ConvexifiableProblem, z, lin: Linearisation, ja: float, free, s: ScvxSettings):
    """Newton projections of an accepted, nearly feasible point onto its defects and violated
    inequalities (the ``defect_correction`` of each point's own linearisation), at most
    ``PROJECTION_STEPS`` while the point stays infeasible and each lowers the merit. Returns
    (z, linearisation, merit) of the point kept."""
    for _ in range(PROJECTION_STEPS):
        ev = lin.evaluation
        if within_tolerances(ev, s):
            break
        if max_defect(ev) > s.projection_defect_limit:
            break
        zp = np.clip(z + constraint_correction(lin, ev, free), problem.lower, problem.upper)
        if merit(problem.evaluate(zp), s) >= ja:
            break
        z, lin = zp, problem.linearise(zp)
        ja = merit(lin.evaluation, s)
    return z, lin, ja


def restore_feasibility(problem: ConvexifiableProblem, z, lin: Linearisation, free, s: ScvxSettings):
    """At a stationary point a little outside the tolerances: one Newton projection onto its
    defects and violated inequalities (``constraint_correction``). Returns (z, linearisation) of
    the projected point when it lies within the tolerances and its objective moved by at most
    the decrease tolerance (the optimum is unchanged), else None. The merit is not the test
    here: a projection spreads tiny defects over all nodes, whose l1 sum can outweigh the
    violation removed (measured: violation 1.17e-6 -> 4.1e-7, largest defect 6.7e-9 -> 8e-8,
    J_a +1e-3, objective +3e-7)."""
    ev = lin.evaluation
    if not (s.feasibility_projection and problem.n_defects) or max_defect(ev) > s.projection_defect_limit:
        return None
    zp = problem.tighten(np.clip(z + constraint_correction(lin, ev, free), problem.lower, problem.upper))
    linp = problem.linearise(zp)
    evp = linp.evaluation
    if within_tolerances(evp, s) and abs(evp.objective - ev.objective) <= s.decrease_tolerance * (1.0 + abs(ev.objective)):
        return zp, linp
    return None


def golden_section(merit_at, full_step_merit: float, steps: int) -> tuple[float, float]:
    """Step length alpha in [0, 1] minimising the merit along the step (eq. 29, alpha1 = 0,
    alpha4 = 1), ``steps`` interval reductions; returns (alpha, merit). The full step is kept
    unless an interior point is better."""
    a1, a4 = 0.0, 1.0
    a2, a3 = a1 + (1.0 - GOLDEN) * (a4 - a1), a1 + GOLDEN * (a4 - a1)
    m2, m3 = merit_at(a2), merit_at(a3)
    best = min((full_step_merit, 1.0), (m2, a2), (m3, a3))
    for _ in range(steps - 1):
        if m2 <= m3:  # optimum in [a1, a3]
            a4, a3, m3 = a3, a2, m2
            a2 = a1 + (1.0 - GOLDEN) * (a4 - a1)
            m2 = merit_at(a2)
            best = min(best, (m2, a2))
        else:  # optimum in [a2, a4]
            a1, a2, m2 = a2, a3, m3
            a3 = a1 + GOLDEN * (a4 - a1)
            m3 = merit_at(a3)
            best = min(best, (m3, a3))
    return best[1], best[0]


def solve_scvx(problem: ConvexifiableProblem, z0, settings: ScvxSettings | None = None,
               progress=None) -> ScvxOutcome:
    """Run SCvx from z0 (projected onto the hard bounds). ``progress(k, record)`` is called
    after every iteration when given."""
    s = settings or ScvxSettings()
    t0 = time.perf_counter()
    sub = ScvxSubproblem(problem, s)
    z = np.clip(np.asarray(z0, float), problem.lower, problem.upper)
    free = problem.correction_variables() & (problem.upper > problem.lower)
    lin = problem.linearise(z)
    model_time = time.perf_counter() - t0
    socp_time = 0.0
    ja = merit(lin.evaluation, s)
    radius = s.trust_radius
    history: list[IterationRecord] = []
    converged, message = False, ""
    for k in range(s.max_iterations):
        t1 = time.perf_counter()
        z_new, predicted, solver_its = sub.solve(z, lin, radius)
        socp_time += time.perf_counter() - t1
        ev = lin.evaluation
        if z_new is not None and ja - predicted < -s.decrease_tolerance * (1.0 + abs(ja)):
            # dz = 0 is feasible in the sub-problem with the model at J_a: an exact solution never
            # raises the model merit. An inexact one (a first-order solver's) is not a step.
            z_new, predicted = None, f"an inexact solution raising the model merit by {predicted - ja:.3g}"
            refined = sub.refine()  # if so, the same sub-problem is solved again, more accurately
        else:
            refined = False
        if z_new is None:  # a failed solve counts as a rejected iteration
            history.append(IterationRecord(ja, math.nan, 0.0, math.nan, 0.0, radius, False, max_defect(ev),
                                           max_violation(ev), time.perf_counter() - t1, 0.0, solver_its))
            if refined:
                continue
            if radius > s.trust_radius_min:
                radius /= s.trust_factor
                continue
            message = f"the convex sub-problem failed ({predicted}) at trust radius {radius:.3g}"
            break
        t2 = time.perf_counter()
        decrease = ja - predicted
        objective_decrease = decrease - (ja - ev.objective) if within_tolerances(ev, s) else decrease
        if objective_decrease <= s.decrease_tolerance * (1.0 + abs(ja)):
            rec = IterationRecord(ja, decrease, 0.0, math.nan, 0.0, radius, False, max_defect(ev), max_violation(ev),
                                  t2 - t1, 0.0, solver_its)
            history.append(rec)
            if progress is not None:
                progress(k, rec)
            if within_tolerances(ev, s):
                converged, message = True, f"converged in {k + 1} iterations"
            elif (restored := restore_feasibility(problem, z, lin, free, s)) is not None:
                z, lin = restored
                converged = True
                message = (f"converged in {k + 1} iterations (stationary with largest defect "
                           f"{max_defect(ev):.2g} and violation {max_violation(ev):.2g}; one projection onto "
                           f"the constraints brought them to {max_defect(lin.evaluation):.2g} and "
                           f"{max_violation(lin.evaluation):.2g}, the objective unchanged within the decrease "
                           f"tolerance)")
            else:
                message = ("stationary at an infeasible point (no decrease of the penalised merit is "
                           "predicted): " + diagnose(problem, ev))
            break
        z_new = problem.tighten(z_new)
        ev_new = problem.evaluate(z_new)
        ja_full = merit(ev_new, s)
        if s.second_order_correction and problem.n_defects:
            z_soc = problem.tighten(np.clip(z_new + constraint_correction(lin, ev_new, free), problem.lower,
                                            problem.upper))
            ja_soc = merit(problem.evaluate(z_soc), s)
            if ja_soc < ja_full:
                z_new, ja_full = z_soc, ja_soc
        step = z_new - z

        def merit_at(a):
            return merit(problem.evaluate(problem.tighten(z + a * step)), s)

        alpha, ja_new = 1.0, ja_full
        if s.line_search_steps:
            alpha, ja_new = golden_section(merit_at, ja_full, s.line_search_steps)
        actual = ja - ja_new
        rho = actual / decrease  # eq. 22: J_a after the line search against L_a of the full step
        accepted = rho >= s.rho0 and actual > 0.0
        used_radius = radius
        if accepted:
            z = z_new if alpha == 1.0 else problem.tighten(z + alpha * step)
            lin = problem.linearise(z)
            ja = merit(lin.evaluation, s)
            if s.feasibility_projection and problem.n_defects:
                z, lin, ja = project_accepted(problem, z, lin, ja, free, s)
        if not accepted or rho < s.rho1:
            radius /= s.trust_factor
        elif rho >= s.rho2 and (not history or history[-1].accepted):
            radius = min(radius * s.trust_factor, s.trust_radius_max)
        model_time += time.perf_counter() - t2
        ev = lin.evaluation
        rec = IterationRecord(ja, decrease, actual, rho, alpha, used_radius, accepted, max_defect(ev),
                              max_violation(ev), t2 - t1, time.perf_counter() - t2, solver_its)
        history.append(rec)
        if progress is not None:
            progress(k, rec)
        if radius < s.trust_radius_min:
            floor = FLOOR_DECREASE_FACTOR * s.decrease_tolerance * (1.0 + abs(ja))
            if within_tolerances(ev, s) and decrease <= floor:
                converged = True
                message = (f"converged at the trust-region floor in {k + 1} iterations (feasible; predicted "
                           f"decrease {decrease:.2g} <= {floor:.2g}, {FLOOR_DECREASE_FACTOR:g} x the tolerance)")
            else:
                message = (f"trust region collapsed (radius {radius:.2g}) after {k + 1} iterations: "
                           + diagnose(problem, ev))
            break
    else:
        message = f"no convergence in {s.max_iterations} iterations: " + diagnose(problem, lin.evaluation)
    return ScvxOutcome(z, lin.evaluation, converged, message, history, socp_time, model_time)
