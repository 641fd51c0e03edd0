"""FNPEG's corrector (Lu 2014 Sec. III.B): sigma_0 that zeroes the predicted range error
z(sigma_0) = s_to_go - s_flown(sigma_0) - s_f* [m], by minimising f = z^2/2 with a damped
secant (Newton) iteration: sigma_0 <- sigma_0 - lambda z / z', lambda = 2^-i the first that
lowers f, z' by a first difference at the first iteration of a flight and by the secant after
(carried over from cycle to cycle). sigma_0 is kept in [0, 90 deg] deliberately (a step that
leaves it is clipped; the magnitude is what the profile flies). It stops when |z| is within the
tolerance, when |z z'| (the gradient of f) is small (the minimum of f when no root exists:
the energy is short), when no halving lowers f (a minimum on a bound), or at the iteration cap.
"""
from __future__ import annotations

import dataclasses as dc
import math

__all__ = ["SIGMA0_BOUNDS", "CorrectorSettings", "Correction", "correct"]

SIGMA0_BOUNDS = (0.0, math.radians(90.0))


@dc.dataclass(frozen=True)
class CorrectorSettings:
    """tolerance [m]; max_iterations; max_halvings; first_difference [rad]; gradient_tolerance
    [m^2/rad]: the |z z'| stop (default: tolerance^2 / 1 deg, a root within tolerance of a
    1-deg move)."""

    tolerance: float = 100.0
    max_iterations: int = 15
    max_halvings: int = 10
    first_difference: float = math.radians(1.0)

    @property
    def gradient_tolerance(self) -> float:
        return self.tolerance * self.tolerance / math.radians(1.0)


@dc.dataclass(frozen=True)
class Correction:
    """sigma0 [rad]; z [m] there; slope dz/dsigma_0 [m/rad] (the secant to carry over);
    predictions made; converged (|z| within tolerance); why it stopped."""

    sigma0: float
    z: float
    slope: float
    predictions: int
    converged: bool
    stop: str


def _clip(s: float) -> float:
    return min(max(s, SIGMA0_BOUNDS[0]), SIGMA0_BOUNDS[1])


def correct(z_of, sigma0: float, settings: CorrectorSettings, slope: float | None = None) -> Correction:
    """Correct ``sigma0`` [rad] with ``z_of(sigma0) -> z [m]`` (a prediction); ``slope``: a
    dz/dsigma_0 [m/rad] to start from (None: a first difference)."""
    s = settings
    sigma0 = _clip(sigma0)
    z = z_of(sigma0)
    n = 1
    for _ in range(s.max_iterations):
        if not math.isfinite(z):
            return Correction(sigma0, z, math.nan if slope is None else slope, n, False, "the prediction failed")
        if abs(z) <= s.tolerance:
            return Correction(sigma0, z, math.nan if slope is None else slope, n, True, "converged")
        if slope is None or not math.isfinite(slope) or slope == 0.0:
            d = s.first_difference if sigma0 + s.first_difference <= SIGMA0_BOUNDS[1] else -s.first_difference
            zd = z_of(sigma0 + d)
            n += 1
            slope = (zd - z) / d
            if not math.isfinite(slope) or slope == 0.0:
                return Correction(sigma0, z, slope, n, False, "z does not change with sigma_0")
        if abs(z * slope) <= s.gradient_tolerance:
            return Correction(sigma0, z, slope, n, False, "minimum of z^2 (no root)")
        step, lam = -z / slope, 1.0
        for _ in range(s.max_halvings + 1):
            trial = _clip(sigma0 + lam * step)
            if trial == sigma0:
                return Correction(sigma0, z, slope, n, False, "on the sigma_0 bound")
            zt = z_of(trial)
            n += 1
            if math.isfinite(zt) and zt * zt < z * z:
                break
            lam *= 0.5
        else:
            return Correction(sigma0, z, slope, n, False, "no halving lowers z^2 (a minimum)")
        slope = (zt - z) / (trial - sigma0)
        sigma0, z = trial, zt
    return Correction(sigma0, z, slope, n, abs(z) <= s.tolerance,
                      "converged" if abs(z) <= s.tolerance else f"{s.max_iterations} iterations")
