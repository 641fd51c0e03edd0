"""FNPEG's whole predicted flight as one compiled call: the driver of the compiled predictor.

These functions are not called from Python as written: ``Predictor`` compiles them with numba
together with two kernels generated from the model expressions (models.kernels), which they
call by name:

  ``rhs(v, out)``           out[0:7] = d/dt [h, lon, lat, V, gamma, psi, s] at v (14: the 7
                            states, then sigma_0, e_0, sign, k_L, k_D, sigma_f, e_f)
  ``energy(v, out)``        out[0] = e = mu/r - V^2/2 [J/kg]
  ``energy_rate(v, out)``   out[0] = e, out[1] = de/dt (the right-hand side's h and V rates)

So the driver holds no physics: only Drake's fixed-step Runge-Kutta 3 (the native predictor's
integrator: k1 at t, k2 at t + h/2 from y + h/2 k1, k3 at t + h from y - h k1 + 2 h k2,
y + h/6 (k1 + 4 k2 + k3)) and the stops of ``Predictor`` (the energy checked every
``steps_per_check`` steps, as the native predictor's Simulator calls do; the step that
crosses e_f found again and Newton on time to e_f).
"""
# ruff: noqa: F821  (rhs, energy and energy_rate are the generated kernels of the compiled module)
import math

import numpy as np

__all__ = ["REACHED", "FLOOR", "CEILING", "TIMEOUT", "NOT_FINITE", "rk3_step", "predict_flight"]

#: how a predicted flight stopped (predict_flight's first result)
REACHED, FLOOR, CEILING, TIMEOUT, NOT_FINITE = 0, 1, 2, 3, 4
_N = 7  # integrated states: h, lon, lat, V, gamma, psi, s


def rk3_step(v, h, out, k1, k2, k3, work):
    """One Runge-Kutta 3 step of size h [s] from v into out (the inputs v[7:] copied)."""
    rhs(v, k1)
    work[:] = v
    for i in range(7):
        work[i] = v[i] + 0.5 * h * k1[i]
    rhs(work, k2)
    for i in range(7):
        work[i] = v[i] + h * (2.0 * k2[i] - k1[i])
    rhs(work, k3)
    out[:] = v
    for i in range(7):
        out[i] = v[i] + h * (k1[i] + 4.0 * k2[i] + k3[i]) / 6.0


def predict_flight(v0, step, e_f, floor, ceiling, max_time, steps_per_check):
    """The predicted flight from v0 (14, ``rhs``'s layout) with fixed steps ``step`` [s] until
    the energy e_f [J/kg] or a stop checked every ``steps_per_check`` steps: below ``floor`` [m],
    above ``ceiling`` [m], at ``max_time`` [s]. Returns (stop code, time [s], the final v, the
    number of right-hand sides evaluated)."""
    v, nxt = v0.copy(), v0.copy()
    k1, k2, k3, work = np.empty(7), np.empty(7), np.empty(7), np.empty(v0.size)
    e = np.empty(2)
    cross_from = v0.copy()
    t, evaluations = 0.0, 0
    while True:
        t0 = t
        crossed, t_cross = False, 0.0
        for k in range(steps_per_check):
            rk3_step(v, step, nxt, k1, k2, k3, work)
            evaluations += 3
            for i in range(7):
                if not math.isfinite(nxt[i]):
                    return NOT_FINITE, t, v, evaluations
            energy(nxt, e)
            if not crossed and e[0] >= e_f:
                crossed, t_cross = True, t
                cross_from[:] = v
            v[:] = nxt
            t = t0 + (k + 1) * step
        if e[0] >= e_f:  # e holds the energy after the chunk's last step
            return _newton_to_energy(cross_from, t_cross, step, e_f, nxt, k1, k2, k3, work, e, evaluations)
        if v[0] < floor:
            return FLOOR, t, v, evaluations
        if v[0] > ceiling:
            return CEILING, t, v, evaluations
        if t >= max_time:
            return TIMEOUT, t, v, evaluations


def _newton_to_energy(v, t, step, e_f, nxt, k1, k2, k3, work, e, evaluations):
    """From v at t (the start of the step that crosses e_f), at most three Newton steps on time
    to e_f (stopping when de/dt <= 0 or the step is under 1 us), each flown as Runge-Kutta
    steps of at most ``step``."""
    for _ in range(3):
        energy_rate(v, e)
        evaluations += 1
        if not e[1] > 0.0:
            break
        dt = (e_f - e[0]) / e[1]
        if not dt > 1e-6:
            break
        left = dt
        while left > 0.0:
            h = min(left, step)
            rk3_step(v, h, nxt, k1, k2, k3, work)
            evaluations += 3
            v[:] = nxt
            left -= h
        t += dt
    return REACHED, t, v, evaluations
