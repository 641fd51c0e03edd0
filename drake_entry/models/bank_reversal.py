"""Bank-reversal logic (paper 000 Sec. VI.D; Harpold & Graves 1979), shared by the Drake
BankReversalLogic system and population evaluators: the heading error to the target, a
corridor half-width linear in speed, and the sign that turns back when the error leaves it
(positive bank turns right, i.e. increases the heading). Floats or numpy arrays alike, and
compiled code (numba: each function is also compiled inline where a kernel driver calls it)."""
from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

__all__ = ["wrap_angle", "corridor_half_width", "reversal_sign"]


@register_jitable
def wrap_angle(a):
    """a wrapped to [-pi, pi) [rad]."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@register_jitable
def corridor_half_width(V, heading_rad, velocity_m_s):
    """Heading-error corridor half-width [rad] at speed V [m/s]: linear between the two
    (velocity, half-width) points, held outside."""
    return np.interp(V, velocity_m_s, heading_rad)


@register_jitable
def reversal_sign(heading_error, half_width, sign):
    """The bank sign after this update: -1 when the error is beyond +half_width, +1 beyond
    -half_width, else unchanged (sign is +-1)."""
    return sign + (heading_error < -half_width) * (1.0 - sign) - (heading_error > half_width) * (1.0 + sign)
