"""Pigeon-inspired optimisation (paper 004 eqs. 39-45) and particle-swarm optimisation, hand
written and seeded, minimising a vectorised objective f(X) -> J over box bounds.

PIO: the map-and-compass operator (eqs. 41-42) for iterations 1..k_c, then the landmark
operator (eqs. 43-45): the population is halved each iteration (eq. 44 with ceil, at least
one), keeping the fittest pigeons, which move toward their fitness-weighted centre. Eq. 43 is
used corrected (docs/methods/swarm-bank.md): weights 1/(J + eps) (J is minimised) and no
N_p in the denominator (printed, the centre lands at X/N_p). Start velocities (not given in
the paper) are zero.

PSO: velocity v = w v + c1 r1 (p_best - x) + c2 r2 (g_best - x), w linearly decreasing
(the paper: c1 1.4, c2 2.6, w 1 -> 0.4). c1 + c2 = 4 lies outside PSO's second-order
stability region (24 (1 - w^2) / (7 - 5 w) = 4.03 at w = 0.4 and less above), which
handicaps PSO in the paper's comparison; ``PSO_CONSTRICTION`` (w 0.729, c1 = c2 = 1.494) are
stable settings.

"Iterations to converge" (paper 004 Table 1, undefined there): the first iteration whose best
objective is within ``tolerance`` (1e-3) of the run's final best.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["PSO_PAPER", "PSO_CONSTRICTION", "SwarmResult", "pio_search", "pso_search", "minimise", "pio", "pso"]

PSO_PAPER = dict(c1=1.4, c2=2.6, w_start=1.0, w_end=0.4)
PSO_CONSTRICTION = dict(c1=1.494, c2=1.494, w_start=0.729, w_end=0.729)


@dc.dataclass
class SwarmResult:
    """Best position x (D,), its objective J, the best objective after each iteration
    (history[0] = the initial population), objective evaluations, and the iterations to
    converge (see module doc)."""

    x: np.ndarray
    J: float
    history: np.ndarray
    evaluations: int
    iterations_to_converge: int


def _bounds(bounds) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = (np.asarray(b, float) for b in zip(*bounds))
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)):
        raise ScenarioError(f"swarm bounds {bounds} need finite lower < upper in every dimension")
    return lo, hi


def _start(bounds, n: int, seed: int):
    """The seeded initial swarm: (lo, hi, rng, X uniform in the bounds, V = 0)."""
    lo, hi = _bounds(bounds)
    rng = np.random.default_rng(seed)
    X = lo + rng.random((n, lo.size)) * (hi - lo)
    return lo, hi, rng, X, np.zeros_like(X)


def _result(best_x, best_J, history, evaluations, tolerance) -> SwarmResult:
    history = np.asarray(history, float)
    converged = int(np.flatnonzero(history <= history[-1] + tolerance)[0])
    return SwarmResult(np.asarray(best_x, float), float(best_J), history, int(evaluations), converged)


def pio_search(bounds, *, n: int = 10, k_max: int = 20, k_c: int = 14, R: float = 0.2, seed: int = 0,
               tolerance: float = 1e-3):
    """PIO over ``bounds`` [(lo, hi), ...] (paper 004: N 10, k_max 20, k_c 14, R 0.2) as a
    generator: it yields each population's positions (m, D) and is sent their objectives (m,);
    its return value is the SwarmResult. ``pio`` and ``minimise`` drive it."""
    if not (1 <= k_c <= k_max and n >= 2):
        raise ScenarioError(f"PIO needs n >= 2 and 1 <= k_c <= k_max, got n={n}, k_c={k_c}, k_max={k_max}")
    lo, hi, rng, X, V = _start(bounds, n, seed)
    J = np.asarray((yield X), float)
    evaluations = n
    g = int(np.argmin(J))
    best_x, best_J = X[g].copy(), J[g]
    history = [best_J]
    for k in range(1, k_max + 1):
        if k <= k_c:  # map and compass, eqs. 41-42
            V = V * math.exp(-R * k) + rng.random((len(X), 1)) * (best_x - X)
            X = np.clip(X + V, lo, hi)
        else:  # landmark, eqs. 43-45 (eq. 43 corrected, eq. 44 with ceil and >= 1)
            keep = np.argsort(J)[:max(1, math.ceil(len(X) / 2))]
            X, J = X[keep], J[keep]
            w = 1.0 / (J + 1e-12)
            centre = (w[:, None] * X).sum(axis=0) / w.sum()
            X = np.clip(X + rng.random((len(X), 1)) * (centre - X), lo, hi)
        J = np.asarray((yield X), float)
        evaluations += len(X)
        g = int(np.argmin(J))
        if J[g] < best_J:
            best_x, best_J = X[g].copy(), J[g]
        history.append(best_J)
    return _result(best_x, best_J, history, evaluations, tolerance)


def pso_search(bounds, *, n: int = 10, k_max: int = 20, c1: float = 1.4, c2: float = 2.6, w_start: float = 1.0,
               w_end: float = 0.4, seed: int = 0, tolerance: float = 1e-3):
    """PSO over ``bounds`` with inertia linearly from w_start to w_end (defaults: paper 004's
    settings; ``PSO_CONSTRICTION`` for stable ones), a generator like ``pio_search``."""
    if not (n >= 2 and k_max >= 1):
        raise ScenarioError(f"PSO needs n >= 2 and k_max >= 1, got n={n}, k_max={k_max}")
    lo, hi, rng, X, V = _start(bounds, n, seed)
    J = np.asarray((yield X), float)
    evaluations = n
    p_x, p_J = X.copy(), J.copy()
    g = int(np.argmin(J))
    best_x, best_J = X[g].copy(), J[g]
    history = [best_J]
    for k in range(1, k_max + 1):
        w = w_start + (w_end - w_start) * (k - 1) / max(k_max - 1, 1)
        V = w * V + c1 * rng.random(X.shape) * (p_x - X) + c2 * rng.random(X.shape) * (best_x - X)
        X = np.clip(X + V, lo, hi)
        J = np.asarray((yield X), float)
        evaluations += n
        better = J < p_J
        p_x[better], p_J[better] = X[better], J[better]
        g = int(np.argmin(p_J))
        if p_J[g] < best_J:
            best_x, best_J = p_x[g].copy(), p_J[g]
        history.append(best_J)
    return _result(best_x, best_J, history, evaluations, tolerance)


def minimise(f, searches) -> list[SwarmResult]:
    """Run searches (``pio_search``/``pso_search`` generators) in lockstep: each round
    evaluates the positions of every unfinished search in one call f(X) -> J, so a
    vectorised objective flies all their populations together (20 seeds of Table 1 cost
    about what one run costs). Results in the order of ``searches``."""
    searches = list(searches)
    results: list = [None] * len(searches)
    pending = {i: next(s) for i, s in enumerate(searches)}
    while pending:
        order = list(pending)
        X = np.concatenate([pending[i] for i in order])
        J = np.asarray(f(X), float)
        if J.shape != (len(X),):
            raise ScenarioError(f"swarm objective returned shape {J.shape}, expected ({len(X)},)")
        start = 0
        for i in order:
            m = len(pending[i])
            try:
                pending[i] = searches[i].send(J[start:start + m])
            except StopIteration as done:
                results[i] = done.value
                del pending[i]
            start += m
    return results


def pio(f, bounds, **settings) -> SwarmResult:
    """Minimise f over ``bounds`` with PIO (settings of ``pio_search``); f maps an (m, D)
    array of positions to m objectives."""
    return minimise(f, [pio_search(bounds, **settings)])[0]


def pso(f, bounds, **settings) -> SwarmResult:
    """Minimise f over ``bounds`` with PSO (settings of ``pso_search``)."""
    return minimise(f, [pso_search(bounds, **settings)])[0]
