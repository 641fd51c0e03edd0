"""Legendre pseudospectral (LGL) transcription, paper 002 eqs. 12-15."""
from __future__ import annotations

import numpy as np

from drake_entry.planning.nlp.node_program import _NodeProgram
from drake_entry.planning.nlp.result import NlpResult
from drake_entry.planning.pseudospectral import LGL


class _LglTranscription(_NodeProgram):
    """Paper 002 eqs. 12-14 on LGL nodes.

    Decision variables z = [X (N x nx), U (N x nu), t_f] (scaled). One constraint holds
    the defects D X - (t_f / 2) f(X, U) = 0 (eq. 13, rows node-major) and the path
    functions (eq. 14); its Jacobian is assembled from the exact D and the node Jacobians
    of _NodeEvaluator, with the true sparsity pattern declared to the solver. The cost is
    (t_f / 2) sum w_k L_k (eq. 12) plus the Mayer term. Costates: the defect rows'
    multipliers divided by the LGL weights (eq. 15)."""

    description = "LGL defects and path"

    def __init__(self, problem, nodes, scaling):
        self.lgl = LGL(nodes)
        super().__init__(problem, nodes, scaling, n_rows=nodes * problem.n_states)

    def node_times(self, tf):
        return (self.lgl.tau + 1.0) * 0.5 * tf

    def _collocation_sparsity(self):
        N, nx = self.N, self.nx
        pairs = []
        for k in range(N):
            for i in range(nx):
                cols = set(self._x_col(m, i) for m in range(N)) | set(self._node_cols(k)) | set(self._tf_cols())
                pairs += [(k * nx + i, c) for c in sorted(cols)]
        return pairs

    def _values_jacobian(self, zv):
        N, nx, nu, npth = self.N, self.nx, self.nu, self.n_path
        Xs, Us, tf = self._split(zv)
        f, g, L, df, dg, dL = self.nodes_eval.evaluate(Xs, Us)
        D = self.lgl.D1_tau
        defect = (D @ Xs - 0.5 * tf * f).ravel()
        J = np.zeros((N * nx + npth * N, zv.size))
        for i in range(nx):  # D acts on each state's nodal values
            idx = np.arange(N) * nx + i
            J[np.ix_(idx, idx)] += D
        for k in range(N):
            rows = k * nx + np.arange(nx)
            J[np.ix_(rows, k * nx + np.arange(nx))] -= 0.5 * tf * df[k, :, :nx]
            J[np.ix_(rows, N * nx + k * nu + np.arange(nu))] -= 0.5 * tf * df[k, :, nx:]
        if self.tf is not None:
            J[:N * nx, -1] = -0.5 * f.ravel()
        values = np.concatenate([defect, self._path_jacobian(J, g, dg)])
        return values, J

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

    def result(self, res) -> NlpResult:
        t, X, U, nu = self.solution(res)
        costates = None
        if nu is not None:  # eq. 15: lambda_k = nu_k / w_k (scaled), then d J / d x in SI
            costates = self.costates_from(nu.reshape(self.N, self.nx) / self.lgl.weights_tau[:, None])
        return self.make_result(res, t, X, U, costates, t if costates is not None else None, "lgl")
