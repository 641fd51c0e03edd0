"""Lu (2014)'s path-limit feedback, shared by the bank laws that fly it (FNPEG, paper 004's law):
the smallest flight-path angle that keeps the aerodynamic load, the heat rate and the dynamic
pressure under their limits a horizon ahead, and the altitude-rate correction of the vertical
lift towards it (Lu 2014 Sec. IV). Written once for float, numpy-array and symbolic scalars (the
compiled predictors trace it).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.symbolic import max as symbolic_max

from drake_entry.models.scalar import is_symbolic

__all__ = ["HEAT_RATE_VELOCITY_EXPONENT", "PathLimits", "enforced", "path_limit_sin_flight_path", "path_limit_correction",
           "corrected_cos_bank"]

#: exponent of V in the heat-rate law the path-limit reference assumes (Lu 2014: 3.15)
HEAT_RATE_VELOCITY_EXPONENT = 3.15


@dc.dataclass(frozen=True)
class PathLimits:
    """What the feedback enforces.

    Attributes:
      R0 [m], g0 [m/s^2]: Lu's length and acceleration units (the gain is nondimensional).
      beta: R0 / H, the nondimensional inverse density scale height (about 900 for Earth).
      gain: k of the feedback (Lu 2014: 40; 0 = off).
      horizon: delta [s] of the prediction (Lu 2014: 0.02 nondimensional, about 16 s).
      load_max [m/s^2] (total aerodynamic acceleration), heat_max [W/m^2], q_max [Pa]: the
        limits enforced (inf = not enforced).
    """

    R0: float
    g0: float
    beta: float = 900.0
    gain: float = 40.0
    horizon: float = 16.0
    load_max: float = math.inf
    heat_max: float = math.inf
    q_max: float = math.inf

    @classmethod
    def of_vehicle(cls, limits, planet, *, gain: float, horizon: float, fraction: float,
                   beta: float = 900.0) -> "PathLimits":
        """The feedback holding ``fraction`` of a vehicle's ``limits`` (models.vehicles.PathLimits:
        its load bound [g], heat rate, q; inf where it has none) on ``planet`` (reference_radius,
        g0), with ``gain`` and ``horizon`` [s]."""
        return cls(planet.reference_radius, planet.g0, beta=beta, gain=gain, horizon=horizon,
                   load_max=fraction * limits.load_bound_max * planet.g0, heat_max=fraction * limits.heat_flux_max,
                   q_max=fraction * limits.dynamic_pressure_max)

    @property
    def active(self) -> bool:
        """A gain and at least one limit enforced."""
        return self.gain > 0.0 and any(enforced(x) for x in (self.load_max, self.heat_max, self.q_max))


def enforced(limit) -> bool:
    """A limit is enforced when finite; a symbolic one (a compiled kernel's input) always is."""
    return is_symbolic(limit) or math.isfinite(limit)


def _max(a, b):
    if is_symbolic(a) or is_symbolic(b):
        return symbolic_max(a, b)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.maximum(a, b)
    return max(a, b)


def path_limit_sin_flight_path(V, D, load, heat, q, s: PathLimits):
    """max{U_a, U_Q, U_q}: the smallest sin(gamma) that keeps the aerodynamic acceleration
    ``load`` [m/s^2], the heat rate ``heat`` [W/m^2] and the dynamic pressure ``q`` [Pa] under
    their limits ``horizon`` seconds ahead, at speed V [m/s] and drag D [m/s^2]. With
    rho'/rho = -beta/R0 and dV/dt = -D:
    a(t + delta) = a [1 + (-beta V sin(gamma)/R0 - 2D/V) delta] <= a_max gives
    U_a = [a_max - a (1 - 2 D delta / V)] / (-a beta V delta / R0); the heat rate (sqrt(rho) V^3.15)
    gives U_Q with 0.5 beta and 3.15 D. A limit that is inf contributes -1 (no bound)."""
    d = s.horizon
    k = s.beta * V * d / s.R0
    bounds = []
    if enforced(s.load_max):
        bounds.append((s.load_max - load * (1.0 - 2.0 * D * d / V)) / (-load * k))
    if enforced(s.q_max):
        bounds.append((s.q_max - q * (1.0 - 2.0 * D * d / V)) / (-q * k))
    if enforced(s.heat_max):
        n = HEAT_RATE_VELOCITY_EXPONENT
        bounds.append((s.heat_max - heat * (1.0 - n * D * d / V)) / (-0.5 * heat * k))
    out = -1.0
    for b in bounds:
        out = _max(out, b)
    return out


def path_limit_correction(V, sin_gamma, D, load, heat, q, s: PathLimits):
    """The feedback's term k V (sin(gamma) - max{sin(gamma), U}) [m/s], <= 0 (it only lifts):
    the law then flies ``corrected_cos_bank``."""
    limit = path_limit_sin_flight_path(V, D, load, heat, q, s)
    return s.gain * V * (sin_gamma - _max(sin_gamma, limit))


def corrected_cos_bank(cos_sigma, correction, lift, R0: float, g0: float):
    """cos(sigma) - correction sqrt(g0/R0) / L: a correction of the vertical lift given in Lu
    2014's nondimensional form (an altitude-rate term [m/s], ``path_limit_correction``'s or
    FNPEG's damping) applied to the bank's cosine in SI, L the lift [m/s^2], R0 [m] and g0
    [m/s^2] Lu's units. Any scalar type; the caller clamps and takes the arc cosine."""
    return cos_sigma - correction * math.sqrt(g0 / R0) / lift
