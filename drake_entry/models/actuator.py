"""Second-order actuator law with position, rate and acceleration limits, shared by the Drake
bank and angle-of-attack actuators (systems/actuators.py) and the scipy cross-check."""
from __future__ import annotations

import functools
import math

import numpy as np
from numba.extending import register_jitable

__all__ = ["BANDWIDTH_RAD_S", "SUBSTEP_S", "FEW_LIMITED", "actuator_rates", "integrate_actuator",
           "integrate_actuators", "actuator_path"]

#: the position loop's bandwidth omega [rad/s] of the closed loop's actuators (systems/actuators.py)
BANDWIDTH_RAD_S = 2.0
#: the sampled actuators' integration sub-step [s]
SUBSTEP_S = 0.02
#: up to this many rate- or acceleration-limited members, ``integrate_actuators`` steps them one by
#: one on floats (faster than NumPy's per-call cost on a few elements; the same numbers)
FEW_LIMITED = 4


@register_jitable  # plain Python when called from Python; compiled inline into numba kernels
def _clip(v: float, lower: float, upper: float) -> float:
    return lower if v < lower else (upper if v > upper else v)


@register_jitable
def _accel(e: float, rate: float, omega: float, rate_limit: float, accel_limit: float) -> float:
    """x_ddot for the position error e = clipped command - x (see actuator_rates)."""
    ae = e if e >= 0.0 else -e
    mag = omega * ae
    if mag > rate_limit:
        mag = rate_limit
    brake = math.sqrt(accel_limit * ae)
    if brake < mag:
        mag = brake
    acc = 4.0 * omega * ((mag if e >= 0.0 else -mag) - rate)
    return -accel_limit if acc < -accel_limit else (accel_limit if acc > accel_limit else acc)


def actuator_rates(x: float, rate: float, command: float, *, lower: float, upper: float, rate_limit: float,
                   accel_limit: float, bandwidth: float) -> tuple[float, float]:
    """(x_dot, x_ddot) of the rate- and acceleration-limited actuator (bank: x = sigma with
    bounds +-bank_limit; angle of attack: x = alpha in [alpha_min, alpha_max]).

    e = clip(cmd, lower, upper) - x;
    x_dot_des = sign(e) min(omega |e|, rate_limit, sqrt(accel_limit |e|)) (the last term
    is a braking curve planned at half the acceleration limit, so the lagging rate loop
    can still stop at the command and does not overshoot it or the position limit);
    x_ddot = clip(4 omega (x_dot_des - x_dot), +-accel_limit). SI units.
    """
    return rate, _accel(_clip(command, lower, upper) - x, rate, bandwidth, rate_limit, accel_limit)


def integrate_actuator(sigma: float, rate: float, command: float, step: float, steps: int, *,
                       lower: float, upper: float, rate_limit: float, accel_limit: float,
                       bandwidth: float) -> tuple[list, list]:
    """(x, x_dot) at 0, step, ..., steps * step seconds of actuator_rates under
    a constant command: lists of steps + 1 values [rad, rad/s].

    Where no limit is active over the whole interval the law is linear,
    x'' = -4 omega x' - 4 omega^2 x with x = sigma - command (critically damped, double root
    -2 omega), and the exact solution x = (x0 + (v0 + 2 omega x0) t) exp(-2 omega t) is used;
    otherwise midpoint-RK2 steps of ``step`` seconds."""
    c = _clip(command, lower, upper)
    if sigma == c and rate == 0.0:  # settled
        return [sigma] * (steps + 1), [0.0] * (steps + 1)
    w = bandwidth
    t = np.arange(steps + 1) * step
    x0 = sigma - c
    B = rate + 2.0 * w * x0
    decay = np.exp(-2.0 * w * t)
    x = (x0 + B * t) * decay
    v = (rate - 2.0 * w * B * t) * decay
    linear = (np.abs(x).max() <= min(rate_limit / w, accel_limit / (w * w))
              and np.abs(4.0 * w * (w * x + v)).max() <= accel_limit)
    if linear:
        return (x + c).tolist(), v.tolist()
    return _limited_path(sigma, rate, c, step, steps, w, rate_limit, accel_limit)


def _limited_path(sigma: float, rate: float, c: float, step: float, steps: int, omega: float,
                  rate_limit: float, accel_limit: float) -> tuple[list, list]:
    """(x, x_dot) lists at 0, step, ..., steps * step of midpoint-RK2 steps of ``_accel``
    towards the clipped command ``c`` (Python floats: for one member this is several times
    faster than the same steps on NumPy arrays)."""
    s_out, r_out = [0.0] * (steps + 1), [0.0] * (steps + 1)
    _limited_steps(sigma, rate, c, step, steps, omega, rate_limit, accel_limit, s_out, r_out)
    return s_out, r_out


@register_jitable
def _limited_steps(sigma: float, rate: float, c: float, step: float, steps: int, omega: float, rate_limit: float,
                   accel_limit: float, positions, rates) -> None:
    """The midpoint-RK2 steps of ``_accel`` towards ``c``: positions and rates at 0, step, ...,
    steps * step written into ``positions`` and ``rates`` (lists in Python, arrays when compiled)."""
    s, r, hh = sigma, rate, 0.5 * step
    positions[0], rates[0] = s, r
    for k in range(steps):
        a1 = _accel(c - s, r, omega, rate_limit, accel_limit)
        r_mid = r + hh * a1
        a2 = _accel(c - (s + hh * r), r_mid, omega, rate_limit, accel_limit)
        s += step * r_mid
        r += step * a2
        positions[k + 1], rates[k + 1] = s, r


@register_jitable
def actuator_path(sigma: float, rate: float, command: float, step: float, steps: int, lower: float, upper: float,
                  rate_limit: float, accel_limit: float, bandwidth: float, positions, rates) -> None:
    """``integrate_actuator`` written for compiled code (numba; models.kernels drivers): the
    positions and rates at 0, step, ..., steps * step into the arrays ``positions`` and ``rates``
    (at least steps + 1 long): the same exact solution where no limit is active, the same
    midpoint-RK2 steps of ``_accel`` where one is (tests hold the two equal)."""
    c = _clip(command, lower, upper)
    w = bandwidth
    x0 = sigma - c
    B = rate + 2.0 * w * x0
    bound = min(rate_limit / w, accel_limit / (w * w))
    linear = True
    for k in range(steps + 1):
        t = k * step
        decay = math.exp(-2.0 * w * t)
        x = (x0 + B * t) * decay
        v = (rate - 2.0 * w * B * t) * decay
        positions[k], rates[k] = x + c, v
        if abs(x) > bound or abs(4.0 * w * (w * x + v)) > accel_limit:
            linear = False
    if not linear:
        _limited_steps(sigma, rate, c, step, steps, w, rate_limit, accel_limit, positions, rates)


def integrate_actuators(x, rate, command, step: float, steps: int, *, lower, upper, rate_limit,
                        accel_limit, bandwidth: float):
    """(x, x_dot) arrays after ``steps`` steps of ``step`` seconds under constant commands, and
    the positions at every step (steps + 1, n) for interpolation: ``integrate_actuator`` for a
    population (the same exact solution where no limit is active over the interval, the same
    midpoint-RK2 steps for the members where one is; tests hold the two equal). The limits
    may be scalars or per-member arrays, so actuators of different limits (bank and alpha)
    integrate in one call."""
    x, rate = np.array(x, float), np.array(rate, float)
    c = np.minimum(np.maximum(np.broadcast_to(command, x.shape), lower), upper)
    per_member = bool(np.ndim(rate_limit) or np.ndim(accel_limit))
    if per_member:
        rate_limit, accel_limit = np.broadcast_to(rate_limit, x.shape), np.broadcast_to(accel_limit, x.shape)
    w = bandwidth
    t, decay = _time_grid(step, steps, w)
    x0 = x - c
    B = rate + 2.0 * w * x0
    dev = (x0 + B * t) * decay
    vel = (rate - 2.0 * w * B * t) * decay
    linear = ((np.abs(dev).max(axis=0) <= np.minimum(rate_limit / w, accel_limit / (w * w)))
              & (np.abs(4.0 * w * (w * dev + vel)).max(axis=0) <= accel_limit))
    positions, rates = dev + c, vel
    limited = np.flatnonzero(~linear)
    if limited.size > FEW_LIMITED:
        s, r, cl, hh = x[limited], rate[limited], c[limited], 0.5 * step
        rl, al = (rate_limit[limited], accel_limit[limited]) if per_member else (rate_limit, accel_limit)
        path_s, path_r = [s], [r]
        for _ in range(steps):
            a1 = _accelerations(cl - s, r, w, rl, al)
            r_mid = r + hh * a1
            a2 = _accelerations(cl - (s + hh * r), r_mid, w, rl, al)
            s = s + step * r_mid
            r = r + step * a2
            path_s.append(s)
            path_r.append(r)
        positions[:, limited], rates[:, limited] = path_s, path_r
    else:  # a few members: the same steps on floats, member by member
        for i in limited:
            rl, al = (rate_limit[i], accel_limit[i]) if per_member else (rate_limit, accel_limit)
            positions[:, i], rates[:, i] = _limited_path(float(x[i]), float(rate[i]), float(c[i]), step, steps, w,
                                                         float(rl), float(al))
    return positions[-1].copy(), rates[-1].copy(), positions


@functools.lru_cache(maxsize=16)
def _time_grid(step: float, steps: int, omega: float):
    """Times (steps + 1, 1) [s] and the exact solution's decay exp(-2 omega t) on them."""
    t = (np.arange(steps + 1) * step)[:, None]
    t.flags.writeable = False
    decay = np.exp(-2.0 * omega * t)
    decay.flags.writeable = False
    return t, decay


def _accelerations(e, rate, omega: float, rate_limit: float, accel_limit: float):
    """``_accel`` for arrays of position errors e = clipped command - x (limits: scalars or
    arrays like e)."""
    ae = np.abs(e)
    mag = np.minimum(np.minimum(omega * ae, rate_limit), np.sqrt(accel_limit * ae))
    acc = 4.0 * omega * (np.copysign(mag, e) - rate)
    return np.minimum(np.maximum(acc, -accel_limit), accel_limit)
