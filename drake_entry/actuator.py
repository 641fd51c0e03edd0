"""Bank-angle actuator law shared by the Drake BankActuator and the scipy cross-check."""
from __future__ import annotations


def _clip(v: float, lim: float) -> float:
    return -lim if v < -lim else (lim if v > lim else v)


def bank_actuator_rates(sigma: float, rate: float, command: float, *, bank_limit: float, rate_limit: float,
                        accel_limit: float, bandwidth: float) -> tuple[float, float]:
    """(sigma_dot, sigma_ddot) of the rate- and acceleration-limited bank actuator.

    sigma_dot_des = clip(omega (clip(cmd, +-bank_limit) - sigma), +-rate_limit),
    sigma_ddot = clip(4 omega (sigma_dot_des - sigma_dot), +-accel_limit). SI units.
    """
    cmd = _clip(command, bank_limit)
    rate_des = _clip(bandwidth * (cmd - sigma), rate_limit)
    return rate, _clip(4.0 * bandwidth * (rate_des - rate), accel_limit)
