"""Legendre-Gauss-Lobatto (LGL) pseudospectral operators (paper 000 Sec. II.C, eqs. 8-17).

N + 1 nodes are the roots of (1 - tau^2) P_N'(tau) on [-1, 1] (eq. 8). On them:
  - quadrature weights w_j = 2 / (N (N + 1) P_N(tau_j)^2) (eq. 17, corrected index),
    exact for polynomials of degree <= 2N - 1;
  - first-derivative matrix D1 (eq. 10) and second-derivative matrix D2 = D1 D1 (eq. 14),
    exact for polynomials of degree <= N;
  - barycentric Lagrange interpolation (eq. 9) to any point.
``LGL(n_nodes, a, b)`` maps everything to the interval [a, b] (eqs. 12-13), for time or
energy as the independent variable.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
from numpy.polynomial import legendre

from drake_entry.errors import ScenarioError

__all__ = ["nodes_per_segment", "segment_compatible", "lgl_nodes", "barycentric_weights", "interpolation_matrix", "LGL", "lobatto_integration_matrix",
           "INTEGRATION_MAX_NODES", "SEGMENT_MAX_NODES", "SegmentMesh"]


def lgl_nodes(n_nodes: int) -> np.ndarray:
    """LGL nodes on [-1, 1], increasing (Newton iteration from Chebyshev-Lobatto points)."""
    if n_nodes < 2:
        raise ScenarioError(f"LGL needs at least 2 nodes, got {n_nodes}")
    N = n_nodes - 1
    x = -np.cos(np.pi * np.arange(n_nodes) / N)
    for _ in range(100):
        P_N, P_Nm1 = legendre.legval(x, np.eye(N + 1)[N]), legendre.legval(x, np.eye(N + 1)[N - 1])
        dx = (x * P_N - P_Nm1) / (n_nodes * P_N)
        x = x - dx
        if np.max(np.abs(dx)) < 1e-15:
            break
    x[0], x[-1] = -1.0, 1.0
    return x


def barycentric_weights(nodes: np.ndarray) -> np.ndarray:
    """Barycentric weights 1 / prod_{k != j} (x_j - x_k), normalised."""
    diff = nodes[:, None] - nodes[None, :]
    np.fill_diagonal(diff, 1.0)
    w = 1.0 / np.prod(diff, axis=1)
    return w / np.max(np.abs(w))


def interpolation_matrix(nodes: np.ndarray, points, bary=None) -> np.ndarray:
    """Matrix P with P @ values = Lagrange interpolant at ``points`` (eq. 9), barycentric form."""
    bary = barycentric_weights(nodes) if bary is None else bary
    pts = np.atleast_1d(np.asarray(points, float))
    diff = pts[:, None] - nodes[None, :]
    exact = np.abs(diff) <= 1e-14 * max(1.0, np.max(np.abs(nodes)))
    diff[exact] = 1.0
    M = bary[None, :] / diff
    M /= M.sum(axis=1, keepdims=True)
    rows = exact.any(axis=1)
    M[rows] = exact[rows].astype(float)
    return M


@lru_cache(maxsize=32)
def _reference_operators(n_nodes: int):
    """(tau, weights_tau, D1_tau, D2_tau, barycentric weights) on [-1, 1]; computed once per
    node count (a re-plan builds new LGL objects many times a flight). Read-only arrays."""
    N = n_nodes - 1
    tau = lgl_nodes(n_nodes)
    P_N = legendre.legval(tau, np.eye(N + 1)[N])
    weights = 2.0 / (N * (N + 1) * P_N**2)
    D = P_N[:, None] / (P_N[None, :] * (tau[:, None] - tau[None, :] + np.eye(N + 1)))
    np.fill_diagonal(D, 0.0)
    D[0, 0] = -N * (N + 1) / 4.0
    D[N, N] = N * (N + 1) / 4.0
    out = (tau, weights, D, D @ D, barycentric_weights(tau))
    for a in out:
        a.flags.writeable = False
    return out


@dataclass
class LGL:
    """LGL operators for ``n_nodes`` nodes on the interval [a, b] (a > b allowed, e.g. energy
    decreasing along the flight).

    Attributes:
      tau, weights_tau, D1_tau, D2_tau: operators on [-1, 1].
      x: nodes on [a, b]; weights: quadrature weights on [a, b] (sum = b - a);
      D1, D2: derivative matrices with respect to x.
    """

    n_nodes: int
    a: float = -1.0
    b: float = 1.0
    tau: np.ndarray = field(init=False)

    def __post_init__(self):
        if self.a == self.b:
            raise ScenarioError("LGL interval must have a != b")
        self.tau, self.weights_tau, self.D1_tau, self.D2_tau, self.bary = _reference_operators(int(self.n_nodes))
        half = (self.b - self.a) / 2.0
        self.x = half * self.tau + (self.a + self.b) / 2.0  # eq. 12
        self.weights = half * self.weights_tau  # eq. 16
        self.D1 = self.D1_tau / half  # eq. 11
        self.D2 = self.D2_tau / half**2

    def to_tau(self, x):
        """Eq. 13: physical variable to [-1, 1]."""
        return (2.0 * np.asarray(x, float) - (self.a + self.b)) / (self.b - self.a)

    def interpolation(self, x) -> np.ndarray:
        """Matrix mapping nodal values to values at physical points x."""
        return interpolation_matrix(self.tau, self.to_tau(x), self.bary)

    def integrate(self, values) -> float:
        """Quadrature of nodal values over [a, b] (eq. 16)."""
        return float(self.weights @ np.asarray(values, float))


@lru_cache(maxsize=16)
def lobatto_integration_matrix(n_nodes: int) -> np.ndarray:
    """A with A[j-1, k] = integral from -1 to tau_j of the k-th Lagrange basis polynomial on
    the LGL nodes tau (j = 1..n-1): x(tau_j) - x(-1) = sum_k A[j-1, k] xdot(tau_k) for every
    polynomial x of degree <= n. Collocating with it is the Lobatto IIIA method of
    order 2n - 2 (n = 2: the trapezoid rule, n = 3: Simpson). Read-only."""
    tau = _reference_operators(int(n_nodes))[0]
    V = np.vander(tau, increasing=True)  # V @ c = nodal values of the monomial expansion
    C = np.linalg.solve(V, np.eye(n_nodes))  # column k: monomial coefficients of l_k
    powers = np.arange(1, n_nodes + 1)
    upper = tau[1:, None] ** powers[None, :] / powers[None, :]  # integral of tau^p from 0
    lower = (-1.0) ** powers / powers
    A = (upper - lower[None, :]) @ C
    A.flags.writeable = False
    return A


#: Lobatto integration matrices above this many nodes come from an ill-conditioned
#: Vandermonde solve (lobatto_integration_matrix); SegmentMesh.integration refuses them
INTEGRATION_MAX_NODES = 16
#: a segment's node count cap (the LGL nodes and differentiation matrix stay accurate far beyond)
SEGMENT_MAX_NODES = 400


def nodes_per_segment(nodes: int, segments: int, fields: tuple = ("nodes", "segments")) -> int:
    """LGL nodes of each of ``segments`` equal segments sharing their end nodes, for ``nodes``
    in all; ScenarioError naming the node counts allowed when they do not divide (the two
    counts called by their ``fields`` names, e.g. a scenario's 'guidance.nodes')."""
    n_name, s_name = fields
    if not (isinstance(segments, (int, np.integer)) and not isinstance(segments, bool) and segments >= 1):
        raise ScenarioError(f"{s_name} = {segments!r}; allowed: an integer >= 1 (LGL segments)")
    m, rest = divmod(nodes - 1, segments)
    if rest or m < 2:
        near = f"{2 * segments + 1}" if m < 2 else f"{segments * m + 1} or {segments * (m + 1) + 1}"
        raise ScenarioError(f"{n_name} = {nodes} with {s_name} = {segments}: {n_name} - 1 must be a multiple of "
                            f"{s_name} with at least 3 nodes per segment; allowed near it: {near}")
    return m + 1


def segment_compatible(nodes: int, segments: int) -> int:
    """The smallest node count >= ``nodes`` that ``segments`` segments of >= 3 nodes share."""
    m = max(2, -(-(int(nodes) - 1) // segments))
    return segments * m + 1


@dataclass
class SegmentMesh:
    """A mesh of ``n_segments`` equal segments of normalised time s in [0, 1], each with
    ``nodes_per_segment`` LGL nodes; neighbouring segments share their end node (the knots
    of Ross & Fahroo's pseudospectral knotting methods).

    Attributes:
      s: the n_nodes node positions in [0, 1]; n_nodes = n_segments (nodes_per_segment - 1) + 1.
      weights: quadrature weights on [0, 1] (sum 1; exact to degree 2 nodes_per_segment - 3).
      segment_nodes: (n_segments, nodes_per_segment) global node indices of each segment.
      length: a segment's length in s (1 / n_segments).
      differentiation, segment_weights: the LGL differentiation matrix and quadrature
        weights of one segment on its own [-1, 1] (d/ds = differentiation / (length / 2)).
      integration: the segment's Lobatto integration matrix scaled to the segment length
        (x_j - x_0 = sum_k integration[j-1, k] dx/ds(s_k); nodes_per_segment <= 16).
    """

    n_segments: int
    nodes_per_segment: int

    def __post_init__(self):
        if not (isinstance(self.n_segments, (int, np.integer)) and self.n_segments >= 1):
            raise ScenarioError(f"SegmentMesh.n_segments = {self.n_segments} must be an integer >= 1")
        if not 2 <= self.nodes_per_segment <= SEGMENT_MAX_NODES:
            raise ScenarioError(f"SegmentMesh.nodes_per_segment = {self.nodes_per_segment} must be in "
                                f"[2, {SEGMENT_MAX_NODES}]")
        m = int(self.nodes_per_segment)
        tau, w_tau, self.differentiation, _, self._bary = _reference_operators(m)
        self._tau, self.segment_weights = tau, w_tau
        h = self.length = 1.0 / self.n_segments
        starts = np.arange(self.n_segments) * h
        self.segment_nodes = np.arange(self.n_segments)[:, None] * (m - 1) + np.arange(m)[None, :]
        self.n_nodes = self.n_segments * (m - 1) + 1
        self.s = np.empty(self.n_nodes)
        self.weights = np.zeros(self.n_nodes)
        for k in range(self.n_segments):
            self.s[self.segment_nodes[k]] = starts[k] + 0.5 * h * (tau + 1.0)
            self.weights[self.segment_nodes[k]] += 0.5 * h * w_tau
        self.s[-1] = 1.0

    @cached_property
    def integration(self) -> np.ndarray:
        if self.nodes_per_segment > INTEGRATION_MAX_NODES:
            raise ScenarioError(f"SegmentMesh.integration: nodes_per_segment = {self.nodes_per_segment} must be in "
                                f"[2, {INTEGRATION_MAX_NODES}] (the Lobatto matrix's Vandermonde solve)")
        return 0.5 * self.length * lobatto_integration_matrix(int(self.nodes_per_segment))

    def interpolation(self, s) -> np.ndarray:
        """Matrix (len(s), n_nodes) mapping nodal values to the segment polynomials at s in [0, 1]."""
        s = np.clip(np.atleast_1d(np.asarray(s, float)), 0.0, 1.0)
        seg = np.minimum((s * self.n_segments).astype(int), self.n_segments - 1)
        out = np.zeros((s.size, self.n_nodes))
        h = 1.0 / self.n_segments
        for k in np.unique(seg):
            rows = np.flatnonzero(seg == k)
            t = 2.0 * (s[rows] - k * h) / h - 1.0
            out[np.ix_(rows, self.segment_nodes[k])] = interpolation_matrix(self._tau, t, self._bary)
        return out
