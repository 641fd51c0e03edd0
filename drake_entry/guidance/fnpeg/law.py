"""FNPEG's bank-magnitude law (Lu 2014), written once for float and symbolic scalars: the
predictor (guidance/fnpeg/predictor.py) builds it into a native Drake system, the on-board
guidance (systems/fnpeg_guidance.py) evaluates it on the navigated state.

- The baseline profile (``models.schedules.linear_bank``, shared with paper 004): |sigma| linear
  in the energy-like variable e = mu/r - V^2/2 (SI; e increases along the flight), from sigma_0
  (solved) at the current e_0 to sigma_f (fixed) at the terminal e_f.
- The altitude-rate feedback augmentation (Lu 2014 Sec. IV): L cos(sigma_cmd) = L cos(sigma_base)
  - k (hdot - hdot_ref), in Lu's nondimensional units (length R0, speed sqrt(g0 R0)), converted
  here to SI: cos(sigma_cmd) = cos(sigma_base) - k sqrt(g0/R0) (hdot - hdot_ref) / L.
  Two references:
  * phugoid damping: hdot_ref = V sin(gamma_QEGC), sin(gamma_QEGC) = -2 / (beta V^2 cos(sigma_QEGC)
    (L/D)) with V in sqrt(g0 R0) and beta = R0 / H the nondimensional inverse scale height
    (the quasi-equilibrium glide's descent rate; Lu writes beta_r = rho'/rho = -beta), gain k_0
    above V_off + ramp, ramped linearly to 0 at V_off;
  * path limits: sin(gamma_ref) = max{sin gamma, U_a, U_Q, U_q}, the smallest flight-path angle
    that keeps the load, heat rate and dynamic pressure under their limits ``delta`` seconds
    ahead (a first-order prediction in an exponential atmosphere), gain k_path; shared with
    paper 004's law (guidance.path_feedback).
  The two corrections add (this library's reading where both are active).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.guidance.path_feedback import PathLimits, corrected_cos_bank, path_limit_correction
from drake_entry.models.scalar import clamp

__all__ = ["FeedbackSettings", "qegc_sin_flight_path", "commanded_bank"]


@dc.dataclass(frozen=True)
class FeedbackSettings:
    """The altitude-rate feedback's constants (SI but the gains, which are Lu's nondimensional).

    Attributes:
      R0, g0: Lu's length [m] and acceleration [m/s^2] units.
      beta: R0 / H, the nondimensional inverse density scale height (about 900 for Earth).
      damping_gain: k_0 of the phugoid damping (Lu 2014: 20; 0 = off).
      damping_bank: sigma_QEGC [rad] (Lu 2014: 60 deg).
      damping_off_speed: V_off [m/s] where the damping gain reaches 0; ramp: the speed band [m/s]
        over which it ramps from k_0 (Lu 2014: off at V_f* + 1000 m/s).
      path: the path-limit feedback (guidance.path_feedback.PathLimits: gain k, Lu 2014's 40,
        horizon delta, about 16 s, and the limits enforced); None = off.
      bank_limit: the largest |sigma_cmd| [rad].
    """

    R0: float
    g0: float
    beta: float = 900.0
    damping_gain: float = 20.0
    damping_bank: float = math.radians(60.0)
    damping_off_speed: float = 3000.0
    ramp: float = 1000.0
    path: PathLimits | None = None
    bank_limit: float = math.radians(90.0)


def _ramp(v, lo: float, width: float):
    """0 below lo, 1 above lo + width, linear between (any scalar type)."""
    return clamp((v - lo) / width, 0.0, 1.0)


def qegc_sin_flight_path(V, lift_to_drag, s: FeedbackSettings):
    """sin(gamma_QEGC): the quasi-equilibrium glide's flight-path angle at speed V [m/s] and
    bank sigma_QEGC, in an exponential atmosphere of inverse scale height beta / R0."""
    v2 = V * V / (s.g0 * s.R0)
    return -2.0 / (s.beta * v2 * math.cos(s.damping_bank) * lift_to_drag)


def commanded_bank(sigma_base, V, gamma, L, D, load, heat, q, s: FeedbackSettings):
    """|sigma_cmd| [rad] in [0, bank_limit]: the baseline magnitude with the altitude-rate
    feedback (module docstring), at speed V [m/s], flight-path angle gamma [rad], lift and drag
    accelerations L, D [m/s^2], aerodynamic acceleration ``load`` [m/s^2], heat rate [W/m^2]
    and q [Pa]. Any scalar type (float or symbolic)."""
    sg = np.sin(gamma)
    hdot = V * sg
    correction = 0.0
    if s.damping_gain > 0.0:
        k = s.damping_gain * _ramp(V, s.damping_off_speed, s.ramp)
        correction = correction + k * (hdot - V * qegc_sin_flight_path(V, L / D, s))
    if s.path is not None and s.path.active:
        correction = correction + path_limit_correction(V, sg, D, load, heat, q, s.path)  # <= 0: only lifts
    c = corrected_cos_bank(np.cos(sigma_base), correction, L, s.R0, s.g0)
    return np.arccos(clamp(c, math.cos(s.bank_limit), 1.0))
