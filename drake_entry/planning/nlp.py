"""NLP path: entry optimal control by Legendre pseudospectral (LGL) collocation or Drake's
DirectCollocation, solved with Ipopt or SNOPT (paper 002).

    result = solve(problem, transcription="lgl" | "dircol", solver="ipopt" | "snopt", nodes=N)

``problem`` is an ``OptimalControlProblem`` (entry dynamics, planning/ocp.py) or a
``CustomProblem``. The NLP runs in scaled units (problem.scales(): canonical units as in
paper 002, altitude in 10 km, controls by their bounds); results are SI.

LGL (paper 002 eqs. 12-14, Fahroo & Ross): states and controls at the N LGL nodes
tau_k of [-1, 1], t = (tau + 1) t_f / 2. The defects are split so every nonlinear
binding stays small (one per node): F_k = (t_f / 2) f(x_k, u_k) (nonlinear, per node) and
D X = F (linear, per state). Costates come from the KKT multipliers of D X = F (eq. 15):
lambda(t_k) = nu_k / w_k, converted back to SI.

DirectCollocation: Drake's Hermite-Simpson transcription of systems.ocp_plant (the same
scaled dynamics as a Drake System) with N samples; the running cost is the trapezoid rule
over the samples; costates are estimated at the segment midpoints from the collocation
multipliers, lambda(t_k+1/2) = 3 nu_k / (2 h_k).

The result reports the Hamiltonian H = L + lambda' f along the solution (zero on an
extremal with free final time, paper 002 Fig. 10) and ``propagate`` (diagrams.propagation)
flies the controls with the Drake Simulator to check the terminal state.
"""
from __future__ import annotations

import dataclasses as dc
import math
import time as _time

import numpy as np
from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.solvers import IpoptSolver, MathematicalProgram, SnoptSolver, SolverOptions

from ..pseudospectral import LGL, interpolation_matrix
from .ocp import OptimalControlProblem

TRANSCRIPTIONS = ("lgl", "dircol")
COSTATE_SIGN = 1.0  # Drake's multiplier sign convention, checked on analytic problems (tests)
DIRCOL_COSTATE_FACTOR = 1.5
SOLVERS = ("ipopt", "snopt")


@dc.dataclass
class NlpResult:
    """Solution of an optimal-control problem.

    Attributes:
      success, message: solver verdict in words.
      time: node times [s] (nodes,). states: (nodes, n_states) SI in the problem's state
        order ([h, lon, lat, V, gamma, psi] first). controls: (nodes, n_controls) SI.
      objective: J in the problem's cost units (Lagrange terms integrated in seconds).
      costates: (nodes, n_states) d J / d x, SI (LGL: at the nodes; dircol: at segment
        midpoints, see costate_time), or None if the solver returned no multipliers.
      costate_time: times of the costate rows [s].
      hamiltonian: H = L + lambda' f at costate_time [cost units / s].
      solve_time: wall time of the solver [s]; build_time: transcription [s].
      transcription, solver, nodes; iterations where the solver reports them.
      max_defect: largest scaled dynamics/constraint violation at the solution.
    """

    success: bool
    message: str
    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    objective: float
    costates: np.ndarray | None
    costate_time: np.ndarray | None
    hamiltonian: np.ndarray | None
    solve_time: float
    build_time: float
    transcription: str
    solver: str
    nodes: int
    max_defect: float
    problem: object = dc.field(repr=False, default=None)

    @property
    def final_time(self) -> float:
        return float(self.time[-1])

    def control_function(self):
        """u(t) [SI] between the nodes: the Lagrange interpolant of the LGL nodes (the
        method's own representation) or first-order hold for dircol."""
        t, U = self.time, self.controls
        if self.transcription == "lgl":
            tf = t[-1]
            tau_nodes = 2.0 * t / tf - 1.0

            def u(tt):
                tau = np.clip(2.0 * np.atleast_1d(tt) / tf - 1.0, -1.0, 1.0)
                return interpolation_matrix(tau_nodes, tau) @ U
        else:
            def u(tt):
                return np.column_stack([np.interp(np.atleast_1d(tt), t, U[:, j]) for j in range(U.shape[1])])
        return u

    def state_function(self):
        """x(t) [SI] between the nodes (Lagrange interpolant for LGL, linear for dircol)."""
        t, X = self.time, self.states
        if self.transcription == "lgl":
            tau_nodes = 2.0 * t / t[-1] - 1.0
            return lambda tt: interpolation_matrix(tau_nodes, np.clip(2.0 * np.atleast_1d(tt) / t[-1] - 1.0, -1, 1)) @ X
        return lambda tt: np.column_stack([np.interp(np.atleast_1d(tt), t, X[:, j]) for j in range(X.shape[1])])


class NlpError(RuntimeError):
    """The NLP could not be built (bad options or problem)."""


# ---------------------------------------------------------------------------------------
# public entry point
# ---------------------------------------------------------------------------------------
def solve(problem, *, transcription: str = "lgl", solver: str = "ipopt", nodes: int = 40, guess=None,
          tolerance: float = 1e-8, max_iterations: int = 3000, verbose: bool = False) -> NlpResult:
    """Solve ``problem`` (see module docstring).

    Args:
      transcription: 'lgl' (Legendre pseudospectral, paper 002 eqs. 12-14) or 'dircol'.
      solver: 'ipopt' (default) or 'snopt'.
      nodes: LGL nodes or DirectCollocation samples (>= 3).
      guess: an NlpResult, or (t [s], states (n, nx), controls (n, nu)) SI, or None for the
        built-in propagated guess (``initial_guess``).
      tolerance: solver optimality and feasibility tolerance (scaled units).
      max_iterations: solver iteration limit.
    """
    if transcription not in TRANSCRIPTIONS:
        raise ValueError(f"transcription '{transcription}' is unknown; allowed: {', '.join(TRANSCRIPTIONS)}")
    if solver not in SOLVERS:
        raise ValueError(f"solver '{solver}' is unknown; allowed: {', '.join(SOLVERS)}")
    if not (isinstance(nodes, (int, np.integer)) and nodes >= 3):
        raise ValueError(f"nodes must be an integer >= 3, got {nodes}")
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, got {tolerance}")
    engine = IpoptSolver() if solver == "ipopt" else SnoptSolver()
    if not engine.available() or not engine.enabled():
        raise NlpError(f"solver '{solver}' is not available in this pydrake build")
    if guess is None:
        guess = initial_guess(problem)
    elif isinstance(guess, NlpResult):
        guess = (guess.time, guess.states, guess.controls)
    t_build = _time.perf_counter()
    tx = _LglTranscription(problem, nodes) if transcription == "lgl" else _DircolTranscription(problem, nodes)
    tx.set_guess(*guess)
    build_time = _time.perf_counter() - t_build
    options = SolverOptions()
    if solver == "ipopt":
        options.SetOption(engine.solver_id(), "tol", tolerance)
        options.SetOption(engine.solver_id(), "constr_viol_tol", tolerance)
        options.SetOption(engine.solver_id(), "max_iter", int(max_iterations))
        options.SetOption(engine.solver_id(), "print_level", 5 if verbose else 0)
    else:
        options.SetOption(engine.solver_id(), "Major optimality tolerance", tolerance)
        options.SetOption(engine.solver_id(), "Major feasibility tolerance", tolerance)
        options.SetOption(engine.solver_id(), "Major iterations limit", int(max_iterations))
        options.SetOption(engine.solver_id(), "Iterations limit", int(max_iterations) * 100)
        if verbose:
            options.SetOption(engine.solver_id(), "Print file", "snopt.out")
    t0 = _time.perf_counter()
    res = engine.Solve(tx.prog, tx.initial_guess, options)
    solve_time = _time.perf_counter() - t0
    return tx.result(res, solver, solve_time, build_time)


# ---------------------------------------------------------------------------------------
# initial guess by propagating a simple control law
# ---------------------------------------------------------------------------------------
def initial_guess(problem, samples: int = 200):
    """(t, states, controls) SI: a propagated guess.

    Entry problems: fly a constant angle of attack (alpha-bar, within the bounds) and a
    constant bank magnitude found by bisection so the flight ends at the final altitude
    near the final position (or at the fixed/maximum final time), with controls at rest.
    Other problems: the straight line between the boundary values over the mean final
    time, controls at the middle of their bounds (or zero).
    """
    if isinstance(problem, OptimalControlProblem):
        return _entry_guess(problem, samples)
    return _straight_line_guess(problem, samples)


def _mid(lo, hi, default):
    if np.isfinite(lo) and np.isfinite(hi):
        return 0.5 * (lo + hi)
    if np.isfinite(lo):
        return max(lo, default)
    if np.isfinite(hi):
        return min(hi, default)
    return default


def _straight_line_guess(problem, samples):
    t_lo, t_hi = problem.final_time_bounds
    tf = 0.5 * (t_lo + t_hi) if np.isfinite(t_hi) else t_lo * 2.0
    x0l, x0h = problem.boundary_bounds("initial")
    xfl, xfh = problem.boundary_bounds("final")
    xl, xh, ul, uh = problem.bounds_arrays()
    x0 = np.array([_mid(a, b, _mid(c, d, 0.0)) for a, b, c, d in zip(x0l, x0h, xl, xh)])
    xf = np.array([_mid(a, b, x0[i]) for i, (a, b) in enumerate(zip(xfl, xfh))])
    t = np.linspace(0.0, tf, samples)
    X = x0[None, :] + (t / tf)[:, None] * (xf - x0)[None, :]
    U = np.tile([_mid(a, b, 0.0) for a, b in zip(ul, uh)], (samples, 1))
    return t, X, U


def _entry_guess(problem: OptimalControlProblem, samples):
    from scipy.integrate import solve_ivp

    x0l, x0h = problem.boundary_bounds("initial")
    if not np.all(np.isfinite(x0l[:6])) or not np.allclose(x0l[:6], x0h[:6]):
        return _straight_line_guess(problem, samples)
    x0 = x0l.copy()
    xl, xh, ul, uh = problem.bounds_arrays()
    xfl, xfh = problem.boundary_bounds("final")
    h_end = xfl[0] if np.isfinite(xfl[0]) else 0.0
    alpha = float(np.clip(problem.alpha_bar, xl[6] if problem.controls == "rates" else ul[0],
                          xh[6] if problem.controls == "rates" else uh[0]))
    t_lo, t_hi = problem.final_time_bounds
    t_max = t_hi if np.isfinite(t_hi) else 5000.0
    target = None
    if np.isfinite(xfl[1]) and np.isfinite(xfl[2]):
        target = (xfl[1], xfl[2])

    def fly(bank):
        def f(t, y):
            u = np.zeros(problem.n_controls) if problem.controls == "rates" else np.array([alpha, bank])
            x = y.copy()
            if problem.controls == "rates":
                x[6], x[7] = alpha, bank
            return problem.dynamics(x, u)

        def ground(t, y):
            return y[0] - h_end
        ground.terminal, ground.direction = True, -1
        y0 = x0.copy()
        if problem.controls == "rates":
            y0[6], y0[7] = alpha, bank
        return solve_ivp(f, (0.0, t_max), y0, events=ground, rtol=1e-7, atol=1e-9, max_step=5.0)

    def miss(sol):  # flown central angle beyond the target's [rad]
        xf = sol.y[:, -1]
        start = (float(x0[1]), float(x0[2]))
        return problem._central_angle(*start, float(xf[1]), float(xf[2])) - problem._central_angle(*start, *target)

    def too_long(sol):  # did not land, or landed beyond the final position
        return sol.status != 1 or (target is not None and miss(sol) > 0)

    # bisection on a constant bank magnitude: more bank = shorter flight
    lo, hi = 0.0, math.radians(89.0)
    best = fly(hi)
    for _ in range(25):
        mid = 0.5 * (lo + hi)
        s = fly(mid)
        if too_long(s):
            lo = mid
        else:
            hi, best = mid, s  # best is always the flight with bank hi
        if hi - lo < 1e-4:
            break
    t = np.linspace(0.0, best.t[-1], samples)
    from scipy.interpolate import interp1d

    X = interp1d(best.t, best.y, axis=1)(t).T
    if problem.controls == "rates":
        U = np.zeros((samples, 2))
    else:
        U = np.column_stack([np.full(samples, alpha), np.full(samples, hi)])
    if t[-1] < t_lo or t[-1] > t_hi:  # stretch to the allowed final time
        t = t * np.clip(t[-1], t_lo, t_hi) / t[-1]
    return t, X, U


# ---------------------------------------------------------------------------------------
# transcriptions
# ---------------------------------------------------------------------------------------
class _Transcription:
    """Scaling, bounds, boundary conditions, path constraints shared by both transcriptions."""

    def __init__(self, problem, nodes: int):
        self.problem = problem
        self.N = nodes
        self.sx, self.su, self.ts = problem.scales()
        self.nx, self.nu = problem.n_states, problem.n_controls
        self.t_lo, self.t_hi = problem.final_time_bounds
        self.fixed_tf = self.t_lo == self.t_hi

    # scaled <-> SI
    def L_scaled(self, xs, us):
        """Lagrangian at scaled (x, u): integrated over scaled time it gives J / time_scale."""
        return self.problem.lagrangian(xs * self.sx, us * self.su)

    def path_scaled(self, xs, us):
        vals = self.problem.path_values(xs * self.sx, us * self.su)
        return np.array([v / c.scale for v, c in zip(vals, self.problem.path)])

    def add_bounds(self, prog, X, U, x_first, x_last):
        xl, xh, ul, uh = self.problem.bounds_arrays()
        for k in range(X.shape[0]):
            prog.AddBoundingBoxConstraint(xl / self.sx, xh / self.sx, X[k])
        for k in range(U.shape[0]):
            prog.AddBoundingBoxConstraint(ul / self.su, uh / self.su, U[k])
        for which, var in (("initial", x_first), ("final", x_last)):
            lo, hi = self.problem.boundary_bounds(which)
            prog.AddBoundingBoxConstraint(lo / self.sx, hi / self.sx, var)

    def add_path(self, prog, X, U):
        path = self.problem.path
        if not path:
            return
        lo = np.array([c.min / c.scale for c in path])
        hi = np.array([c.max / c.scale for c in path])
        nx = self.nx
        for k in range(X.shape[0]):
            prog.AddConstraint(lambda z: self.path_scaled(z[:nx], z[nx:]), lo, hi,
                               np.concatenate([X[k], U[k]]), description=f"path[{k}]")

    def mayer_cost(self, prog, x_last, tf_vars):
        """Mayer cost M(x_f, t_f) / time_scale; t_f (scaled) is the sum of ``tf_vars`` (the
        LGL final time, or the DirectCollocation time steps), or fixed when None."""
        if not self.problem.has_mayer:
            return
        nx = self.nx
        if tf_vars is None:
            tf = self.t_lo
            prog.AddCost(lambda z: self.problem.mayer(z * self.sx, tf) / self.ts, x_last)
        else:
            prog.AddCost(lambda z: self.problem.mayer(z[:nx] * self.sx, z[nx:].sum() * self.ts) / self.ts,
                         np.concatenate([x_last, np.atleast_1d(tf_vars)]))

    def worst_violation(self, res) -> tuple[float, str]:
        """(largest scaled constraint violation, the constraint's description) at ``res``."""
        worst, where = 0.0, ""
        for b in self.prog.GetAllConstraints():
            v = res.EvalBinding(b)
            lo, hi = b.evaluator().lower_bound(), b.evaluator().upper_bound()
            viol = np.maximum(lo - v, 0.0) + np.maximum(v - hi, 0.0)
            viol = viol[np.isfinite(viol)]
            if viol.size and viol.max() > worst:
                worst = float(viol.max())
                where = b.evaluator().get_description() or type(b.evaluator()).__name__
        return worst, where

    def diagnose(self, res) -> str:
        """Name the worst violated constraint at the returned point (infeasible problems)."""
        worst, where = self.worst_violation(res)
        return f"largest violation {worst:.3g} (scaled) in '{where}'" if worst > 0 else "no violated constraint"

    def _message(self, res, solver) -> tuple[bool, str]:
        ok = res.is_success()
        detail = res.get_solution_result().name
        try:
            if solver == "ipopt":
                detail += f" (Ipopt status {res.get_solver_details().status})"
            else:
                detail += f" (SNOPT info {res.get_solver_details().info})"
        except Exception:  # noqa: BLE001 - details are a courtesy
            pass
        return ok, ("solved: " if ok else "not solved: ") + detail


class _NodeEvaluator:
    """Dynamics, path functions and Lagrangian at all nodes with their Jacobians.

    Every node's values depend only on that node's state and control, so one vectorised
    model call on the nodes and their 2 (n_x + n_u) central perturbations gives all
    Jacobian blocks (step (eps^(1/3)) in scaled units, truncation error ~1e-10). Models only
    need to accept float arrays; a model that does not is evaluated node by node."""

    def __init__(self, tx, step: float = 6e-6):
        self.tx, self.step = tx, step
        self._key, self._out = None, None
        self.vectorised = True

    def _models(self, Xs, Us):
        """f_scaled (nx, M), path_scaled (np, M), L (M,) at M scaled points (columns)."""
        tx = self.tx
        x = Xs * tx.sx[:, None]
        u = Us * tx.su[:, None]
        if self.vectorised:
            try:
                return self._call(x, u)
            except Exception:  # noqa: BLE001 - a model without array support
                self.vectorised = False
        cols = [self._call(x[:, m], u[:, m]) for m in range(x.shape[1])]
        return (np.column_stack([c[0] for c in cols]), np.column_stack([c[1] for c in cols]),
                np.array([c[2] for c in cols], float))

    def _call(self, x, u):
        tx, p = self.tx, self.tx.problem
        xs, us = list(x), list(u)
        m = np.shape(x)[1:] or ()
        f = np.array([np.broadcast_to(np.asarray(v, float), m) for v in p.dynamics(xs, us)])
        f = f * (tx.ts / tx.sx).reshape((-1,) + (1,) * len(m))
        if p.path:
            g = np.array([np.broadcast_to(np.asarray(v, float), m) / c.scale
                          for v, c in zip(p.path_values(xs, us), p.path)])
        else:
            g = np.zeros((0,) + tuple(m))
        L = np.broadcast_to(np.asarray(p.lagrangian(xs, us), float), m) if p.has_lagrange else np.zeros(m)
        return f, g, L

    def evaluate(self, Xs, Us):
        """Values and node Jacobians: f (N, nx), g (N, np), L (N,), and df (N, nx, nx+nu),
        dg (N, np, nx+nu), dL (N, nx+nu) with respect to the scaled node variables."""
        key = np.concatenate([Xs.ravel(), Us.ravel()]).tobytes()
        if key == self._key:
            return self._out
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
        self._key, self._out = key, (f0, g0, L0, df, dg, dL)
        return self._out


def _chain(J, G):
    """J @ G for the input gradient G that Drake passes: the identity in practice (skip the
    dense product, which dominates at 125 nodes), any matrix in general."""
    if G.shape[0] == G.shape[1] and np.count_nonzero(G) == G.shape[0] and np.all(np.diag(G) == 1.0):
        return J
    return J @ G


class _LglTranscription(_Transcription):
    """Paper 002 eqs. 12-14 on LGL nodes.

    Decision variables z = [X (N x nx), U (N x nu), t_f] (scaled). One constraint holds
    the defects D X - (t_f / 2) f(X, U) = 0 (eq. 13, rows node-major) and the path
    functions (eq. 14); its Jacobian is assembled from the exact D and the node Jacobians
    of _NodeEvaluator, with the true sparsity pattern declared to the solver. The cost is
    (t_f / 2) sum w_k L_k (eq. 12) plus the Mayer term. Costates: the defect rows'
    multipliers divided by the LGL weights (eq. 15)."""

    def __init__(self, problem, nodes):
        super().__init__(problem, nodes)
        self.lgl = LGL(nodes)
        prog = self.prog = MathematicalProgram()
        N, nx, nu = nodes, self.nx, self.nu
        self.X = prog.NewContinuousVariables(N, nx, "x")
        self.U = prog.NewContinuousVariables(N, nu, "u")
        self.tf = None if self.fixed_tf else prog.NewContinuousVariables(1, "tf")[0]
        if self.tf is not None:
            prog.AddBoundingBoxConstraint(self.t_lo / self.ts, min(self.t_hi, 1e12) / self.ts, self.tf)
        self.nodes_eval = _NodeEvaluator(self)
        self.n_path = len(problem.path)
        z = [self.X.ravel(), self.U.ravel()] + ([[self.tf]] if self.tf is not None else [])
        self.z = np.concatenate(z)
        lo = np.concatenate([np.zeros(N * nx)] + [np.full(N, c.min / c.scale) for c in problem.path])
        hi = np.concatenate([np.zeros(N * nx)] + [np.full(N, c.max / c.scale) for c in problem.path])
        # path rows are ordered path-major: row N nx + c N + k
        self.collocation = prog.AddConstraint(self._constraint, lo, hi, self.z, description="LGL defects and path")
        self.collocation.evaluator().SetGradientSparsityPattern(self._sparsity())
        self.add_bounds(prog, self.X, self.U, self.X[0], self.X[-1])
        if problem.has_lagrange:
            prog.AddCost(self._lagrange_cost, self.z)
        self.mayer_cost(prog, self.X[-1], None if self.tf is None else [self.tf])

    # -- variable layout ------------------------------------------------------------------
    def _split(self, zv):
        N, nx, nu = self.N, self.nx, self.nu
        Xs = zv[:N * nx].reshape(N, nx)
        Us = zv[N * nx:N * (nx + nu)].reshape(N, nu)
        tf = zv[-1] if self.tf is not None else self.t_lo / self.ts
        return Xs, Us, tf

    def _x_col(self, k, i):
        return k * self.nx + i

    def _u_col(self, k, j):
        return self.N * self.nx + k * self.nu + j

    def _sparsity(self):
        N, nx, nu, npth = self.N, self.nx, self.nu, self.n_path
        pairs = []
        node_cols = [[self._x_col(k, m) for m in range(nx)] + [self._u_col(k, j) for j in range(nu)] for k in range(N)]
        tf_col = [self.z.size - 1] if self.tf is not None else []
        for k in range(N):
            for i in range(nx):
                r = k * nx + i
                cols = set(self._x_col(l, i) for l in range(N)) | set(node_cols[k]) | set(tf_col)
                pairs += [(r, c) for c in sorted(cols)]
        for c in range(npth):
            for k in range(N):
                pairs += [(N * nx + c * N + k, col) for col in node_cols[k]]
        return pairs

    # -- NLP functions --------------------------------------------------------------------
    def _values_jacobian(self, zv):
        N, nx, nu, npth = self.N, self.nx, self.nu, self.n_path
        Xs, Us, tf = self._split(zv)
        f, g, L, df, dg, dL = self.nodes_eval.evaluate(Xs, Us)
        D = self.lgl.D1_tau
        defect = (D @ Xs - 0.5 * tf * f).ravel()
        values = np.concatenate([defect, g.T.ravel()])
        J = np.zeros((N * nx + npth * N, zv.size))
        for i in range(nx):  # D acts on each state's nodal values
            idx = np.arange(N) * nx + i
            J[np.ix_(idx, idx)] += D
        for k in range(N):
            rows = k * nx + np.arange(nx)
            J[np.ix_(rows, k * nx + np.arange(nx))] -= 0.5 * tf * df[k, :, :nx]
            J[np.ix_(rows, N * nx + k * nu + np.arange(nu))] -= 0.5 * tf * df[k, :, nx:]
            for c in range(npth):
                r = N * nx + c * N + k
                J[r, k * nx:(k + 1) * nx] = dg[k, c, :nx]
                J[r, N * nx + k * nu:N * nx + (k + 1) * nu] = dg[k, c, nx:]
        if self.tf is not None:
            J[:N * nx, -1] = -0.5 * f.ravel()
        return values, J

    def _constraint(self, z):
        if z.dtype != object:
            return self._values_jacobian(np.asarray(z, float))[0]
        zv = ExtractValue(z).ravel()
        values, J = self._values_jacobian(zv)
        return InitializeAutoDiff(values, _chain(J, ExtractGradient(z))).ravel()

    def _lagrange_value_gradient(self, zv):
        N, nx, nu = self.N, self.nx, self.nu
        Xs, Us, tf = self._split(zv)
        *_, L, _, _, dL = self.nodes_eval.evaluate(Xs, Us)
        w = self.lgl.weights_tau
        value = 0.5 * tf * float(w @ L)
        grad = np.zeros(zv.size)
        grad[:N * nx] = (0.5 * tf * w[:, None] * dL[:, :nx]).ravel()
        grad[N * nx:N * (nx + nu)] = (0.5 * tf * w[:, None] * dL[:, nx:]).ravel()
        if self.tf is not None:
            grad[-1] = 0.5 * float(w @ L)
        return value, grad

    def _lagrange_cost(self, z):
        if z.dtype != object:
            return self._lagrange_value_gradient(np.asarray(z, float))[0]
        value, grad = self._lagrange_value_gradient(ExtractValue(z).ravel())
        return InitializeAutoDiff(np.array([value]), _chain(grad[None, :], ExtractGradient(z)))[0, 0]

    def set_guess(self, t, X, U):
        t = np.asarray(t, float)
        tf = float(np.clip(t[-1], self.t_lo, self.t_hi))
        tk = (self.lgl.tau + 1.0) * 0.5 * t[-1]
        Xk = np.column_stack([np.interp(tk, t, np.asarray(X)[:, i]) for i in range(self.nx)]) / self.sx
        Uk = np.column_stack([np.interp(tk, t, np.asarray(U)[:, j]) for j in range(self.nu)]) / self.su
        guess = np.zeros(self.prog.num_vars())
        self.initial_guess = guess
        self.prog.SetDecisionVariableValueInVector(self.X, Xk, guess)
        self.prog.SetDecisionVariableValueInVector(self.U, Uk, guess)
        if self.tf is not None:
            self.prog.SetDecisionVariableValueInVector(self.tf, tf / self.ts, guess)

    def result(self, res, solver, solve_time, build_time) -> NlpResult:
        ok, msg = self._message(res, solver)
        Xs = np.reshape(res.GetSolution(self.X), (self.N, self.nx))
        Us = np.reshape(res.GetSolution(self.U), (self.N, self.nu))
        tf = self.t_lo if self.tf is None else float(res.GetSolution(self.tf)) * self.ts
        t = (self.lgl.tau + 1.0) * 0.5 * tf
        X, U = Xs * self.sx, Us * self.su
        costates = None
        try:  # eq. 15: lambda_k = nu_k / w_k (scaled), then d J / d x in SI
            nu = np.asarray(res.GetDualSolution(self.collocation))[:self.N * self.nx].reshape(self.N, self.nx)
            lam_scaled = nu / self.lgl.weights_tau[:, None]
            costates = COSTATE_SIGN * lam_scaled * self.ts / self.sx
        except Exception:  # noqa: BLE001 - a solver without duals
            costates = None
        if not ok:
            msg += "; " + self.diagnose(res)
        return _finish(self, ok, msg, t, X, U, res, costates, t if costates is not None else None,
                       solve_time, build_time, "lgl", solver)


class _DircolTranscription(_Transcription):
    """Drake DirectCollocation (Hermite-Simpson) of the scaled plant."""

    def __init__(self, problem, nodes):
        super().__init__(problem, nodes)
        from pydrake.planning import DirectCollocation

        from drake_entry.systems.ocp_plant import OptimalControlPlant  # the transcription needs a Drake System

        self.plant = OptimalControlPlant(problem, self.sx, self.su, self.ts)
        h_min = self.t_lo / self.ts / (nodes - 1) * 0.2
        h_max = (self.t_hi if np.isfinite(self.t_hi) else 10 * self.t_lo) / self.ts / (nodes - 1) * 5.0
        self.dc = DirectCollocation(self.plant, self.plant.CreateDefaultContext(), nodes, h_min, h_max)
        self.dc.AddEqualTimeIntervalsConstraints()
        self.dc.AddDurationBounds(self.t_lo / self.ts, min(self.t_hi, 1e12) / self.ts)
        prog = self.prog = self.dc.prog()
        N, nx, nu = nodes, self.nx, self.nu
        self.X = np.array([self.dc.state(k) for k in range(N)])
        self.U = np.array([self.dc.input(k) for k in range(N)])
        self.H = np.array([self.dc.time_step(k)[0] for k in range(N - 1)])
        self.add_bounds(prog, self.X, self.U, self.dc.initial_state(), self.dc.final_state())
        self.add_path(prog, self.X, self.U)
        if problem.has_lagrange:  # trapezoid rule over the samples
            for k in range(N - 1):
                prog.AddCost(lambda z: 0.5 * z[-1] * (self.L_scaled(z[:nx], z[nx:nx + nu])
                                                      + self.L_scaled(z[nx + nu:2 * nx + nu], z[2 * nx + nu:-1])),
                             np.concatenate([self.X[k], self.U[k], self.X[k + 1], self.U[k + 1], [self.H[k]]]))
        self.collocation = [b for b in prog.GetAllConstraints()
                            if b.evaluator().get_description().startswith("collocation constraint")]
        self.mayer_cost(prog, self.X[-1], None if self.fixed_tf else self.H)

    def set_guess(self, t, X, U):
        from pydrake.trajectories import PiecewisePolynomial

        t = np.asarray(t, float) / self.ts
        Xs = (np.asarray(X) / self.sx).T
        Us = (np.asarray(U) / self.su).T
        self.dc.SetInitialTrajectory(PiecewisePolynomial.FirstOrderHold(t, Us),
                                     PiecewisePolynomial.FirstOrderHold(t, Xs))
        self.initial_guess = self.prog.GetInitialGuess(self.prog.decision_variables())

    def result(self, res, solver, solve_time, build_time) -> NlpResult:
        ok, msg = self._message(res, solver)
        t = self.dc.GetSampleTimes(res) * self.ts
        X = np.reshape(self.dc.GetStateSamples(res), (self.nx, self.N)).T * self.sx
        U = np.reshape(self.dc.GetInputSamples(res), (self.nu, self.N)).T * self.su
        costates, t_mid = None, 0.5 * (t[:-1] + t[1:])
        try:  # collocation multipliers at the segment midpoints
            h = np.diff(t) / self.ts
            nu = np.vstack([res.GetDualSolution(b) for b in self.collocation])
            costates = COSTATE_SIGN * DIRCOL_COSTATE_FACTOR * nu / h[:, None] * self.ts / self.sx
        except Exception:  # noqa: BLE001
            costates = None
        if not ok:
            msg += "; " + self.diagnose(res)
        return _finish(self, ok, msg, t, X, U, res, costates, t_mid if costates is not None else None,
                       solve_time, build_time, "dircol", solver)


def _finish(tx, ok, msg, t, X, U, res, costates, t_costate, solve_time, build_time, transcription, solver):
    problem = tx.problem
    objective = float(res.get_optimal_cost()) * tx.ts
    ham = None
    if costates is not None:
        Xc = X if len(t_costate) == len(t) else 0.5 * (X[:-1] + X[1:])
        Uc = U if len(t_costate) == len(t) else 0.5 * (U[:-1] + U[1:])
        ham = np.array([float(problem.lagrangian(x, u)) + float(lam @ np.asarray(problem.dynamics(x, u), float))
                        for x, u, lam in zip(Xc, Uc, costates)])
    viol = tx.worst_violation(res)[0]
    return NlpResult(success=ok, message=msg, time=t, states=X, controls=U, objective=objective,
                     costates=costates, costate_time=t_costate, hamiltonian=ham, solve_time=solve_time,
                     build_time=build_time, transcription=transcription, solver=solver, nodes=tx.N,
                     max_defect=viol, problem=problem)


def extremal_controls(problem, result: NlpResult) -> np.ndarray:
    """Rates u* that minimise the Hamiltonian given the costates (paper 002 eqs. 22-23):
    dH/du = 2 k2 u / u_max^2 + lambda_alpha = 0 gives u*_alpha = -u_max^2 lambda_alpha / (2 k2)
    (and likewise for sigma), clipped to the rate bounds; at the costate times, SI.

    The paper prints u_max / (2 k) in eq. 23; differentiating its eq. 11 gives u_max^2
    (the square is missing in eqs. 22-23)."""
    if not isinstance(problem, OptimalControlProblem) or problem.controls != "rates":
        raise ValueError("extremal_controls needs an entry problem with controls='rates'")
    terms = [t for t in problem.objective if t.kind == "control_margin"]
    if len(terms) != 1 or any(t.kind in ("lagrange",) for t in problem.objective):
        raise ValueError("extremal_controls needs exactly one control_margin term and no user Lagrange term")
    if result.costates is None:
        raise ValueError("the result has no costates (the solver returned no multipliers)")
    t = terms[0]
    lam = result.costates
    u = np.column_stack([-t.u_alpha_max ** 2 * lam[:, 6] / (2.0 * t.weight * t.k[1]),
                         -t.u_sigma_max ** 2 * lam[:, 7] / (2.0 * t.weight * t.k[2])])
    _, _, ul, uh = problem.bounds_arrays()
    return np.clip(u, ul, uh)


def summary(problem, result: NlpResult, check=None) -> dict:
    """Figures of merit of a solution (paper 002 'Results' for entry problems): objective,
    final time, solve time, the local altitude maxima and the dynamic pressure there,
    final bank, largest |H| at interior nodes, extremal-control match and, with ``check``
    (a diagrams.propagation.PropagationCheck), the propagated terminal errors."""
    out = {"success": result.success, "message": result.message, "transcription": result.transcription,
           "solver": result.solver, "nodes": result.nodes, "objective": result.objective,
           "final_time_s": result.final_time, "solve_time_s": result.solve_time, "build_time_s": result.build_time,
           "max_constraint_violation_scaled": result.max_defect}
    if result.hamiltonian is not None:
        inner = result.hamiltonian[1:-1] if result.hamiltonian.size > 2 else result.hamiltonian
        out["hamiltonian_interior_max_abs"] = float(np.abs(inner).max())
        out["hamiltonian_interior_rms"] = float(np.sqrt(np.mean(inner ** 2)))
        out["hamiltonian_interior_mean"] = float(np.mean(inner))
    if isinstance(problem, OptimalControlProblem):
        t = np.linspace(0.0, result.final_time, 4001)
        x = result.state_function()(t)
        h = x[:, 0]
        peaks = [i for i in range(1, len(t) - 1) if h[i] >= h[i - 1] and h[i] > h[i + 1]]
        out["altitude_maxima"] = [{"time_s": float(t[i]), "altitude_km": float(h[i] / 1e3),
                                   "dynamic_pressure_kPa": float(problem.conditions(x[i], np.zeros(problem.n_controls))
                                                                  .dynamic_pressure / 1e3)} for i in peaks]
        if problem.controls == "rates":
            out["final_bank_deg"] = float(np.degrees(result.states[-1, 7]))
            out["max_bank_deg"] = float(np.degrees(np.abs(result.states[:, 7]).max()))
            out["max_alpha_deg"] = float(np.degrees(result.states[:, 6].max()))
            try:
                ext = extremal_controls(problem, result)
                U = result.controls if len(result.costate_time) == len(result.time) else \
                    0.5 * (result.controls[:-1] + result.controls[1:])
                out["extremal_control_max_diff_deg_s"] = float(np.degrees(np.abs(ext - U).max()))
            except ValueError:
                pass
    if check is not None:
        out["propagated_terminal_error"] = check.terminal_error
    return out
