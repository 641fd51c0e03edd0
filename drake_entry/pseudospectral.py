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
from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre

from .errors import ScenarioError


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
