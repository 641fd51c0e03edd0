"""Bank-angle actuator law shared by the Drake BankActuator and the scipy cross-check."""
from __future__ import annotations

import math


def _clip(v: float, lim: float) -> float:
    return -lim if v < -lim else (lim if v > lim else v)


def _accel(e: float, rate: float, omega: float, rate_limit: float, accel_limit: float) -> float:
    """sigma_ddot for the position error e = clipped command - sigma (see bank_actuator_rates)."""
    ae = e if e >= 0.0 else -e
    mag = omega * ae
    if mag > rate_limit:
        mag = rate_limit
    brake = math.sqrt(accel_limit * ae)
    if brake < mag:
        mag = brake
    acc = 4.0 * omega * ((mag if e >= 0.0 else -mag) - rate)
    return -accel_limit if acc < -accel_limit else (accel_limit if acc > accel_limit else acc)


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
    return rate, _accel(_clip(command, bank_limit) - sigma, rate, bandwidth, rate_limit, accel_limit)


def integrate_bank_actuator(sigma: float, rate: float, command: float, step: float, steps: int, *,
                            bank_limit: float, rate_limit: float, accel_limit: float,
                            bandwidth: float) -> tuple[list, list]:
    """(sigma, sigma_dot) after 0..steps midpoint-RK2 steps of ``step`` seconds of
    bank_actuator_rates under a constant command: lists of steps + 1 values [rad, rad/s].

    A settled actuator (at the command, at rest) stays put without integrating."""
    c = _clip(command, bank_limit)
    if sigma == c and rate == 0.0:
        return [sigma] * (steps + 1), [0.0] * (steps + 1)
    s_out, r_out = [sigma], [rate]
    s, r, hh = sigma, rate, 0.5 * step
    for _ in range(steps):
        a1 = _accel(c - s, r, bandwidth, rate_limit, accel_limit)
        r_mid = r + hh * a1
        a2 = _accel(c - (s + hh * r), r_mid, bandwidth, rate_limit, accel_limit)
        s += step * r_mid
        r += step * a2
        s_out.append(s)
        r_out.append(r)
    return s_out, r_out
