"""Paper 004's population of trajectories as one compiled call: the driver of the compiled
evaluator (``evaluator.evaluate``; module docstring there for the flight it replicates).

These functions are not called from Python as written: ``evaluator`` compiles them with numba
together with kernels generated from the model expressions (models.kernels), which they call by
name (v: the kernel's inputs, out: its outputs):

  ``aero``             [h, lon, lat, V, gamma, psi, alpha, k_L, k_D] -> [rho, a, Mach, L, D, q,
                       heat flux, total load g]
  ``motion``           [h, lon, lat, V, gamma, psi, bank, L, D] -> the 6 state rates
  ``derivatives``      [h, lon, lat, V, gamma, psi, bank, alpha, k_L, k_D] -> the 6 state rates
  ``bank_magnitude``   [h, V, gamma, L, D, sigma_0, sigma_f, e_0, e_f, q, heat flux, the path
                       feedback's load, heat-flux and q limits] -> |sigma| (eqs. 17, 46-48, Lu 2014's
                       path-limit feedback where the law has it)
  ``coefficients``     [alpha, Mach, k_L, k_D] -> [C_L, C_D]
  ``load_target``      [q] -> sqrt(C_L^2 + C_D^2) at the load limit (eq. 31)
  ``heat_target``      [C_D previous, heat flux] -> C_DQ (eq. 21, the flux over its limit)
  ``heading_error``    [lon, lat, psi, target lon, target lat] -> psi - bearing to the target
  ``energy``           [h, V] -> e = mu/r - V^2/2

and the shared laws compiled inline: the actuators (models.actuator.actuator_path) and the bank
reversal (models.bank_reversal). What is written here is the loop of the Python evaluator, per
member: no physics, and the alpha laws' Illinois root finder on one member at a time (the
Python evaluator's ``guidance_law._solve_increasing``, vectorised: tests hold the two equal).
"""
# ruff: noqa: F821  (the kernels named above are generated into the compiled module)
import math

import numpy as np

from drake_entry.guidance.swarm_bank.guidance_law import SOLVE_MAX_ITERATIONS, SOLVE_RTOL
from drake_entry.models.actuator import actuator_path
from drake_entry.models.bank_reversal import corridor_half_width, reversal_sign, wrap_angle

__all__ = ["PATH_LIMIT_FIELDS", "SETTINGS", "fly_population"]

#: the path feedback's limits (guidance.path_feedback.PathLimits fields), inputs of bank_magnitude
PATH_LIMIT_FIELDS = ("load_max", "heat_max", "q_max")

#: the layout of fly_population's ``settings`` array
SETTINGS = ("e0", "ef", "target_lon", "target_lat", "lift_scale", "drag_scale", "alpha0", "bank0", "sign0",
            "mach_was_above", "switched", "step_s", "substeps", "altitude_floor_m", "max_time_s", "alpha_min",
            "alpha_max", "bank_limit", "alpha_rate", "bank_rate", "alpha_accel", "bank_accel", "bandwidth",
            "heat_case", "mach_shift", "schedule_case", "path_load_max", "path_heat_max", "path_q_max",
            "bank_rate0")


def _coefficient(alpha, mach, kl, kd, total, v, out):
    """sqrt(C_L^2 + C_D^2) (total) or C_D at (alpha, Mach)."""
    v[0], v[1], v[2], v[3] = alpha, mach, kl, kd
    coefficients(v, out)
    return math.hypot(out[0], out[1]) if total else out[1]


def _solve(target, mach, kl, kd, total, lo, hi, v, out):
    """alpha in [lo, hi] where the coefficient equals ``target`` (increasing in alpha): Illinois
    false position, the bound where the target is outside (guidance_law._solve_increasing)."""
    a, b = lo, hi
    fa = _coefficient(a, mach, kl, kd, total, v, out) - target
    fb = _coefficient(b, mach, kl, kd, total, v, out) - target
    x = a if fa >= 0.0 else b
    inside = fa < 0.0 and fb > 0.0
    side = 0.0
    tol = SOLVE_RTOL * max(abs(target), 1.0)
    for _ in range(SOLVE_MAX_ITERATIONS):
        if not inside:
            break
        xi = b - fb * (b - a) / (fb - fa)
        fx = _coefficient(xi, mach, kl, kd, total, v, out) - target
        if fx > 0.0:  # the root is left of xi: xi becomes b
            if side == -1.0:
                fa = 0.5 * fa
            b, fb, side = xi, fx, -1.0
        else:
            if side == 1.0:
                fb = 0.5 * fb
            a, fa, side = xi, fx, 1.0
        x = xi
        inside = abs(fx) > tol and b - a > 1e-15
    return x


def fly_population(x0, sigma0, sigma_f, settings, corridor_velocity, corridor_heading, alpha_speeds, alpha_values,
                   final, t_end, reached, peaks, reversals):
    """Fly every member (sigma0[i], sigma_f[i]) from x0 with ``settings`` (SETTINGS) and write
    its final state (at the TAEM energy, interpolated, or where it stopped), time, whether it
    reached the energy, peaks [heat flux, q, load] and reversals into the output arrays.
    alpha_speeds, alpha_values: the 'schedule' law's alpha [rad] in speed [m/s]."""
    e0, ef, tlon, tlat, kl, kd = settings[0], settings[1], settings[2], settings[3], settings[4], settings[5]
    dt, steps, floor, max_time = settings[11], int(settings[12]), settings[13], settings[14]
    alpha_min, alpha_max, bank_limit = settings[15], settings[16], settings[17]
    rate_limits, accel_limits = (settings[18], settings[19]), (settings[20], settings[21])  # (alpha, bank)
    bandwidth, heat_case, mach_shift = settings[22], settings[23] > 0.5, settings[24]
    schedule_case = settings[25] > 0.5
    path_load, path_heat, path_q = settings[26], settings[27], settings[28]
    va, vb = np.empty(10), np.empty(14)
    aero_out, k1, k2, k3, k4 = np.empty(8), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    one, two = np.empty(1), np.empty(2)
    a_path, b_path = np.empty(steps + 1), np.empty(steps + 1)
    a_rates, b_rates = np.empty(steps + 1), np.empty(steps + 1)
    x, xn = np.empty(6), np.empty(6)
    half = steps // 2
    for i in range(sigma0.size):
        x[:] = x0
        alpha, alpha_rate, bank, bank_rate = settings[6], 0.0, settings[7], settings[29]
        sign = 1.0 if settings[8] >= 0.0 else -1.0
        alpha_command, above, switched = settings[6], settings[9] > 0.5, settings[10] > 0.5
        n_rev, p0, p1, p2 = 0, 0.0, 0.0, 0.0
        stopped, t = False, 0.0
        two[0], two[1] = x[0], x[3]
        energy(two, one)
        e = one[0]  # the energy at x, carried from step to step
        while t < max_time:
            for k in range(6):
                va[k] = x[k]
            va[6], va[7], va[8] = alpha, kl, kd
            aero(va, aero_out)
            mach, L, D, q, heat = aero_out[2], aero_out[3], aero_out[4], aero_out[5], aero_out[6]
            p0, p1, p2 = max(p0, heat), max(p1, q), max(p2, aero_out[7])
            vb[0], vb[1], vb[2], vb[3], vb[4] = x[0], x[3], x[4], L, D
            vb[5], vb[6], vb[7], vb[8] = sigma0[i], sigma_f[i], e0, ef
            vb[9], vb[10], vb[11], vb[12], vb[13] = q, heat, path_load, path_heat, path_q
            bank_magnitude(vb, one)
            magnitude = one[0]
            if schedule_case:
                command = np.interp(x[3], alpha_speeds, alpha_values)
            else:
                vb[0] = q
                load_target(vb, one)
                command = _solve(one[0], mach, kl, kd, True, alpha_min, alpha_max, vb, two)
            if heat_case:
                above = above or mach > mach_shift
                switched = switched or (above and mach <= mach_shift)
                if not switched:
                    _coefficient(alpha_command, mach, kl, kd, False, vb, two)
                    vb[0], vb[1] = two[1], heat
                    heat_target(vb, one)
                    command = _solve(one[0], mach, kl, kd, False, alpha_min, alpha_max, vb, two)
            alpha_command = command
            bank_command = sign * magnitude  # the sign of the previous step (the Python evaluator's)
            vb[0], vb[1], vb[2], vb[3], vb[4] = x[1], x[2], x[5], tlon, tlat
            heading_error(vb, one)
            new_sign = reversal_sign(wrap_angle(one[0]), corridor_half_width(x[3], corridor_heading,
                                                                              corridor_velocity), sign)
            if new_sign != sign:
                n_rev += 1
            sign = new_sign
            actuator_path(alpha, alpha_rate, alpha_command, dt / steps, steps, alpha_min, alpha_max, rate_limits[0],
                          accel_limits[0], bandwidth, a_path, a_rates)
            actuator_path(bank, bank_rate, bank_command, dt / steps, steps, -bank_limit, bank_limit, rate_limits[1],
                          accel_limits[1], bandwidth, b_path, b_rates)
            alpha, alpha_rate, bank, bank_rate = a_path[steps], a_rates[steps], b_path[steps], b_rates[steps]
            if steps % 2 == 0:
                a_mid, b_mid = a_path[half], b_path[half]
            else:
                a_mid, b_mid = 0.5 * (a_path[half] + a_path[half + 1]), 0.5 * (b_path[half] + b_path[half + 1])
            # one RK4 step of the plant's equations (the first stage's aerodynamics are those above)
            for k in range(6):
                va[k] = x[k]
            va[6], va[7], va[8] = b_path[0], L, D
            motion(va, k1)
            _stage(x, k1, 0.5 * dt, b_mid, a_mid, kl, kd, va, k2)
            _stage(x, k2, 0.5 * dt, b_mid, a_mid, kl, kd, va, k3)
            _stage(x, k3, dt, b_path[steps], a_path[steps], kl, kd, va, k4)
            for k in range(6):
                xn[k] = x[k] + dt / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k])
            t += dt
            two[0], two[1] = xn[0], xn[3]
            energy(two, one)
            e_new = one[0]
            if e_new >= ef:  # the TAEM energy was crossed inside this step: interpolate in energy
                w = min(max((ef - e) / (e_new - e), 0.0), 1.0)
                for k in range(6):
                    final[i, k] = x[k] + w * (xn[k] - x[k])
                t_end[i], reached[i], stopped = t - dt + w * dt, True, True
                break
            if xn[0] < floor:
                final[i, :] = xn
                t_end[i], stopped = t, True
                break
            x[:] = xn
            e = e_new
        if not stopped:
            final[i, :] = x
            t_end[i] = t
        peaks[i, 0], peaks[i, 1], peaks[i, 2], reversals[i] = p0, p1, p2, n_rev


def _stage(x, k, h, bank, alpha, kl, kd, v, out):
    """The state rates at x + h k with the actuators at (bank, alpha)."""
    for j in range(6):
        v[j] = x[j] + h * k[j]
    v[6], v[7], v[8], v[9] = bank, alpha, kl, kd
    derivatives(v, out)
