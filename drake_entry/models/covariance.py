"""A 6 x 6 covariance given in a scenario file: its checks (one line naming the field) and its
square root, to draw correlated Gaussian deviations from standard normal draws. Shared by the
entry delivery covariance (models.dispersions) and the INS entry errors
(models.inertial_navigation)."""
from __future__ import annotations

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["check_covariance", "covariance_root"]


def check_covariance(c, where: str, axes: str) -> None:
    """6 rows of 6 finite values, symmetric, positive semi-definite; ``axes`` names the rows and
    their units in the message (e.g. '[altitude m, longitude deg, ...]')."""
    if not (len(c) == 6 and all(len(row) == 6 for row in c)):
        raise ScenarioError(f"{where} needs 6 rows of 6 values {axes}")
    m = np.asarray(c, float)
    if not np.all(np.isfinite(m)):
        raise ScenarioError(f"{where} has a value that is not finite")
    if not np.allclose(m, m.T, rtol=1e-9, atol=0.0):
        i, j = np.unravel_index(np.argmax(np.abs(m - m.T)), m.shape)
        raise ScenarioError(f"{where} is not symmetric: [{i}][{j}] = {m[i, j]:g} but [{j}][{i}] = {m[j, i]:g}")
    lowest = float(np.linalg.eigvalsh(m).min())
    if lowest < -1e-9 * max(1.0, float(np.abs(m).max())):
        raise ScenarioError(f"{where} is not positive semi-definite (its smallest eigenvalue is {lowest:g}); a "
                            f"covariance needs variances >= 0 and correlations in [-1, 1]")


def covariance_root(covariance) -> np.ndarray:
    """L with L L^T = covariance (symmetric positive semi-definite; eigen-decomposition, so a
    singular covariance, e.g. one correlated pair, is fine)."""
    values, vectors = np.linalg.eigh(np.asarray(covariance, float))
    return vectors * np.sqrt(np.clip(values, 0.0, None))
