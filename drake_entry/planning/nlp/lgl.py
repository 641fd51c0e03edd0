"""Legendre pseudospectral (LGL) transcription, paper 002 eqs. 12-15, on one global
polynomial or on equal segments that share their end nodes (Ross & Fahroo's knotting)."""
from __future__ import annotations

import numpy as np

from drake_entry.planning.nlp.node_program import _NodeProgram, _Part
from drake_entry.planning.nlp.result import NlpResult
from drake_entry.planning.pseudospectral import SegmentMesh, nodes_per_segment, segment_compatible  # noqa: F401 (API)

__all__ = ["nodes_per_segment", "segment_compatible"]


class _LglTranscription(_NodeProgram):
    """Paper 002 eqs. 12-14 on LGL nodes, one polynomial per segment.

    Decision variables z = [X (N x nx), U (N x nu), t_f] (scaled). With normalised time
    s = t / t_f and ``segments`` equal segments of length h (h = 1: the paper's global
    polynomial), segment j's rows are D X_j - (h / 2) t_f f(X_j, U_j) = 0 (eq. 13 on the
    segment's own [-1, 1], rows node-major); a knot (the node two segments share) carries
    both segments' rows. Each segment is one constraint over its own nodes (node_program's
    parts) holding its rows and the path functions (eq. 14) of its nodes (a knot's in the
    segment before it); its Jacobian is assembled from the exact D and the node Jacobians of
    _NodeEvaluator, with the sparsity declared to the solver. The cost is (t_f / 2) sum W_k L_k
    (eq. 12, W the composite weights on [-1, 1]) plus the Mayer term. Costates (eq. 15): the
    multipliers of a node's rows, each times its segment's h, summed and divided by W_k; on
    one segment, nu_k / w_k."""

    description = "LGL defects and path"

    def __init__(self, problem, nodes, scaling, segments: int = 1):
        self.mesh = SegmentMesh(segments, nodes_per_segment(nodes, segments))
        m, nx = self.mesh.nodes_per_segment, problem.n_states
        self.h = self.mesh.length
        self.weights_tau = 2.0 * self.mesh.weights  # composite quadrature on [-1, 1]
        parts = [_Part(int(seg[0]), int(seg[-1]) + 1, m * nx, m if j == segments - 1 else m - 1, j)
                 for j, seg in enumerate(self.mesh.segment_nodes)]
        super().__init__(problem, nodes, scaling, parts)

    @property
    def segments(self) -> int:
        return self.mesh.n_segments

    def node_times(self, tf):
        return self.mesh.s * tf

    def _collocation_sparsity(self, part):
        m, nx = part.size, self.nx
        pairs = []
        for k in range(m):
            for i in range(nx):
                cols = set(self._x_col(j, i) for j in range(m)) | set(self._node_cols(k, m)) | set(self._tf_cols(m))
                pairs += [(k * nx + i, c) for c in sorted(cols)]
        return pairs

    def _collocation(self, part, Xs, Us, tf, J):
        m, nx, nu = part.size, self.nx, self.nu
        f, _, _, df, _, _ = self.nodes_eval.evaluate(Xs, Us)
        D, c = self.mesh.differentiation, 0.5 * self.h * tf
        defect = (D @ Xs - c * f).ravel()
        for i in range(nx):  # D acts on each state's nodal values
            idx = np.arange(m) * nx + i
            J[np.ix_(idx, idx)] += D
        k = np.arange(m)
        rows = (k * nx)[:, None, None] + np.arange(nx)[None, :, None]  # (m, nx, 1)
        J[rows, (k * nx)[:, None, None] + np.arange(nx)[None, None, :]] -= c * df[:, :, :nx]
        J[rows, (m * nx + k * nu)[:, None, None] + np.arange(nu)[None, None, :]] -= c * df[:, :, nx:]
        if self.tf is not None:
            J[:m * nx, -1] = -0.5 * self.h * f.ravel()
        return defect

    def _quadrature_weights(self, part):
        """(h / 2) w_tau of the segment: its share of (t_f / 2) sum W_k L_k (eq. 12)."""
        return 0.5 * self.h * self.mesh.segment_weights

    def result(self, res) -> NlpResult:
        t, X, U, nu = self.solution(res)
        costates = None
        if nu is not None:  # eq. 15 summed over a knot's rows: lambda_k = sum h nu / W_k (scaled), then SI
            per_node = np.zeros((self.N, self.nx))
            np.add.at(per_node, self.mesh.segment_nodes.ravel(), self.h * nu.reshape(-1, self.nx))
            costates = self.costates_from(per_node / self.weights_tau[:, None])
        result = self.make_result(res, t, X, U, costates, t if costates is not None else None, "lgl")
        result.segments = self.segments
        return result
