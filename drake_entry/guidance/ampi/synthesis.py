"""On-line synthesis from the database (paper 003 Sec. IV.C-D): subspace selection
(Algorithm 1), tensor-product interpolation (Algorithm 2), and the nearest database entry
for neighbour-trajectory tracking (NTT, the paper's comparison).

Algorithm 1 as printed has typos (docs/methods/ampi.md): U_1 needs n_i entries
(not d), its loops disagree, and a value on a grid point gives sign 0. Fixed here: in each
dimension the enclosing interval is [j, j + 1] with j the last level <= x (the first
interval for x below the grid, the last for x above it: then the interpolation
extrapolates linearly and the dimension is flagged).

Algorithm 2 with order-2 B-splines and knots (p_j, p_j, p_j+1, p_j+1) is multilinear
interpolation: the 2^d corners are collapsed one dimension at a time (the paper's cyclic
rotation A' of the coefficient array is the move to the next axis).
"""
from __future__ import annotations

import numpy as np

__all__ = ["select_subspace", "interpolate_corners", "interpolate", "nearest_case"]

#: how a reference is made from the database: AMPI (Algorithms 1-2) or the nearest entry (NTT)


def select_subspace(levels, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Algorithm 1 (fixed): for query offsets ``x`` (d,) and the grid ``levels`` (d sequences),
    (lower level index per dimension (d,), fraction within the interval (d,), extrapolated
    flag (d,)); fractions outside [0, 1] extrapolate."""
    x = np.asarray(x, float)
    lower = np.empty(len(levels), int)
    frac = np.empty(len(levels))
    outside = np.zeros(len(levels), bool)
    for d, lv in enumerate(levels):
        lv = np.asarray(lv, float)
        j = int(np.clip(np.searchsorted(lv, x[d], side="right") - 1, 0, lv.size - 2))
        lower[d] = j
        frac[d] = (x[d] - lv[j]) / (lv[j + 1] - lv[j])
        outside[d] = x[d] < lv[0] or x[d] > lv[-1]
    return lower, frac, outside


def interpolate_corners(corners: np.ndarray, frac) -> np.ndarray:
    """Algorithm 2: multilinear interpolation of the 2^d corner values ``corners`` (shape
    (2,) * d + value shape) at the fractions ``frac`` (d,), one dimension at a time."""
    a = corners
    for w in frac:
        a = (1.0 - w) * a[0] + w * a[1]
    return a


def interpolate(values: np.ndarray, levels, x) -> tuple[np.ndarray, np.ndarray]:
    """Algorithms 1-2 on a tensor grid: ``values`` (grid shape + value shape) at offsets ``x``;
    returns (value, extrapolated flags (d,))."""
    lower, frac, outside = select_subspace(levels, x)
    corners = values[tuple(slice(j, j + 2) for j in lower)]
    return interpolate_corners(corners, frac), outside


def nearest_case(levels, x) -> tuple[int, ...]:
    """NTT: the multi-index of the database entry nearest to offsets ``x`` in grid steps
    (each dimension's distance divided by its local level spacing; the levels are a tensor
    grid, so the nearest level of each dimension)."""
    out = []
    for d, lv in enumerate(levels):
        lv = np.asarray(lv, float)
        spacing = np.gradient(lv) if lv.size > 1 else np.ones(1)
        out.append(int(np.argmin(np.abs(x[d] - lv) / np.abs(spacing))))
    return tuple(out)
