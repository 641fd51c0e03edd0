"""Paper 004 trajectories for a whole population at once: every member flies the guidance law
of ``guidance_law`` with its own sigma_0 (eq. 17), from the entry state to the TAEM energy,
and gets the objective of eq. 32.

Per guidance step (``guidance_step_s``, the step the eq. 21 recursion depends on): air data,
the bank magnitude (eq. 17 with the QEG compensation of eq. 48, limited to the vehicle's bank
limit), its sign from the heading-error corridor (the reversal logic of paper 000 Sec. VI.D),
the alpha command (eq. 31, or eq. 21 until Mach falls below Mach_shift, latched), the alpha
actuator over the step in ``actuator_substep_s`` RK2 substeps (rate and acceleration limits),
then one RK4 step of drake_entry.dynamics (the same equations as the Drake plant) with the
actuator's alpha at the stage times. A member stops at the TAEM energy (its final state
interpolated in energy), below the altitude floor or at ``max_time_s``.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from ...actuator import integrate_actuators
from ...constraints import dynamic_pressure
from ...dynamics import aero_accelerations, equations_of_motion, state_derivatives
from ...geodesy import bearings, downtrack_crosstrack
from ...reversal import corridor_half_width, reversal_sign, wrap_angle
from .guidance_law import alpha_for_heat_rate, alpha_for_load_factor, linear_bank, qeg_bank, qeg_sin_flight_path


@dc.dataclass
class SwarmProblem:
    """A paper-004 design problem (SI, rad).

    Attributes:
      vehicle, planet, atmosphere: models (a rotating sphere, central gravity: paper 004 eq. 12).
      x0: entry state [h, lon, lat, V, gamma, psi]. target: (lon, lat) of the TAEM point.
      h_f, V_f: TAEM altitude [m] and speed [m/s] (r*, V* of eq. 32).
      sigma_f: terminal bank of eq. 17 (paper: 60 deg).
      alpha_min, alpha_max, alpha_rate, alpha_accel: alpha bounds and actuator limits.
      load_max [g], heat_max [W/m^2]: the path limits of eqs. 13-14.
      case: 'load' (Case 1, eq. 31) or 'heat' (Case 2, eq. 21 until mach_shift, then eq. 31).
      k2, beta: eq. 48 gain and eq. 46 nondimensional scale height (paper: 10, 920).
      reversal_heading, reversal_velocity: heading-error corridor [rad] linear in speed [m/s].
    """

    vehicle: object
    planet: object
    atmosphere: object
    x0: np.ndarray
    target: tuple
    h_f: float
    V_f: float
    sigma_f: float = math.radians(60.0)
    alpha_min: float = math.radians(10.0)
    alpha_max: float = math.radians(20.0)
    alpha_rate: float = math.radians(4.0)
    alpha_accel: float = math.radians(8.0)
    load_max: float = 2.0
    heat_max: float = 6e6
    case: str = "load"
    mach_shift: float = 20.0
    k2: float = 10.0
    beta: float = 920.0
    reversal_heading: tuple = (math.radians(5.0), math.radians(15.0))
    reversal_velocity: tuple = (1000.0, 6000.0)
    guidance_step_s: float = 1.0
    actuator_substep_s: float = 0.05
    altitude_floor_m: float = 5000.0
    max_time_s: float = 5000.0

    @property
    def e0(self) -> float:
        """Energy-like variable e = mu/r - V^2/2 at entry [J/kg] (eq. 10, SI)."""
        return self.energy(self.x0[0], self.x0[3])

    @property
    def ef(self) -> float:
        return self.energy(self.h_f, self.V_f)

    def energy(self, h, V):
        return self.planet.mu / self.planet.radius(h) - 0.5 * np.asarray(V) ** 2


@dc.dataclass
class Evaluation:
    """Per member (arrays): objective J (eq. 32), its parts, the final state and peaks.

    Attributes: J; range_error_m (signed along-track: + beyond the target); crossrange_m;
      altitude_error_m; velocity_error_m_s; final_state (n, 6); time_s; reached (bool);
      peak_heat_flux_W_m2, peak_dynamic_pressure_Pa, peak_total_load_g; reversals;
      trajectories: members evaluated.
    """

    J: np.ndarray
    range_error_m: np.ndarray
    crossrange_m: np.ndarray
    altitude_error_m: np.ndarray
    velocity_error_m_s: np.ndarray
    final_state: np.ndarray
    time_s: np.ndarray
    reached: np.ndarray
    peak_heat_flux_W_m2: np.ndarray
    peak_dynamic_pressure_Pa: np.ndarray
    peak_total_load_g: np.ndarray
    reversals: np.ndarray
    trajectories: int


def evaluate(problem: SwarmProblem, sigma0) -> Evaluation:
    """Fly every sigma0 [rad] of the population (array) and return its Evaluation."""
    p, pl = problem, problem.planet
    sigma0 = np.atleast_1d(np.asarray(sigma0, float))
    n = sigma0.size
    x = np.tile(np.asarray(p.x0, float)[:, None], (1, n))
    alpha = np.full(n, p.alpha_max)
    alpha_rate = np.zeros(n)
    sign = np.ones(n)
    reversals = np.zeros(n, int)
    latched = np.zeros(n, bool)  # Case 2: Mach has been above mach_shift and fallen below it
    been_above = np.zeros(n, bool)
    active = np.ones(n, bool)
    reached = np.zeros(n, bool)
    final = x.copy()
    t_end = np.zeros(n)
    peaks = np.zeros((3, n))
    e0, ef = p.e0, p.ef
    R0, g0 = pl.reference_radius, pl.g0
    v_scale = math.sqrt(g0 * R0)
    lim = dict(lower=p.alpha_min, upper=p.alpha_max, rate_limit=p.alpha_rate, accel_limit=p.alpha_accel,
               bandwidth=2.0)
    steps = max(1, int(round(p.guidance_step_s / p.actuator_substep_s)))
    dt = p.guidance_step_s
    t = 0.0
    while active.any() and t < p.max_time_s:
        idx = np.flatnonzero(active)
        xa = x[:, idx]
        h, V, gamma = xa[0], xa[3], xa[4]
        rho, a = p.atmosphere.air_data(pl.atmospheric_altitude(h, xa[2]))
        mach, L, D = aero_accelerations(xa, alpha[idx], rho, a, p.vehicle)
        q = dynamic_pressure(rho, V)
        heat = p.vehicle.heat_flux(rho, V)
        peaks[:, idx] = np.maximum(peaks[:, idx], [heat, q, np.hypot(L, D) / g0])
        # bank magnitude: eq. 17, then the QEG compensation (eqs. 46-48, nondimensional)
        e = p.energy(h, V)
        base = linear_bank(e, e0, ef, sigma0[idx], p.sigma_f)
        r_n, V_n = pl.radius(h) / R0, V / v_scale
        s_qeg = qeg_sin_flight_path(r_n, V_n, D / g0, p.beta)
        mag = np.minimum(qeg_bank(base, L / g0, D / g0, np.sin(gamma), s_qeg, p.k2), p.vehicle.bank_limit)
        # sign: heading-error corridor (positive bank turns right)
        err = wrap_angle(xa[5] - bearings(xa[1], xa[2], *p.target))
        new_sign = reversal_sign(err, corridor_half_width(V, p.reversal_heading, p.reversal_velocity), sign[idx])
        reversals[idx] += new_sign != sign[idx]
        sign[idx] = new_sign
        bank = sign[idx] * mag
        # alpha command: eq. 31, or eq. 21 while Case 2 has not switched (latched at Mach_shift)
        command = alpha_for_load_factor(q, mach, p.vehicle.aero, p.vehicle.area_over_mass, g0, p.load_max,
                                        p.alpha_min, p.alpha_max)
        if p.case == "heat":
            been_above[idx] |= mach > p.mach_shift
            latched[idx] |= been_above[idx] & (mach <= p.mach_shift)
            heat_alpha = alpha_for_heat_rate(alpha[idx], heat / p.heat_max, mach, p.vehicle.aero, p.alpha_min,
                                             p.alpha_max)
            command = np.where(latched[idx], command, heat_alpha)
        alpha_new, rate_new, positions = integrate_actuators(alpha[idx], alpha_rate[idx], command,
                                                             dt / steps, steps, **lim)
        stage_alpha = (positions[0], positions[steps // 2], positions[-1])
        # one RK4 step of the plant's equations
        k1 = equations_of_motion(xa, bank, L, D, pl)  # the air data above are the first stage's
        k2 = np.asarray(state_derivatives(list(xa + 0.5 * dt * k1), bank, stage_alpha[1], p.vehicle, pl, p.atmosphere))
        k3 = np.asarray(state_derivatives(list(xa + 0.5 * dt * k2), bank, stage_alpha[1], p.vehicle, pl, p.atmosphere))
        k4 = np.asarray(state_derivatives(list(xa + dt * k3), bank, stage_alpha[2], p.vehicle, pl, p.atmosphere))
        xn = xa + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        alpha[idx], alpha_rate[idx] = alpha_new, rate_new
        t += dt
        e_new = p.energy(xn[0], xn[3])
        done = e_new >= ef
        if done.any():  # the TAEM energy was crossed inside this step: interpolate in energy
            w = np.clip((ef - e[done]) / (e_new[done] - e[done]), 0.0, 1.0)
            final[:, idx[done]] = xa[:, done] + w * (xn[:, done] - xa[:, done])
            t_end[idx[done]] = t - dt + w * dt
            reached[idx[done]] = True
        low = ~done & (xn[0] < p.altitude_floor_m)
        final[:, idx[low]] = xn[:, low]
        t_end[idx[low]] = t
        x[:, idx] = xn
        active[idx[done | low]] = False
    final[:, active] = x[:, active]
    t_end[active] = t
    R = pl.reference_radius
    lon0, lat0 = p.x0[1], p.x0[2]
    d, c = downtrack_crosstrack(final[1], final[2], lon0, lat0, p.target[0], p.target[1], R)
    d_target, _ = downtrack_crosstrack(np.array([p.target[0]]), np.array([p.target[1]]), lon0, lat0, *p.target, R)
    ds, dh, dV = d - d_target[0], final[0] - p.h_f, final[3] - p.V_f
    J = np.abs(ds) / 1.852e5 + np.abs(dh) / 1e3 + np.abs(dV) / 100.0  # eq. 32
    J = np.where(reached, J, np.inf)
    return Evaluation(J, ds, c, dh, dV, final.T.copy(), t_end, reached, peaks[0], peaks[1], peaks[2], reversals, n)
