"""Legendre pseudospectral (LGL) transcription, paper 002 eqs. 12-15."""
from __future__ import annotations

import numpy as np
from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff
from pydrake.solvers import MathematicalProgram

from drake_entry.planning.nlp.evaluator import _chain, _NodeEvaluator
from drake_entry.planning.nlp.result import NlpResult
from drake_entry.planning.nlp.transcription import _Transcription
from drake_entry.planning.pseudospectral import LGL


class _LglTranscription(_Transcription):
    """Paper 002 eqs. 12-14 on LGL nodes.

    Decision variables z = [X (N x nx), U (N x nu), t_f] (scaled). One constraint holds
    the defects D X - (t_f / 2) f(X, U) = 0 (eq. 13, rows node-major) and the path
    functions (eq. 14); its Jacobian is assembled from the exact D and the node Jacobians
    of _NodeEvaluator, with the true sparsity pattern declared to the solver. The cost is
    (t_f / 2) sum w_k L_k (eq. 12) plus the Mayer term. Costates: the defect rows'
    multipliers divided by the LGL weights (eq. 15)."""

    def __init__(self, problem, nodes, scaling):
        super().__init__(problem, nodes, scaling)
        self.lgl = LGL(nodes)
        prog = self.prog = MathematicalProgram()
        N, nx, nu = nodes, self.nx, self.nu
        self.X = prog.NewContinuousVariables(N, nx, "x")
        self.U = prog.NewContinuousVariables(N, nu, "u")
        self.tf = None if self.fixed_tf else prog.NewContinuousVariables(1, "tf")[0]
        if self.tf is not None:
            prog.AddBoundingBoxConstraint(self.t_lo / self.ts, self.t_hi / self.ts, self.tf)
        self.nodes_eval = _NodeEvaluator(self)
        self.n_path = len(problem.path)
        z = [self.X.ravel(), self.U.ravel()] + ([[self.tf]] if self.tf is not None else [])
        self.z = np.concatenate(z)
        path_lo, path_hi = self.scaled_bounds(problem.path)
        lo = np.concatenate([np.zeros(N * nx), np.repeat(path_lo, N)])
        hi = np.concatenate([np.zeros(N * nx), np.repeat(path_hi, N)])
        # path rows are ordered path-major: row N nx + c N + k
        self.collocation = prog.AddConstraint(self.timer.wrap(self._constraint, bounds=(lo, hi)), lo, hi, self.z,
                                              description="LGL defects and path")
        self.collocation.evaluator().SetGradientSparsityPattern(self._sparsity())
        self.add_bounds(prog, self.X, self.U, self.X[0], self.X[-1])
        self.add_terminal(prog, self.X[-1], self.U[-1])
        if problem.has_lagrange:
            prog.AddCost(self.timer.wrap(self._lagrange_cost, cost=True), self.z)
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
        c = self.cost_factor
        value = 0.5 * c * tf * float(w @ L)
        grad = np.zeros(zv.size)
        grad[:N * nx] = (0.5 * c * tf * w[:, None] * dL[:, :nx]).ravel()
        grad[N * nx:N * (nx + nu)] = (0.5 * c * tf * w[:, None] * dL[:, nx:]).ravel()
        if self.tf is not None:
            grad[-1] = 0.5 * c * float(w @ L)
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

    def result(self, res) -> NlpResult:
        Xs = np.reshape(res.GetSolution(self.X), (self.N, self.nx))
        Us = np.reshape(res.GetSolution(self.U), (self.N, self.nu))
        tf = self.t_lo if self.tf is None else float(res.GetSolution(self.tf)) * self.ts
        t = (self.lgl.tau + 1.0) * 0.5 * tf
        costates = None
        try:  # eq. 15: lambda_k = nu_k / w_k (scaled), then d J / d x in SI
            nu = np.asarray(res.GetDualSolution(self.collocation))[:self.N * self.nx].reshape(self.N, self.nx)
            costates = self.costates_from(nu / self.lgl.weights_tau[:, None])
        except Exception:  # noqa: BLE001 - a solver without duals
            costates = None
        return self.make_result(res, t, Xs * self.sx, Us * self.su, costates, t if costates is not None else None,
                                "lgl")
