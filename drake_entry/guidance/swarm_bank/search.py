"""Searches for paper 004's sigma_0 (and optionally sigma_f): the paper's swarms (PIO, PSO) and
the scipy baselines that answer whether a swarm is needed for one or two parameters, all on
the same counted, vectorised objective; and the on-board re-solution of sigma_0 (and of sigma_f
where sigma_0 alone cannot zero the range error).

Angles are in degrees here (the paper's and the user's unit); the evaluator works in rad.

Baselines (docs/methods/swarm-bank.md measured their trajectory counts):
  grid            vectorised grid refinement on the signed range error (16 points, 4 rounds)
  brentq          one 16-point grid to bracket the signed range error, then scipy brentq
  secant          vectorised bracketing (16 points, then 2 rounds of 8 inside the bracket) and
                  one regula-falsi point: the on-board re-solution's algorithm, 4 populations
  bounded         scipy minimize_scalar(method='bounded') on J (Brent with bounds)
  differential_evolution  scipy's, vectorised over its population
J(sigma_0) is V-shaped with false minima where the reversal count changes; the signed range
error is the smooth quantity (its root is J's minimum up to the altitude and speed terms).
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np
from scipy import optimize

from drake_entry.errors import ScenarioError
from drake_entry.guidance.swarm_bank.evaluator import Evaluation, SwarmProblem, evaluate
from drake_entry.guidance.swarm_bank.optimizers import (
    PSO_CONSTRICTION,
    PSO_PAPER,
    SwarmResult,
    minimise,
    pio_search,
    pso_search,
)
from drake_entry.guidance.swarm_bank.spec import SWARMS, swarm_trajectories
from drake_entry.planning.progress import ProgressLine, wanted

__all__ = ["BASELINES", "Objective", "SearchResult", "swarm_searches", "search", "Resolution", "resolve_sigma0",
           "resolve_bank_end", "problem_from_scenario"]

BASELINES = ("grid", "brentq", "secant", "bounded", "differential_evolution")


class Objective:
    """J (eq. 32) of positions in degrees, (m, 1) = sigma_0 or (m, 2) = (sigma_0, sigma_f),
    evaluated as one population; counts trajectories and keeps every evaluation."""

    def __init__(self, problem: SwarmProblem, progress: ProgressLine | None = None, budget: int | None = None,
                 sigma0_held_deg: float | None = None):
        """``sigma0_held_deg``: the positions are sigma_f (m, 1), flown with this sigma_0 [deg]."""
        self.problem = problem
        self.sigma0_held_deg = sigma0_held_deg
        self.trajectories = 0
        self.calls = 0
        self.log: list[tuple[np.ndarray, Evaluation]] = []
        self.progress, self.budget = progress, budget
        self.best_J = math.inf
        if progress is not None:
            progress.start()

    def evaluate(self, X) -> Evaluation:
        X = np.atleast_2d(np.asarray(X, float))
        if self.sigma0_held_deg is not None:
            ev = evaluate(self.problem, np.full(len(X), math.radians(self.sigma0_held_deg)), sigma_f=np.radians(X[:, 0]))
        else:
            sigma_f = np.radians(X[:, 1]) if X.shape[1] > 1 else None
            ev = evaluate(self.problem, np.radians(X[:, 0]), sigma_f=sigma_f)
        self.trajectories += len(X)
        self.calls += 1
        self.log.append((X.copy(), ev))
        self.best_J = min(self.best_J, float(np.min(ev.J)))
        if self.progress is not None and self.progress.due():
            of = f" of {self.budget}" if self.budget else ""
            self.progress.emit([f"{self.trajectories}{of} trajectories", f"best J {self.best_J:.6g}"])
        return ev

    def __call__(self, X) -> np.ndarray:
        return self.evaluate(X).J

    def best(self) -> tuple[np.ndarray, float]:
        """The best position evaluated so far and its J."""
        X = np.concatenate([x for x, _ in self.log])
        J = np.concatenate([e.J for _, e in self.log])
        i = int(np.argmin(J))
        return X[i], float(J[i])


@dc.dataclass
class SearchResult:
    """A search's answer: x [deg] (sigma_0, or sigma_0 and sigma_f), its J, trajectories
    flown, objective calls (populations), wall time [s], the swarm's record (swarms only) and
    a message (why a bracket was not found, ...)."""

    method: str
    x: np.ndarray
    J: float
    trajectories: int
    calls: int
    wall_s: float
    swarm: SwarmResult | None = None
    message: str = ""


def swarm_searches(method: str, bounds, seeds, *, n: int = 10, k_max: int = 20, k_c: int = 14, R: float = 0.2):
    """Generators (optimizers.minimise) of one swarm ``method`` for each seed."""
    if method == "pio":
        return [pio_search(bounds, n=n, k_max=k_max, k_c=k_c, R=R, seed=s) for s in seeds]
    settings = {"pso": PSO_PAPER, "pso_stable": PSO_CONSTRICTION}.get(method)
    if settings is None:
        raise ScenarioError(f"swarm method {method!r}; allowed: {', '.join(SWARMS)}")
    return [pso_search(bounds, n=n, k_max=k_max, seed=s, **settings) for s in seeds]


def search(problem: SwarmProblem, method: str, bounds_deg=((0.0, 89.0),), *, seed: int = 0, n: int = 10,
           k_max: int = 20, k_c: int = 14, R: float = 0.2, progress="auto") -> SearchResult:
    """Minimise J over ``bounds_deg`` (one pair: sigma_0; two: sigma_0, sigma_f) with ``method``
    (SWARMS or BASELINES; the root-finding baselines take sigma_0 only). ``progress``: a line on
    stderr every 5 s once the search has run 5 s (trajectories so far of the swarm's budget, best
    J): True, False or 'auto' (stderr is a terminal)."""
    bounds = [tuple(map(float, b)) for b in bounds_deg]
    if not 1 <= len(bounds) <= 2:
        raise ScenarioError(f"bounds_deg has {len(bounds)} pairs; allowed: 1 (sigma_0) or 2 (sigma_0, sigma_f)")
    budget = swarm_trajectories(n, k_max) if method in SWARMS else None
    line = ProgressLine(f"{method} search", hint="Ctrl-C stops the search") if wanted(progress) else None
    f = Objective(problem, line, budget)
    t0 = time.perf_counter()
    swarm, message = None, ""
    if method in SWARMS:
        swarm = minimise(f, swarm_searches(method, bounds, [seed], n=n, k_max=k_max, k_c=k_c, R=R))[0]
    elif method == "differential_evolution":
        optimize.differential_evolution(lambda X: f(np.asarray(X).T), bounds, seed=seed, vectorized=True,
                                        updating="deferred", popsize=10, tol=1e-4, polish=False, maxiter=100)
    elif len(bounds) != 1:
        raise ScenarioError(f"search method {method!r} takes sigma_0 only; for two parameters use "
                            f"{', '.join(SWARMS)} or differential_evolution")
    elif method == "bounded":
        optimize.minimize_scalar(lambda s: f([[s]])[0], bounds=bounds[0], method="bounded",
                                 options={"xatol": 1e-3})
    elif method == "grid":
        message = _grid_refinement(f, *bounds[0], points=16, rounds=4)
    elif method == "brentq":
        message = _bracketed_brentq(f, *bounds[0])
    elif method == "secant":
        message = _bracketed_secant(f, *bounds[0])
    else:
        raise ScenarioError(f"search method {method!r}; allowed: {', '.join(SWARMS + BASELINES)}")
    if method in ("brentq", "secant"):  # the root they solve for: eq. 32's J also weighs the crossrange,
        x, _, J = _nearest_root(f)    # which the reversal timing moves by km between neighbouring sigma_0
        x = [x]
    else:
        x, J = f.best()
    if swarm is not None:
        x, J = swarm.x, swarm.J
    return SearchResult(method, np.asarray(x, float), float(J), f.trajectories, f.calls, time.perf_counter() - t0,
                        swarm, message)


def _samples(f: Objective, lo: float = -np.inf, hi: float = np.inf):
    """Every sigma_0 evaluated so far in [lo, hi] (one-parameter searches), sorted, with its
    signed range error, J and reached flag."""
    X = np.concatenate([x[:, 0] for x, _ in f.log])
    d = np.concatenate([e.range_error_m for _, e in f.log])
    J = np.concatenate([e.J for _, e in f.log])
    ok = np.concatenate([e.reached for _, e in f.log])
    keep = (X >= lo) & (X <= hi)
    order = np.argsort(X[keep], kind="stable")
    return X[keep][order], d[keep][order], J[keep][order], ok[keep][order]


def _nearest_root(f: Objective) -> tuple[float, float, float]:
    """(sigma_0 [deg], signed range error [m], J) of the reached member evaluated so far with the
    smallest |signed range error| (one-parameter searches)."""
    X, d, J, ok = _samples(f)
    i = int(np.argmin(np.where(ok, np.abs(d), np.inf)))
    return float(X[i]), float(d[i]), float(J[i])


def _brackets(f: Objective, lo: float = -np.inf, hi: float = np.inf) -> list[tuple[float, float, float, float]]:
    """Sign changes of the signed range error between neighbouring evaluated (reached) sigma_0
    in [lo, hi], as (a, b, d(a), d(b)), the pair with the lowest J first."""
    X, d, J, ok = _samples(f, lo, hi)
    found = [(X[i], X[i + 1], d[i], d[i + 1], min(J[i], J[i + 1])) for i in range(len(X) - 1)
             if ok[i] and ok[i + 1] and X[i] < X[i + 1] and np.sign(d[i]) != np.sign(d[i + 1])]
    return [b[:4] for b in sorted(found, key=lambda b: b[4])]


def _refine(f: Objective, X0, *, points: int, rounds: int):
    """Fly X0 (one population), then ``rounds`` - 1 rounds of ``points`` sigma_0 inside the
    best bracket of the signed range error; the final bracket (a, b, d(a), d(b)) or None."""
    f.evaluate(np.asarray(X0, float)[:, None])
    found = _brackets(f, min(X0), max(X0))
    for _ in range(rounds - 1):
        if not found:
            return None
        a, b = found[0][:2]
        f.evaluate(np.linspace(a, b, points + 2)[1:-1, None])
        found = _brackets(f, a, b) or found
    return found[0] if found else None


def _grid_refinement(f: Objective, lo: float, hi: float, *, points: int, rounds: int) -> str:
    """Grid refinement on the signed range error: each round flies ``points`` sigma_0 in the
    current bracket (one population); the best evaluated J is the answer."""
    if _refine(f, np.linspace(lo, hi, points), points=points, rounds=rounds) is None:
        return "no sign change of the signed range error: the best grid point is returned"
    return ""


def _bracketed_brentq(f: Objective, lo: float, hi: float) -> str:
    found = _refine(f, np.linspace(lo, hi, 16), points=16, rounds=1)
    if found is None:
        return "no sign change of the signed range error on the 16-point grid: the best grid point is returned"
    optimize.brentq(lambda s: f.evaluate([[s]]).range_error_m[0], found[0], found[1], xtol=1e-4)
    return ""


def _secant(bracket) -> float:
    """The regula-falsi point of a bracket (a, b, d(a), d(b)) of the signed range error."""
    a, b, da, db = bracket
    return float(a - da * (b - a) / (db - da))


def _bracketed_secant(f: Objective, lo: float, hi: float) -> str:
    found = _refine(f, np.linspace(lo, hi, 16), points=8, rounds=3)
    if found is None:
        return "no sign change of the signed range error on the 16-point grid: the best grid point is returned"
    f.evaluate([[_secant(found)]])
    return ""


# ---------------------------------------------------------------------------------------
# on-board re-solution
# ---------------------------------------------------------------------------------------
@dc.dataclass
class Resolution:
    """An on-board re-solution: sigma_0 [deg], whether a root of the signed range error was
    bracketed, the predicted range error there (of the closest member when not) [m], trajectories, and
    sigma_f [deg] when it was re-solved too (``resolve_bank_end``; nan: unchanged)."""

    sigma0_deg: float
    bracketed: bool
    range_error_m: float
    trajectories: int
    sigma_f_deg: float = math.nan


def _root(f: Objective, previous: float, bounds_deg, width_deg: float, points: int, rounds: int):
    """(the position zeroing the signed range error, bracketed, its range error [m]): grid rounds
    of ``points`` positions, first within +-``width_deg`` of ``previous`` (the whole bounds when
    that holds no sign change), then inside the bracket, then the secant of the bracket's ends,
    flown: it is the root only where its |range error| is below both ends' (a sign change across
    a jump, e.g. between a flight that turns away and one that does not, is no root); otherwise,
    or without a sign change, the member with the smallest |range error|."""
    lo_b, hi_b = bounds_deg
    lo, hi = max(lo_b, previous - width_deg), min(hi_b, previous + width_deg)
    found = _refine(f, np.linspace(lo, hi, points), points=points, rounds=rounds)
    if found is None and (lo > lo_b or hi < hi_b):
        found = _refine(f, np.linspace(lo_b, hi_b, 2 * points), points=points, rounds=rounds)
    if found is not None:
        x = _secant(found)
        e = f.evaluate([[x]])
        if e.reached[0] and abs(e.range_error_m[0]) <= min(abs(found[2]), abs(found[3])):
            return x, True, float(e.range_error_m[0])
    x, d, _ = _nearest_root(f)
    return x, False, d


def resolve_sigma0(problem: SwarmProblem, previous_deg: float, bounds_deg=(0.0, 89.0), *, width_deg: float = 6.0,
                   points: int = 8, rounds: int = 3) -> Resolution:
    """sigma_0 that zeroes the predicted signed range error from ``problem``'s start state
    (the navigation estimate, eq. 17 anchored at the entry energy): grid rounds of ``points``
    trajectories, first within +-``width_deg`` of the previous sigma_0 (the whole bounds when
    that holds no sign change), then inside the bracket, then the secant of the bracket's
    ends. Without a sign change the member with the smallest |range error| is kept."""
    f = Objective(problem)
    sigma0, bracketed, miss = _root(f, previous_deg, bounds_deg, width_deg, points, rounds)
    return Resolution(sigma0, bracketed, miss, f.trajectories)


def resolve_bank_end(problem: SwarmProblem, sigma0_deg: float, bounds_deg, *, width_deg: float = 6.0,
                     points: int = 8, rounds: int = 3) -> Resolution:
    """sigma_f [deg] in ``bounds_deg`` that zeroes the predicted signed range error with sigma_0
    held at ``sigma0_deg`` (not the paper's: where sigma_0 alone brackets no root, typically at
    its bound late in the flight, when eq. 17's weight on sigma_0 has shrunk with the energy
    left), searched as ``resolve_sigma0`` searches sigma_0, from ``problem.sigma_f``."""
    f = Objective(problem, sigma0_held_deg=sigma0_deg)
    sigma_f, bracketed, miss = _root(f, math.degrees(problem.sigma_f), bounds_deg, width_deg, points, rounds)
    return Resolution(sigma0_deg, bracketed, miss, f.trajectories, sigma_f_deg=sigma_f)


# ---------------------------------------------------------------------------------------
# the problem of a scenario
# ---------------------------------------------------------------------------------------
def problem_from_scenario(scenario) -> SwarmProblem:
    """The SwarmProblem of a scenario whose guidance is a SwarmBank spec (its entry state,
    target, vehicle limits and law settings)."""
    g = scenario.guidance
    vehicle = scenario.make_vehicle()
    rad = math.radians
    h_f, V_f, _ = scenario.guidance_terminal_state()
    return SwarmProblem(
        vehicle=vehicle, planet=scenario.make_planet(), atmosphere=scenario.make_atmosphere(),
        x0=scenario.initial_state(), target=(rad(scenario.target.longitude_deg), rad(scenario.target.latitude_deg)),
        h_f=h_f, V_f=V_f, sigma_f=rad(g.bank_end_deg), alpha_min=rad(g.alpha_min_deg), alpha_max=rad(g.alpha_max_deg),
        alpha_rate=rad(g.alpha_rate_deg_s), alpha_accel=rad(g.alpha_accel_deg_s2),
        load_max=vehicle.limits.total_load_max, heat_max=vehicle.limits.heat_flux_max, case=g.alpha_law,
        mach_shift=g.mach_shift, k2=g.qeg_gain, beta=g.qeg_beta,
        reversal_heading=tuple(np.radians(g.reversal_heading_deg)), reversal_velocity=tuple(g.reversal_velocity_m_s),
        guidance_step_s=g.period_s, max_time_s=scenario.simulation.max_time_s,
        alpha_schedule=(tuple(g.alpha_velocity_m_s), tuple(map(rad, g.alpha_deg))),
        objective_units=(1e3 * g.objective_range_unit_km, 1e3 * g.objective_altitude_unit_km,
                         g.objective_speed_unit_m_s), limit_fraction=g.limit_fraction,
        path_gain=g.path_gain, path_horizon_s=g.path_horizon_s, path_fraction=g.path_limit_fraction)
