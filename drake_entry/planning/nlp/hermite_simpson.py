"""Hermite-Simpson direct collocation, vectorised: the NLP of Drake's DirectCollocation
(equal intervals, cubic Hermite states, first-order-hold controls, the running cost by the
trapezoid rule over the samples), with every model call of an evaluation in one vectorised
call and the Jacobian assembled from the node and midpoint Jacobians with its sparsity
declared (node_program), as the LGL transcription has.

On interval k of length h = t_f / (N - 1) (Hargraves & Paris 1987, the compressed form):

    x_c = (x_k + x_k+1) / 2 + h (f_k - f_k+1) / 8,   u_c = (u_k + u_k+1) / 2
    c_k = 3 (x_k+1 - x_k) / (2 h) - (f_k + f_k+1) / 4 - f(x_c, u_c) = 0

(the cubic's slope at the midpoint minus the dynamics there): the residual of Drake's
DirectCollocationConstraint row for row, so the multipliers give the costates as there,
lambda(t_k+1/2) = 1.5 nu_k / h (dircol.DIRCOL_COSTATE_FACTOR). t_f is kept above 1e-6 time
scales (h divides the rows)."""
from __future__ import annotations

import numpy as np

from drake_entry.planning.nlp.dircol import DIRCOL_COSTATE_FACTOR
from drake_entry.planning.nlp.evaluator import _NodeEvaluator
from drake_entry.planning.nlp.node_program import _NodeProgram, _Part
from drake_entry.planning.nlp.result import NlpResult

__all__ = ["MIN_FINAL_TIME", "PART_INTERVALS", "interval_parts"]

MIN_FINAL_TIME = 1e-6  # [time scales]
#: intervals per part (one constraint each, node_program): Drake packs a Python constraint's
#: Jacobian as AutoDiff over all its variables, so parts of this size cost far less than one
#: over every sample (the SCvx cross-check's 100 samples: see docs/performance.md)
PART_INTERVALS = 25


def interval_parts(nodes: int, nx: int, per_part: int | None = None) -> list:
    """Parts of about ``per_part`` (default PART_INTERVALS) intervals each, neighbours sharing
    a sample (its path rows in the part before it, the last sample's in the last part)."""
    n_parts = max(1, round((nodes - 1) / (per_part or PART_INTERVALS)))
    edges = np.linspace(0, nodes - 1, n_parts + 1).round().astype(int)
    return [_Part(int(a), int(b) + 1, int(b - a) * nx, int(b - a) + (j == n_parts - 1), j)
            for j, (a, b) in enumerate(zip(edges[:-1], edges[1:]))]


class _HermiteSimpsonTranscription(_NodeProgram):
    """Hermite-Simpson collocation rows (interval-major: row k nx + i) and the path rows at
    the N samples, in parts of about PART_INTERVALS intervals; z = [X, U, t_f] (scaled)."""

    description = "Hermite-Simpson collocation and path"
    row_unit = "the interval from node"

    def __init__(self, problem, nodes, scaling):
        super().__init__(problem, nodes, scaling, interval_parts(nodes, problem.n_states))
        self.midpoints_eval = _NodeEvaluator(self, dynamics_only=True)  # the rows need f there only
        if self.tf is not None:
            self.prog.AddBoundingBoxConstraint(MIN_FINAL_TIME, np.inf, self.tf)

    def node_times(self, tf):
        return np.linspace(0.0, tf, self.N)

    def _collocation_sparsity(self, part):
        pairs, N = [], part.size
        for k in range(N - 1):
            cols = self._node_cols(k, N) + self._node_cols(k + 1, N) + self._tf_cols(N)
            for i in range(self.nx):
                pairs += [(k * self.nx + i, c) for c in cols]
        return pairs

    def _collocation(self, part, Xs, Us, tf, J):
        N, nx, nu = part.size, self.nx, self.nu
        f, _, _, df, _, _ = self.nodes_eval.evaluate(Xs, Us)
        n, intervals = N - 1, self.N - 1  # the part's intervals, all of them
        h = tf / intervals
        f0, f1 = f[:-1], f[1:]
        xc = 0.5 * (Xs[:-1] + Xs[1:]) + h / 8.0 * (f0 - f1)
        uc = 0.5 * (Us[:-1] + Us[1:])
        fc, _, _, dfc, _, _ = self.midpoints_eval.evaluate(xc, uc)
        rows = 1.5 / h * (Xs[1:] - Xs[:-1]) - 0.25 * (f0 + f1) - fc
        A0, B0, A1, B1 = df[:-1, :, :nx], df[:-1, :, nx:], df[1:, :, :nx], df[1:, :, nx:]
        Ac, Bc = dfc[:, :, :nx], dfc[:, :, nx:]
        eye = np.eye(nx)
        d_x0 = -(Ac @ (0.5 * eye + h / 8.0 * A0) + 1.5 / h * eye + 0.25 * A0)
        d_u0 = -(h / 8.0 * Ac @ B0 + 0.5 * Bc + 0.25 * B0)
        d_x1 = -(Ac @ (0.5 * eye - h / 8.0 * A1) - 1.5 / h * eye + 0.25 * A1)
        d_u1 = -(-h / 8.0 * Ac @ B1 + 0.5 * Bc + 0.25 * B1)
        Jx = J[:n * nx, :N * nx].reshape(n, nx, N, nx)  # views into J
        Ju = J[:n * nx, N * nx:N * (nx + nu)].reshape(n, nx, N, nu)
        k = np.arange(n)
        Jx[k, :, k, :] = d_x0
        Jx[k, :, k + 1, :] = d_x1
        Ju[k, :, k, :] = d_u0
        Ju[k, :, k + 1, :] = d_u1
        if self.tf is not None:  # d/d t_f = (d/d h) / (N - 1)
            d_h = -np.einsum("kij,kj->ki", Ac, (f0 - f1) / 8.0) - 1.5 / h ** 2 * (Xs[1:] - Xs[:-1])
            J[:n * nx, -1] = (d_h / intervals).ravel()
        return rows.ravel()

    def _quadrature_weights(self, part):
        """The part's share of 1 / (N - 1) (sum L_k - (L_0 + L_N-1) / 2) over t_f: the trapezoid
        rule of dircol."""
        w = np.full(part.size, 1.0 / (self.N - 1))
        w[[0, -1]] *= 0.5
        return w

    def result(self, res) -> NlpResult:
        t, X, U, nu = self.solution(res)
        costates, t_mid = None, 0.5 * (t[:-1] + t[1:])
        if nu is not None:  # collocation multipliers at the interval midpoints, as dircol's
            h = np.diff(t) / self.ts
            costates = self.costates_from(DIRCOL_COSTATE_FACTOR * nu.reshape(self.N - 1, self.nx) / h[:, None])
        return self.make_result(res, t, X, U, costates, t_mid if costates is not None else None, "hermite_simpson")
