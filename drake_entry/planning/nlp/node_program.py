"""What the vectorised transcriptions (LGL, Hermite-Simpson) share: decision variables
z = [X (N x nx), U (N x nu), t_f] (scaled), one constraint holding every collocation and
path row with its Jacobian assembled from the node Jacobians of a _NodeEvaluator and its
sparsity pattern declared, and a running cost with its exact gradient. A subclass gives the
node times, the rows and their Jacobian (``_values_jacobian``) and the quadrature of the
running cost (``_lagrange_value_gradient``)."""
from __future__ import annotations

import numpy as np
from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.solvers import MathematicalProgram

from drake_entry.planning.nlp.evaluator import _chain, _NodeEvaluator
from drake_entry.planning.nlp.transcription import _Transcription


class _NodeProgram(_Transcription):
    """Node variables, the one constraint of ``n_rows`` collocation rows (= 0) followed by the
    path rows (path-major: row n_rows + c N + k), bounds, terminal and Mayer terms."""

    description = "collocation and path"

    def __init__(self, problem, nodes, scaling, n_rows: int):
        super().__init__(problem, nodes, scaling)
        prog = self.prog = MathematicalProgram()
        N, nx, nu = nodes, self.nx, self.nu
        self.X = prog.NewContinuousVariables(N, nx, "x")
        self.U = prog.NewContinuousVariables(N, nu, "u")
        self.tf = None if self.fixed_tf else prog.NewContinuousVariables(1, "tf")[0]
        if self.tf is not None:
            prog.AddBoundingBoxConstraint(self.t_lo / self.ts, self.t_hi / self.ts, self.tf)
        self.nodes_eval = _NodeEvaluator(self)
        self.n_path = len(problem.path)
        self.n_rows = n_rows
        z = [self.X.ravel(), self.U.ravel()] + ([[self.tf]] if self.tf is not None else [])
        self.z = np.concatenate(z)
        path_lo, path_hi = self.scaled_bounds(problem.path)
        lo = np.concatenate([np.zeros(n_rows), np.repeat(path_lo, N)])
        hi = np.concatenate([np.zeros(n_rows), np.repeat(path_hi, N)])
        self.collocation = prog.AddConstraint(self.timer.wrap(self._constraint, bounds=(lo, hi)), lo, hi, self.z,
                                              description=self.description)
        self.collocation.evaluator().SetGradientSparsityPattern(self._sparsity())
        self.add_bounds(prog, self.X, self.U, self.X[0], self.X[-1])
        self.add_terminal(prog, self.X[-1], self.U[-1])
        if problem.has_lagrange:
            prog.AddCost(self.timer.wrap(self._lagrange_cost, cost=True), self.z)
        self.mayer_cost(prog, self.X[-1], None if self.tf is None else [self.tf])

    # -- layout ---------------------------------------------------------------------------
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

    def _node_cols(self, k) -> list:
        return [self._x_col(k, m) for m in range(self.nx)] + [self._u_col(k, j) for j in range(self.nu)]

    def _tf_cols(self) -> list:
        return [self.z.size - 1] if self.tf is not None else []

    def _collocation_sparsity(self) -> list:  # pragma: no cover - interface
        raise NotImplementedError

    def _sparsity(self):
        pairs = self._collocation_sparsity()
        for c in range(self.n_path):
            for k in range(self.N):
                pairs += [(self.n_rows + c * self.N + k, col) for col in self._node_cols(k)]
        return pairs

    def _path_jacobian(self, J, g, dg):
        """Path values (path-major) and their rows of J from the node values g and Jacobians dg."""
        N, nx, nu = self.N, self.nx, self.nu
        k = np.arange(N)
        for c in range(self.n_path):
            r = self.n_rows + c * N + k
            J[r[:, None], (k * nx)[:, None] + np.arange(nx)] = dg[:, c, :nx]
            J[r[:, None], (N * nx + k * nu)[:, None] + np.arange(nu)] = dg[:, c, nx:]
        return g.T.ravel()

    # -- the callbacks the solver sees ----------------------------------------------------
    def _values_jacobian(self, zv):  # pragma: no cover - interface
        raise NotImplementedError

    def _lagrange_value_gradient(self, zv):  # pragma: no cover - interface
        raise NotImplementedError

    def _constraint(self, z):
        if z.dtype != object:
            return self._values_jacobian(np.asarray(z, float))[0]
        zv = ExtractValue(z).ravel()
        values, J = self._values_jacobian(zv)
        return InitializeAutoDiff(values, _chain(J, ExtractGradient(z))).ravel()

    def _lagrange_cost(self, z):
        if z.dtype != object:
            return self._lagrange_value_gradient(np.asarray(z, float))[0]
        value, grad = self._lagrange_value_gradient(ExtractValue(z).ravel())
        return InitializeAutoDiff(np.array([value]), _chain(grad[None, :], ExtractGradient(z)))[0, 0]

    # -- guess and solution ---------------------------------------------------------------
    def node_times(self, tf: float) -> np.ndarray:  # pragma: no cover - interface
        """The node times [s] for final time tf [s]."""
        raise NotImplementedError

    def set_guess(self, t, X, U):
        t = np.asarray(t, float)
        tf = float(np.clip(t[-1], self.t_lo, self.t_hi))
        tk = self.node_times(t[-1])
        Xk = np.column_stack([np.interp(tk, t, np.asarray(X)[:, i]) for i in range(self.nx)]) / self.sx
        Uk = np.column_stack([np.interp(tk, t, np.asarray(U)[:, j]) for j in range(self.nu)]) / self.su
        guess = np.zeros(self.prog.num_vars())
        self.initial_guess = guess
        self.prog.SetDecisionVariableValueInVector(self.X, Xk, guess)
        self.prog.SetDecisionVariableValueInVector(self.U, Uk, guess)
        if self.tf is not None:
            self.prog.SetDecisionVariableValueInVector(self.tf, tf / self.ts, guess)

    def solution(self, res):
        """(node times [s], states [SI], controls [SI], the collocation rows' multipliers or None)."""
        Xs = np.reshape(res.GetSolution(self.X), (self.N, self.nx))
        Us = np.reshape(res.GetSolution(self.U), (self.N, self.nu))
        tf = self.t_lo if self.tf is None else float(res.GetSolution(self.tf)) * self.ts
        try:
            nu = np.asarray(res.GetDualSolution(self.collocation))[:self.n_rows]
        except Exception:  # noqa: BLE001 - a solver without duals
            nu = None
        return self.node_times(tf), Xs * self.sx, Us * self.su, nu
