"""Bank-angle actuator law shared by the Drake BankActuator and the scipy cross-check."""
from __future__ import annotations

import math


def _clip(v: float, lim: float) -> float:
    return -lim if v < -lim else (lim if v > lim else v)


def bank_actuator_rates(sigma: float, rate: float, command: float, *, bank_limit: float, rate_limit: float,
                        accel_limit: float, bandwidth: float) -> tuple[float, float]:
    """(sigma_dot, sigma_ddot) of the rate- and acceleration-limited bank actuator.

    e = clip(cmd, +-bank_limit) - sigma;
    sigma_dot_des = sign(e) min(omega |e|, rate_limit, sqrt(accel_limit |e|)) (the last term
    is a braking curve planned at half the acceleration limit, so the lagging rate loop
    can still stop at the command and does not overshoot it or the bank limit);
    sigma_ddot = clip(4 omega (sigma_dot_des - sigma_dot),
    +-accel_limit). SI units.
    """
    e = _clip(command, bank_limit) - sigma
    mag = min(bandwidth * abs(e), rate_limit, math.sqrt(accel_limit * abs(e)))
    rate_des = mag if e >= 0 else -mag
    return rate, _clip(4.0 * bandwidth * (rate_des - rate), accel_limit)
