"""Model values and Jacobians at all nodes from one vectorised call (central differences),
and the timer of the Python callbacks a solver calls."""
from __future__ import annotations

import functools
import time

import numpy as np
from pydrake.autodiffutils import ExtractValue

from drake_entry.planning.progress import ProgressLine

__all__ = ["SolveProgress", "CallbackTimer", "CACHED_EVALUATIONS", "model_values"]


class SolveProgress(ProgressLine):
    """Console progress of a long solve (planning.progress): the solver's evaluations of the
    problem functions, the objective at the latest evaluation (solver units) and, where
    constraints hold the collocation rows (LGL, Hermite-Simpson), their largest scaled violation."""

    def __init__(self, label: str, *, stream=None, after: float | None = None, interval: float | None = None):
        super().__init__(label, hint="Ctrl-C stops the solve", stream=stream, after=after, interval=interval)

    def report(self, calls: int, objective: float | None, violation: float | None):
        parts = [f"{calls} evaluations"]
        if objective is not None:
            parts.append(f"objective {objective:.8g}")
        if violation is not None:
            parts.append(f"largest collocation violation {violation:.2e} (scaled)")
        self.emit(parts)


class CallbackTimer:
    """Calls and wall time [s] of the Python callbacks handed to the solver (model values,
    Jacobians, AutoDiff packing): the rest of a solve's time is the solver's own and Drake's.
    With ``progress`` (a SolveProgress) it also prints the solve's progress when due: the
    evaluations are the calls of the callback wrapped with ``evaluation=True`` (one per point
    the solver evaluates the problem at), else all calls."""

    def __init__(self):
        self.calls, self.seconds, self.evaluations = 0, 0.0, 0
        self.progress: SolveProgress | None = None
        self._costs, self._violations = {}, {}

    def wrap(self, fn, *, cost: bool = False, bounds: tuple | None = None, evaluation: bool = False):
        """``fn`` counted and timed; ``cost``: its value is a term of the objective; ``bounds``
        (lower, upper): a constraint holding collocation rows, whose violation progress reports
        (the largest over such constraints at their latest evaluations); ``evaluation``: its
        calls count the solver's evaluations."""
        @functools.wraps(fn)
        def timed(*args):
            t0 = time.perf_counter()
            out = None
            try:
                out = fn(*args)
                return out
            finally:
                self.seconds += time.perf_counter() - t0
                self.calls += 1
                self.evaluations += evaluation
                if out is not None and self.progress is not None:
                    self._observe(timed, out, cost, bounds)
        return timed

    def _observe(self, key, out, cost: bool, bounds):
        if cost:
            self._costs[key] = float(out.value() if hasattr(out, "value") else out)
        if bounds is not None:  # every evaluation (C++ value extraction), so none is stale
            out = np.ravel(out)
            v = ExtractValue(out).ravel() if out.dtype == object else np.asarray(out, float)
            self._violations[key] = float(np.max(np.maximum(bounds[0] - v, 0.0) + np.maximum(v - bounds[1], 0.0),
                                                 initial=0.0))
        if not self.progress.due():
            return
        self.progress.report(self.evaluations or self.calls, sum(self._costs.values()) if self._costs else None,
                             max(self._violations.values()) if self._violations else None)


#: evaluations a _NodeEvaluator keeps by default: the constraint and the running cost of each
#: part of a program evaluate the same points in turn (node_program raises it above its parts)
CACHED_EVALUATIONS = 16


class _NodeEvaluator:
    """Dynamics, path functions and Lagrangian at all nodes with their Jacobians.

    Every node's values depend only on that node's state and control, so one vectorised
    model call on the nodes and their 2 (n_x + n_u) central perturbations gives all
    Jacobian blocks (step (eps^(1/3)) in scaled units, truncation error ~1e-10). Models only
    need to accept float arrays; a model that does not is evaluated node by node. With
    ``dynamics_only`` the path functions and the Lagrangian are not evaluated (returned as
    zero rows and zeros: Hermite-Simpson's midpoints need f only)."""

    def __init__(self, tx, step: float = 6e-6, dynamics_only: bool = False):
        self.tx, self.step, self.dynamics_only = tx, step, dynamics_only
        self._cache = {}  # the latest evaluations by their points (one per part of a program)
        self.capacity = CACHED_EVALUATIONS
        self.vectorised = True
        self.path_scale = np.array([c.scale for c in tx.problem.path], float).reshape(-1, 1)

    def _models(self, Xs, Us):
        """f_scaled (nx, M), path_scaled (np, M), L (M,) at M scaled points (columns)."""
        tx = self.tx
        f, g, L, self.vectorised = model_values(tx.problem, Xs * tx.sx[:, None], Us * tx.su[:, None], self.vectorised,
                                                dynamics_only=self.dynamics_only)
        return f * (tx.ts / tx.sx)[:, None], (g / self.path_scale if g.shape[0] else g), L

    def evaluate(self, Xs, Us):
        """Values and node Jacobians: f (N, nx), g (N, np), L (N,), and df (N, nx, nx+nu),
        dg (N, np, nx+nu), dL (N, nx+nu) with respect to the scaled node variables."""
        key = np.concatenate([Xs.ravel(), Us.ravel()]).tobytes()
        if key in self._cache:
            return self._cache[key]
        N, nx = Xs.shape
        nu = Us.shape[1]
        nv = nx + nu
        V = np.hstack([Xs, Us])  # (N, nv)
        h = self.step * np.maximum(1.0, np.abs(V))  # (N, nv)
        pts = [V]
        for j in range(nv):
            for sgn in (1.0, -1.0):
                W = V.copy()
                W[:, j] += sgn * h[:, j]
                pts.append(W)
        P = np.vstack(pts).T  # (nv, N (1 + 2 nv))
        f, g, L = self._models(P[:nx], P[nx:])
        M = N
        f0, g0, L0 = f[:, :M].T, g[:, :M].T, L[:M]
        df = np.empty((N, nx, nv))
        dg = np.empty((N, g.shape[0], nv))
        dL = np.empty((N, nv))
        for j in range(nv):
            a, b = slice((1 + 2 * j) * M, (2 + 2 * j) * M), slice((2 + 2 * j) * M, (3 + 2 * j) * M)
            den = 2.0 * h[:, j]
            df[:, :, j] = ((f[:, a] - f[:, b]) / den).T
            dg[:, :, j] = ((g[:, a] - g[:, b]) / den).T
            dL[:, j] = (L[a] - L[b]) / den
        if len(self._cache) >= self.capacity:
            self._cache.pop(next(iter(self._cache)))  # the oldest
        out = self._cache[key] = (f0, g0, L0, df, dg, dL)
        return out


def model_values(problem, x, u, vectorised: bool = True, dynamics_only: bool = False):
    """Dynamics f (nx, M), path values (np, M) and Lagrangian (M,), SI, at the M columns of
    x (nx, M), u (nu, M): one vectorised model call, or column by column when the models
    take scalars only. Returns (f, g, L, vectorised); with ``dynamics_only``, g has no rows
    and L is zero (neither evaluated)."""
    if vectorised:
        try:
            return (*_call(problem, x, u, dynamics_only), True)
        except Exception:  # noqa: BLE001 - a model without array support
            pass
    cols = [_call(problem, x[:, m], u[:, m], dynamics_only) for m in range(x.shape[1])]
    return (np.column_stack([c[0] for c in cols]), np.column_stack([c[1] for c in cols]).reshape(-1, x.shape[1]),
            np.array([c[2] for c in cols], float), False)


def _call(problem, x, u, dynamics_only: bool = False):
    xs, us = list(x), list(u)
    m = np.shape(x)[1:] or ()
    f = np.array([np.broadcast_to(np.asarray(v, float), m) for v in problem.dynamics(xs, us)])
    if dynamics_only:
        return f, np.zeros((0,) + tuple(m)), np.zeros(m)
    if problem.path:
        g = np.array([np.broadcast_to(np.asarray(v, float), m) for v in problem.path_values(xs, us)])
    else:
        g = np.zeros((0,) + tuple(m))
    L = np.broadcast_to(np.asarray(problem.lagrangian(xs, us), float), m) if problem.has_lagrange else np.zeros(m)
    return f, g, L


def _chain(J, G):
    """J @ G for the input gradient G that Drake passes: the identity in practice (skip the
    dense product, which dominates at 125 nodes), any matrix in general."""
    if G.shape[0] == G.shape[1] and np.count_nonzero(G) == G.shape[0] and np.all(np.diag(G) == 1.0):
        return J
    return J @ G
