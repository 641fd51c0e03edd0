"""Paper 004 trajectories for a whole population at once: every member flies the guidance law
of ``guidance_law`` with its own sigma_0 (eq. 17), from the start state to the TAEM energy,
and gets the objective of eq. 32.

The evaluation is a discrete-time replica of the Drake closed loop the method flies
(diagrams/closed_loop.py with guidance/swarm_bank), so a planned optimum is what the
Simulator then flies. Per guidance step (``guidance_step_s``, the step the eq. 21 recursion
depends on): air data and aerodynamic accelerations at the actuators' positions; the law's
|sigma| and alpha commands (``law_commands``); the bank command is |sigma| times the sign
chosen at the previous step (the shared reversal logic's sign is a discrete state, so the
actuator samples it one step late), then the sign is updated from the heading-error
corridor (paper 000 Sec. VI.D); both actuators are integrated over the step in
``actuator_substep_s`` steps (drake_entry.models.actuator, the Drake actuators' law); then one RK4
step of drake_entry.models.dynamics (the same equations as the Drake plant) with the actuators'
positions at the stage times. A member stops at the TAEM energy (its final state
interpolated in energy), below the altitude floor or at ``max_time_s``.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.symbolic import Expression, Variable

from drake_entry.errors import ScenarioError
from drake_entry.guidance.path_feedback import PathLimits, enforced
from drake_entry.guidance.swarm_bank import population_flight
from drake_entry.guidance.swarm_bank.guidance_law import (
    LawMemory,
    LawSettings,
    bank_magnitude,
    heat_drag_target,
    law_commands,
    load_coefficient_target,
    scheduled_alpha,
)
from drake_entry.guidance.swarm_bank.population_flight import PATH_LIMIT_FIELDS
from drake_entry.guidance.swarm_bank.spec import ALPHA_LAWS
from drake_entry.models.actuator import integrate_actuators
from drake_entry.models.aerodynamics import ScaledAero
from drake_entry.models.bank_reversal import corridor_half_width, reversal_sign, wrap_angle
from drake_entry.models.constraints import dynamic_pressure
from drake_entry.models.dynamics import aero_accelerations, air_data, equations_of_motion, state_derivatives
from drake_entry.models.geodesy import bearings, central_angle, downtrack_crosstrack
from drake_entry.models.kernels import Kernel, compile_kernels
from drake_entry.models.verdict import altitude_floor

__all__ = ["RANGE_UNIT_M", "ALTITUDE_UNIT_M", "SPEED_UNIT_M_S", "SwarmProblem", "Evaluation", "HISTORY_COLUMNS",
           "CONTROL_COLUMNS", "ENGINES", "evaluate", "range_error", "LIMIT_WEIGHT", "limit_excess",
           "HELD_BY_ALPHA"]

#: J of eq. 32: range error over 100 nmi, altitude error over 1 km, speed error over 100 m/s
RANGE_UNIT_M, ALTITUDE_UNIT_M, SPEED_UNIT_M_S = 1.852e5, 1e3, 100.0
#: J added per unit of relative excess of a path limit the alpha law does not hold (the 'schedule'
#: law holds none, eq. 31 the load alone; a 10 % breach weighs as 10 km of altitude error)
LIMIT_WEIGHT = 100.0


#: the path limits each alpha law holds by its alpha (eq. 31 flies the load on its limit; Case 2
#: the heat rate, then the load): the bank's path feedback and J's penalty see only the others
HELD_BY_ALPHA = {"load": ("load",), "heat": ("heat", "load"), "schedule": ()}


def limit_excess(limits, peaks, fraction: float = 1.0, held=()):
    """Sum over heat flux ('heat'), dynamic pressure ('q') and load ('load') of
    max(0, peak / (fraction limit) - 1) per member, except the limits in ``held``; ``peaks``
    (3, n): [heat flux W/m^2, q Pa, total load g] (the total load against the lower of the
    vehicle's total and normal load limits: the total bounds the normal)."""
    bounds = (("heat", limits.heat_flux_max), ("q", limits.dynamic_pressure_max), ("load", limits.load_bound_max))
    return sum(np.maximum(np.asarray(peak, float) / (fraction * bound) - 1.0, 0.0)
               for peak, (name, bound) in zip(peaks, bounds) if math.isfinite(bound) and name not in held)


@dc.dataclass
class SwarmProblem:
    """A paper-004 design problem (SI, rad).

    Attributes:
      vehicle, planet, atmosphere: models (a rotating sphere, central gravity: paper 004 eq. 12).
      x0: start state [h, lon, lat, V, gamma, psi]. target: (lon, lat) of the TAEM point.
      origin: (lon, lat) the along-track range is measured from (None: x0's position).
      h_f, V_f: TAEM altitude [m] and speed [m/s] (r*, V* of eq. 32).
      sigma_f: terminal bank of eq. 17 (paper: 60 deg). e0: eq. 17's start energy [J/kg]
        (None: x0's; an on-board re-solution keeps the entry's).
      alpha_min, alpha_max, alpha_rate, alpha_accel: alpha bounds and actuator limits.
      load_max [g], heat_max [W/m^2]: the path limits of eqs. 13-14.
      case: 'load' (Case 1, eq. 31), 'heat' (Case 2, eq. 21 until mach_shift, then eq. 31) or
        'schedule' (alpha_schedule: another method's alpha profile, as a mission states it).
      alpha_schedule: ((speeds [m/s], increasing), (alpha [rad])) of the 'schedule' case.
      objective_units: eq. 32's range [m], altitude [m] and speed [m/s] units (paper 004: 100 nmi,
        1 km, 100 m/s).
      limit_fraction: J is penalised past this fraction of each limit the alpha law does not hold.
      path_gain, path_horizon_s, path_fraction: Lu 2014's path-limit feedback on the bank (gain,
        horizon [s]) holding this fraction of the vehicle's limits under the 'schedule' case
        (guidance.path_feedback; gain 0: paper 004's law).
      k2, beta: eq. 48 gain and eq. 46 nondimensional scale height (paper: 10, 920).
      reversal_heading, reversal_velocity: heading-error corridor [rad] linear in speed [m/s].
      initial_alpha, initial_bank, initial_bank_rate, initial_sign, memory: the actuators
        [rad, rad/s], the reversal sign and the alpha law's memory at x0 (entry: alpha_max, or
        the schedule's alpha at x0's speed; 0, 0, +1, nothing latched). On board the bank and its
        rate are the actuator's, so that a reversal under way is predicted as flown.
    """

    vehicle: object
    planet: object
    atmosphere: object
    x0: np.ndarray
    target: tuple
    h_f: float
    V_f: float
    origin: tuple | None = None
    sigma_f: float = math.radians(60.0)
    e0: float | None = None
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
    actuator_substep_s: float = 0.02
    altitude_floor_m: float | None = None  # None: models.verdict.altitude_floor(h_f), the closed loop's
    max_time_s: float = 5000.0
    initial_alpha: float | None = None
    initial_bank: float = 0.0
    initial_bank_rate: float = 0.0
    initial_sign: float = 1.0
    memory: tuple = (False, False)  # (Mach was above Mach_shift, switched to Case 1)
    alpha_schedule: tuple = ((), ())
    objective_units: tuple = (RANGE_UNIT_M, ALTITUDE_UNIT_M, SPEED_UNIT_M_S)
    limit_fraction: float = 1.0
    path_gain: float = 0.0
    path_horizon_s: float = 16.0
    path_fraction: float = 0.9

    def __post_init__(self):
        if self.altitude_floor_m is None:
            self.altitude_floor_m = altitude_floor(self.h_f)
        if self.case not in ALPHA_LAWS:
            raise ScenarioError(f"paper-004 alpha law case = {self.case!r}; allowed: {', '.join(ALPHA_LAWS)}")
        speeds, values = self.alpha_schedule
        if self.case == "schedule" and not (len(speeds) == len(values) >= 1 and np.all(np.diff(speeds) > 0)):
            raise ScenarioError(f"the 'schedule' alpha law needs as many alphas as increasing speeds; got "
                                f"{len(values)} alphas at speeds {list(speeds)}")

    @property
    def entry_alpha(self) -> float:
        """The alpha actuator at x0 [rad]: initial_alpha, else the schedule's alpha at x0's
        speed ('schedule'), else alpha_max."""
        if self.initial_alpha is not None:
            return self.initial_alpha
        if self.case == "schedule":
            return float(scheduled_alpha(float(self.x0[3]), *self.alpha_schedule))
        return self.alpha_max

    @property
    def start_energy(self) -> float:
        """eq. 17's e0 [J/kg] (e = mu/r - V^2/2, eq. 10, SI)."""
        return self.energy(self.x0[0], self.x0[3]) if self.e0 is None else self.e0

    @property
    def ef(self) -> float:
        return self.energy(self.h_f, self.V_f)

    def energy(self, h, V):
        """e = mu/r - V^2/2 [J/kg] (eq. 10): any scalar type or numpy arrays."""
        return self.planet.mu / self.planet.radius(h) - 0.5 * V * V

    def path_limits(self) -> PathLimits | None:
        """The path-limit feedback's settings: path_fraction of the vehicle's limits (those of a
        re-solution's sensed vehicle, models.acceleration_ratios.sensed_vehicle, in its nominal
        air) that the alpha law does not hold (HELD_BY_ALPHA: eq. 31 flies the load on its
        limit, which the feedback would fight; it does not hold the heat rate or q), or None
        without a gain or a limit left to hold."""
        held = HELD_BY_ALPHA[self.case]
        if self.path_gain <= 0.0 or "heat" in held:  # Case 2's alpha holds the heat rate, then the load
            return None
        path = PathLimits.of_vehicle(self.vehicle.limits, self.planet, gain=self.path_gain,
                                     horizon=self.path_horizon_s, fraction=self.path_fraction, beta=self.beta)
        path = dc.replace(path, load_max=math.inf) if "load" in held else path
        return path if path.active else None

    def law(self) -> LawSettings:
        pl = self.planet
        return LawSettings(self.sigma_f, self.start_energy, self.ef, self.vehicle.bank_limit, self.alpha_min,
                           self.alpha_max, self.load_max, self.heat_max, self.case, self.mach_shift, self.k2,
                           self.beta, pl.reference_radius, pl.g0, pl.mu, *map(tuple, self.alpha_schedule),
                           path=self.path_limits())


@dc.dataclass
class Evaluation:
    """Per member (arrays): objective J (eq. 32), its parts, the final state and peaks.

    Attributes:
      J: objective of eq. 32, its range term the great-circle distance to the TAEM point (inf
        where the TAEM energy was not reached), plus LIMIT_WEIGHT times the relative excess of the
        path limits the alpha law does not hold (limit_excess, HELD_BY_ALPHA).
      range_error_m: signed along-track distance at TAEM [m], + beyond the target.
      crossrange_m: cross-track distance from the entry-to-target great circle [m].
      altitude_error_m: h - h_f at the TAEM energy [m].
      velocity_error_m_s: V - V_f at the TAEM energy [m/s].
      final_state: (n, 6) state at the TAEM energy (or where the member stopped).
      time_s: time of the TAEM energy [s]. reached: the TAEM energy was reached.
      peak_heat_flux_W_m2: largest heat rate along the trajectory.
      peak_dynamic_pressure_Pa: largest dynamic pressure.
      peak_total_load_g: largest total load factor.
      reversals: bank reversals flown. trajectories: members evaluated.
      history: per member, the recorded steps (HISTORY_COLUMNS), when asked.
      controls: per member, the actuators' positions at every actuator sub-step, when asked:
        (m, 3) [time s, alpha rad, bank rad], what the plant flew between the guidance steps
        (CONTROL_COLUMNS).
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
    history: list | None = None
    controls: list | None = None


#: columns of Evaluation.history tables
HISTORY_COLUMNS = ("time_s", "altitude_m", "longitude_rad", "latitude_rad", "velocity_m_s", "flight_path_rad",
                   "heading_rad", "alpha_rad", "bank_rad", "bank_command_rad", "alpha_command_rad", "mach",
                   "dynamic_pressure_Pa", "heat_flux_W_m2", "total_load_g")
#: columns of Evaluation.controls tables
CONTROL_COLUMNS = ("time_s", "alpha_rad", "bank_rad")


def evaluate(problem: SwarmProblem, sigma0, *, sigma_f=None, record: bool = False,
             engine: str = "compiled") -> Evaluation:
    """Fly every sigma0 [rad] of the population (array) and return its Evaluation; ``sigma_f``
    [rad]: per-member eq. 17 end banks (the two-parameter search; default the problem's); with
    ``record`` each member's step-by-step history (HISTORY_COLUMNS) and its actuators' path at
    every sub-step (CONTROL_COLUMNS) are kept. ``engine``: "compiled" (the default; one compiled
    call for the population, population_flight) or "numpy" (this function's vectorised loop, the
    reference the compiled flight is tested against); a recorded evaluation is always "numpy"."""
    if engine not in ENGINES:
        raise ScenarioError(f"swarm evaluator engine = {engine!r}; allowed: {', '.join(ENGINES)}")
    p = problem
    sigma0 = np.atleast_1d(np.asarray(sigma0, float))
    n = sigma0.size
    sigma_f = None if sigma_f is None else np.broadcast_to(np.asarray(sigma_f, float), (n,))
    if engine == "compiled" and not record:
        final, t_end, reached, peaks, reversals = _fly_compiled(p, sigma0, sigma_f)
        return _evaluation(p, final, t_end, reached, peaks, reversals, n)
    return _fly_numpy(p, sigma0, sigma_f, record)


def _evaluation(p: SwarmProblem, final, t_end, reached, peaks, reversals, n, history=None, controls=None):
    """The Evaluation of final states (6, n) and the rest (eq. 32)."""
    ds, c = range_error(p, final[1], final[2])
    dh, dV = final[0] - p.h_f, final[3] - p.V_f
    range_unit, altitude_unit, speed_unit = p.objective_units
    # eq. 32's s(e_f): the great-circle range to go to the TAEM point (s* = 0), crossrange included:
    # along-track alone planned SPHYNX's long glide 151 km beside the site, the bank's magnitude set for range only
    s = p.planet.reference_radius * central_angle(final[1], final[2], *p.target)
    J = s / range_unit + np.abs(dh) / altitude_unit + np.abs(dV) / speed_unit  # eq. 32
    # the breaches of the limits the alpha law does not hold are penalised
    J = J + LIMIT_WEIGHT * limit_excess(p.vehicle.limits, peaks, p.limit_fraction, HELD_BY_ALPHA[p.case])
    J = np.where(reached, J, np.inf)
    return Evaluation(J, ds, c, dh, dV, final.T.copy(), t_end, reached, peaks[0], peaks[1], peaks[2], reversals, n,
                      history, controls)


def _fly_numpy(p: SwarmProblem, sigma0, sigma_f, record: bool) -> Evaluation:
    """The population flown on numpy arrays, every member a column (module docstring)."""
    pl, veh = p.planet, p.vehicle
    n = sigma0.size
    law = p.law()
    x = np.tile(np.asarray(p.x0, float)[:, None], (1, n))
    alpha0 = p.entry_alpha
    alpha, alpha_rate = np.full(n, alpha0), np.zeros(n)
    bank, bank_rate = np.full(n, p.initial_bank), np.full(n, p.initial_bank_rate)
    sign = np.full(n, 1.0 if p.initial_sign >= 0 else -1.0)
    memory = LawMemory.start(alpha0, n, was_above=p.memory[0], switched=p.memory[1])
    reversals = np.zeros(n, int)
    active, reached = np.ones(n, bool), np.zeros(n, bool)
    final, t_end, peaks = x.copy(), np.zeros(n), np.zeros((3, n))
    ef = p.ef
    # alpha (first n) and bank (last n) actuators integrate in one call with per-member limits
    limits = {k: np.repeat([a, b], n) for k, a, b in (
        ("lower", p.alpha_min, -veh.bank_limit), ("upper", p.alpha_max, veh.bank_limit),
        ("rate_limit", p.alpha_rate, veh.bank_rate_limit), ("accel_limit", p.alpha_accel, veh.bank_accel_limit))}
    dt = p.guidance_step_s
    steps = max(1, int(round(dt / p.actuator_substep_s)))
    history = [[] for _ in range(n)] if record else None
    controls = [[] for _ in range(n)] if record else None
    t = 0.0
    while active.any() and t < p.max_time_s:
        idx = np.flatnonzero(active)
        xa = x[:, idx]
        V = xa[3]
        rho, a = p.atmosphere.air_data(pl.atmospheric_altitude(xa[0], xa[2]))
        mach, L, D = aero_accelerations(xa, alpha[idx], rho, a, veh)
        q, heat = dynamic_pressure(rho, V), veh.heat_flux(rho, V)
        load = np.hypot(L, D) / pl.g0
        peaks[:, idx] = np.maximum(peaks[:, idx], [heat, q, load])
        mem = LawMemory(memory.alpha_command[idx], memory.mach_was_above[idx], memory.switched[idx])
        magnitude, alpha_cmd, mem = law_commands(law, sigma0[idx], xa, pl.radius(xa[0]), rho, mach, L, D, heat, q,
                                                 veh.aero, veh.area_over_mass, mem,
                                                 None if sigma_f is None else sigma_f[idx])
        memory.alpha_command[idx], memory.mach_was_above[idx], memory.switched[idx] = (
            mem.alpha_command, mem.mach_was_above, mem.switched)
        bank_cmd = sign[idx] * magnitude  # the sign of the previous step (see module doc)
        err = wrap_angle(xa[5] - bearings(xa[1], xa[2], *p.target))
        new_sign = reversal_sign(err, corridor_half_width(V, p.reversal_heading, p.reversal_velocity), sign[idx])
        reversals[idx] += new_sign != sign[idx]
        sign[idx] = new_sign
        if record:
            for j, i in enumerate(idx):
                history[i].append((t, *xa[:, j], alpha[i], bank[i], bank_cmd[j], alpha_cmd[j], mach[j], q[j],
                                   heat[j], load[j]))
        both = np.concatenate([idx, idx + n])
        pos, rates, path = integrate_actuators(np.concatenate([alpha[idx], bank[idx]]),
                                               np.concatenate([alpha_rate[idx], bank_rate[idx]]),
                                               np.concatenate([alpha_cmd, bank_cmd]), dt / steps, steps,
                                               bandwidth=2.0, **{k: v[both] for k, v in limits.items()})
        m = idx.size
        alpha[idx], bank[idx], alpha_rate[idx], bank_rate[idx] = pos[:m], pos[m:], rates[:m], rates[m:]
        a_path, b_path = path[:, :m], path[:, m:]
        if record:
            sub = t + dt * np.arange(steps) / steps  # each step's last point is the next step's first
            for j, i in enumerate(idx):
                controls[i].append(np.column_stack([sub, a_path[:-1, j], b_path[:-1, j]]))
        mid = steps // 2 if steps % 2 == 0 else None
        a_mid = a_path[mid] if mid is not None else 0.5 * (a_path[steps // 2] + a_path[steps // 2 + 1])
        b_mid = b_path[mid] if mid is not None else 0.5 * (b_path[steps // 2] + b_path[steps // 2 + 1])
        # one RK4 step of the plant's equations (the first stage's air data are those above)
        k1 = equations_of_motion(xa, b_path[0], L, D, pl)
        k2 = np.asarray(state_derivatives(list(xa + 0.5 * dt * k1), b_mid, a_mid, veh, pl, p.atmosphere))
        k3 = np.asarray(state_derivatives(list(xa + 0.5 * dt * k2), b_mid, a_mid, veh, pl, p.atmosphere))
        k4 = np.asarray(state_derivatives(list(xa + dt * k3), b_path[-1], a_path[-1], veh, pl, p.atmosphere))
        xn = xa + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        t += dt
        e, e_new = p.energy(xa[0], V), p.energy(xn[0], xn[3])
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
    if record:
        history = [np.array(h) for h in history]
        controls = [np.vstack(c_i) for c_i in controls]
    return _evaluation(p, final, t_end, reached, peaks, reversals, n, history, controls)


#: how a population is flown: "compiled" (population_flight with kernels generated from the
#: models, models.kernels) or "numpy" (the vectorised loop: the reference)
ENGINES = ("compiled", "numpy")
_COMPILED: dict = {}  # the compiled module per (vehicle, planet, atmosphere, law) in this process


def _unscaled(vehicle):
    """(vehicle with its base aerodynamics, k_L, k_D) of a vehicle whose aerodynamics may be
    ScaledAero (the on-board re-solution's acceleration ratios): the scales are kernel inputs."""
    if isinstance(vehicle.aero, ScaledAero):
        return dc.replace(vehicle, aero=vehicle.aero.base), vehicle.aero.lift_scale, vehicle.aero.drag_scale
    return vehicle, 1.0, 1.0


def _population_module(p: SwarmProblem, vehicle):
    """The compiled population flight of ``p``'s models and law constants (cached per process;
    the generated text is cached per machine by models.kernels)."""
    law = p.law()
    # what the trace reads: the objects by identity (an on-board re-solution rebuilds the vehicle
    # around the same aerodynamics each time), the numbers by value
    objects = (vehicle.aero, vehicle.heat_flux, p.planet, p.atmosphere)
    path = law.path if law.path is not None and law.path.active else None
    # the path feedback's limits are inputs (a re-solution's sensed vehicle moves them): its form is in the key
    path_form = None if path is None else (path.gain, path.horizon, path.beta, path.R0, path.g0,
                                           *(enforced(getattr(path, k)) for k in PATH_LIMIT_FIELDS))
    key = (*map(id, objects), vehicle.mass, vehicle.reference_area, vehicle.nose_radius, p.load_max, p.heat_max,
           law.k2, law.beta, law.bank_limit, path_form)
    found = _COMPILED.get(key)
    if found is not None and all(a is b for a, b in zip(found[0], objects)):
        return found[1]
    pl, atm = p.planet, p.atmosphere
    names = ("h", "lon", "lat", "V", "gamma", "psi", "alpha", "bank", "L", "D", "kL", "kD", "sigma0", "sigmaf",
             "e0", "ef", "mach", "q", "cd", "heat", "tlon", "tlat", *(f"path_{k}" for k in PATH_LIMIT_FIELDS))
    v = {n: Variable(n) for n in names}
    e = {n: Expression(var) for n, var in v.items()}
    x = [e[n] for n in names[:6]]
    traced = dc.replace(vehicle, aero=ScaledAero(vehicle.aero, e["kL"], e["kD"]))
    with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
        rho, a = air_data(x, pl, atm)
        mach, L, D = aero_accelerations(x, e["alpha"], rho, a, traced)
        aero = (rho, a, mach, L, D, dynamic_pressure(rho, e["V"]), traced.heat_flux(rho, e["V"]),
                np.sqrt(L * L + D * D) / pl.g0)
        traced_law = law if path is None else dc.replace(law, path=dc.replace(path, **{
            k: e[f"path_{k}"] for k in PATH_LIMIT_FIELDS if enforced(getattr(path, k))}))
        magnitude = bank_magnitude(traced_law, e["sigma0"], e["V"], e["gamma"], pl.radius(e["h"]), e["L"], e["D"],
                                   e["sigmaf"], e["e0"], e["ef"], heat=e["heat"], q=e["q"])
        kernels = [
            Kernel("aero", aero, tuple(v[n] for n in (*names[:7], "kL", "kD"))),
            Kernel("motion", tuple(equations_of_motion(x, e["bank"], e["L"], e["D"], pl)),
                   tuple(v[n] for n in (*names[:6], "bank", "L", "D"))),
            Kernel("derivatives", tuple(state_derivatives(x, e["bank"], e["alpha"], traced, pl, atm)),
                   tuple(v[n] for n in (*names[:6], "bank", "alpha", "kL", "kD"))),
            Kernel("bank_magnitude", (magnitude,),
                   tuple(v[n] for n in ("h", "V", "gamma", "L", "D", "sigma0", "sigmaf", "e0", "ef", "q", "heat",
                                        *(f"path_{k}" for k in PATH_LIMIT_FIELDS)))),
            Kernel("coefficients", tuple(traced.aero.coefficients(e["alpha"], e["mach"])),
                   tuple(v[n] for n in ("alpha", "mach", "kL", "kD"))),
            Kernel("load_target", (load_coefficient_target(e["q"], vehicle.area_over_mass, pl.g0, p.load_max),),
                   (v["q"],)),
            Kernel("heat_target", (heat_drag_target(e["cd"], e["heat"] / p.heat_max),), (v["cd"], v["heat"])),
            Kernel("heading_error", (e["psi"] - bearings(e["lon"], e["lat"], e["tlon"], e["tlat"]),),
                   tuple(v[n] for n in ("lon", "lat", "psi", "tlon", "tlat"))),
            Kernel("energy", (p.energy(e["h"], e["V"]),), (v["h"], v["V"])),
        ]
    module = compile_kernels(kernels, population_flight, tag="swarm_population")
    _COMPILED[key] = (objects, module)  # the objects held, so their ids stay theirs
    return module


def _fly_compiled(p: SwarmProblem, sigma0, sigma_f):
    """(final (6, n), t_end, reached, peaks (3, n), reversals) of the population, compiled."""
    vehicle, kl, kd = _unscaled(p.vehicle)
    module = _population_module(p, vehicle)
    path = p.path_limits()
    n = sigma0.size
    alpha0 = p.entry_alpha
    values = dict(e0=p.start_energy, ef=p.ef, target_lon=p.target[0], target_lat=p.target[1], lift_scale=kl,
                  drag_scale=kd, alpha0=alpha0, bank0=p.initial_bank, bank_rate0=p.initial_bank_rate, sign0=p.initial_sign,
                  mach_was_above=float(p.memory[0]), switched=float(p.memory[1]), step_s=p.guidance_step_s,
                  substeps=max(1, int(round(p.guidance_step_s / p.actuator_substep_s))),
                  altitude_floor_m=p.altitude_floor_m, max_time_s=p.max_time_s, alpha_min=p.alpha_min,
                  alpha_max=p.alpha_max, bank_limit=p.vehicle.bank_limit, alpha_rate=p.alpha_rate,
                  bank_rate=p.vehicle.bank_rate_limit, alpha_accel=p.alpha_accel,
                  bank_accel=p.vehicle.bank_accel_limit, bandwidth=2.0, heat_case=float(p.case == "heat"),
                  mach_shift=p.mach_shift, schedule_case=float(p.case == "schedule"),
                  **{f"path_{k}": getattr(path, k) if path is not None else math.inf for k in PATH_LIMIT_FIELDS})
    settings = np.array([float(values[k]) for k in population_flight.SETTINGS])
    sf = np.full(n, p.sigma_f) if sigma_f is None else np.ascontiguousarray(sigma_f, float)
    final, t_end = np.zeros((n, 6)), np.zeros(n)
    reached, peaks, reversals = np.zeros(n, bool), np.zeros((n, 3)), np.zeros(n, np.int64)
    speeds, values = p.alpha_schedule if p.case == "schedule" else ((0.0,), (0.0,))
    module["fly_population"](np.asarray(p.x0, float), np.ascontiguousarray(sigma0), sf, settings,
                             np.asarray(p.reversal_velocity, float), np.asarray(p.reversal_heading, float),
                             np.asarray(speeds, float), np.asarray(values, float),
                             final, t_end, reached, peaks, reversals)
    return final.T, t_end, reached, peaks.T, reversals


def range_error(problem: SwarmProblem, lon, lat):
    """(signed along-track distance beyond the target [m], cross-track [m]) of positions
    [rad], along the great circle from ``origin`` (x0's position by default) to the target."""
    R = problem.planet.reference_radius
    lon0, lat0 = problem.origin if problem.origin is not None else (problem.x0[1], problem.x0[2])
    tlon, tlat = problem.target
    d, c = downtrack_crosstrack(np.atleast_1d(lon), np.atleast_1d(lat), lon0, lat0, tlon, tlat, R)
    d_target, _ = downtrack_crosstrack(np.array([tlon]), np.array([tlat]), lon0, lat0, tlon, tlat, R)
    return d - d_target[0], c
