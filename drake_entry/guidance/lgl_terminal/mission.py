"""The terminal guidance's problem on a scenario: a problem file's conditions (paper 002's MaRV
impact) on the scenario's vehicle, planet, entry state and target, or, with ``problem:
mission``, the problem the mission itself poses (its terminal interface, target and vehicle
limits; ``mission_problem``); its path constraints planned inside their bounds, and those
bounds as flown limits (pure data: loading a scenario imports no solver)."""
from __future__ import annotations

import dataclasses as dc
import math

from drake_entry.errors import ScenarioError
from drake_entry.models.verdict import DISPLAY_UNITS, PathLimit
from drake_entry.planning.ocp import PATH_QUANTITIES, ObjectiveTerm, OptimalControlProblem, PathConstraint
from drake_entry.planning.ocp_yaml import load_problem

__all__ = ["MISSION", "FLOOR_MARGIN_M", "FLOOR_SPEED_SCALE_M_S", "FLOOR_LABEL", "InterfaceFloor",
           "without_interface_floor", "GAMMA_BOUNDS_DEG",
           "load_guidance_problem", "mission_problem", "problem_for_scenario", "inside_bounds", "mission_path_limits"]

#: the ``problem`` value that poses the problem from the mission instead of a file
MISSION = "mission"
#: the interface floor of a mission's plans (``InterfaceFloor``): this far above the terminal
#: altitude [m] while the speed is well above the final speed, closing within about
#: FLOOR_SPEED_SCALE_M_S [m/s] of it
FLOOR_MARGIN_M = 300.0
FLOOR_SPEED_SCALE_M_S = 100.0
#: the floor's path-constraint label (a refusal names it: "path interface_floor at node k")
FLOOR_LABEL = "interface_floor"


@dc.dataclass(frozen=True)
class InterfaceFloor:
    """The altitude a mission's plan keeps above the terminal altitude ``h_f`` [m], where the
    closed loop stops at its first descent through it: h - h_f - m s^2 / (1 + s^2) >= 0 with s =
    (V - V_f) / ``speed_scale`` (smooth; the full ``margin`` m [m] far from the final speed V_f
    [m/s], none at it). Without it an optimum that bleeds speed low rides the terminal altitude
    at its nodes and dips under it between them (Lu 2014's CAV-H in thin air: the flight stopped
    at 28 km 87 s before the plan's end, 190-240 km short). h is the geodetic altitude on
    ``planet`` where the mission's altitudes are geodetic (altitude_datum 'ellipsoid', as the
    closed loop's stop reads it), else (``planet`` None) the state altitude."""

    h_f: float
    v_f: float
    margin: float = FLOOR_MARGIN_M
    speed_scale: float = FLOOR_SPEED_SCALE_M_S
    planet: object | None = None

    def __call__(self, x, u, env):
        s = (x[3] - self.v_f) / self.speed_scale
        h = x[0] if self.planet is None else self.planet.atmospheric_altitude(x[0], x[2])
        return h - self.h_f - self.margin * (s * s) / (1.0 + s * s)


#: the flight-path bounds of a mission's problem [deg] (paper 002 bounds none; a glide stays
#: inside them, and they keep the solver off the heading equation's singularity at -90 deg)
GAMMA_BOUNDS_DEG = (-60.0, 15.0)


def mission_problem(spec, scenario) -> OptimalControlProblem:
    """The terminal problem a mission poses (not in paper 002, which solves its own impact
    problem): from the entry state to the guidance's terminal altitude over the target at the
    spec's ``terminal_velocity_m_s`` (and final flight-path angle and alpha when the spec and the
    box give them), on the scenario's models; alpha and the bank states (paper 002 eq. 6),
    alpha within ``alpha_bounds_deg`` at rates up to ``alpha_rate_deg_s``, the bank within the
    vehicle's limit and rate; the vehicle's heat-flux, dynamic-pressure and load limits (the
    total load where the vehicle limits it, else the normal) as path constraints (eq. 18's
    form); paper 002's control-margin objective (eq. 11, eq. 19's weights) with alpha-bar the
    vehicle's maximum-L/D alpha."""
    vehicle = scenario.make_vehicle()
    limits = vehicle.limits
    kind, load_max = limits.planned_load()
    path = [PathConstraint(q, max=bound) for q, bound in (("heat_flux", limits.heat_flux_max),
                                                          ("dynamic_pressure", limits.dynamic_pressure_max),
                                                          (f"{kind}_load", load_max))
            if math.isfinite(bound)]
    final = {"V": float(spec.terminal_velocity_m_s)}
    if scenario.terminal.alpha_deg is not None:
        final["alpha"] = math.radians(scenario.terminal.alpha_deg)
    alpha_lo, alpha_hi = (math.radians(a) for a in spec.alpha_bounds_deg)
    rate = math.radians(spec.alpha_rate_deg_s)
    bank = vehicle.bank_limit
    objective = ObjectiveTerm("control_margin", alpha_max=alpha_hi, u_alpha_max=rate, u_sigma_max=vehicle.bank_rate_limit)
    return OptimalControlProblem(
        vehicle=vehicle, planet=scenario.make_planet(), atmosphere=scenario.make_atmosphere(), initial={},
        final=final, final_time=(1.0, 2.0e4), objective=[objective], controls="rates",
        state_bounds={"alpha": (alpha_lo, alpha_hi), "sigma": (-bank, bank),
                      "gamma": tuple(math.radians(g) for g in GAMMA_BOUNDS_DEG)},
        control_bounds={"u_alpha": (-rate, rate), "u_sigma": (-vehicle.bank_rate_limit, vehicle.bank_rate_limit)},
        path=path, name=MISSION)


def load_guidance_problem(spec):
    """The spec's OptimalControlProblem as its file states it (controls must be 'rates')."""
    problem, _ = load_problem(spec.problem)
    if problem.controls != "rates":
        raise ScenarioError(f"guidance.problem '{spec.problem}' has controls '{problem.controls}'; the terminal "
                            f"guidance flies alpha and bank states: controls must be 'rates'")
    return problem


def problem_for_scenario(spec, scenario, *, margin: bool = True):
    """The problem flown: the scenario's vehicle, planet, atmosphere and entry state, its target as
    the final longitude and latitude, the spec's final flight-path angle when given (or, with
    ``final_descent_deg``, a final gamma at most its negative, at least GAMMA_BOUNDS_DEG's lower
    bound), with ``problem: mission`` the altitude at or above the terminal altitude all the way
    and an ``InterfaceFloor`` above it (the closed loop stops at its first descent through it),
    the path constraints ``spec.path_margin`` inside their bounds (``margin=False``: as
    the file gives them, the bounds the verdict checks); the rest (final speed and alpha, bounds,
    objective) from the problem file, the bank bounded by the vehicle's bank limit (the
    actuator's). The terminal altitude is geodetic with altitude_datum 'ellipsoid' (the final
    state altitude is its value at the target's latitude)."""
    p = mission_problem(spec, scenario) if spec.problem == MISSION else load_guidance_problem(spec)
    x0 = scenario.initial_state()
    initial = dict(p.initial)
    initial.update({n: float(v) for n, v in zip(("h", "lon", "lat", "V", "gamma", "psi"), x0)})
    final = dict(p.final)
    lat_f = math.radians(scenario.target.latitude_deg)
    # the state altitude at the target of the guidance's terminal altitude (geodetic with
    # altitude_datum 'ellipsoid': SHEFEX-3's 23.5 km is a 5.1-km state altitude at 68.1 N)
    final.update(h=scenario.guidance_terminal_state()[0], lon=math.radians(scenario.target.longitude_deg), lat=lat_f)
    if spec.final_flight_path_deg is not None:
        final["gamma"] = math.radians(spec.final_flight_path_deg)
    elif spec.final_descent_deg is not None:
        final["gamma"] = (math.radians(GAMMA_BOUNDS_DEG[0]), -math.radians(spec.final_descent_deg))
    path = [inside_bounds(c, spec.path_margin) for c in p.path] if margin else list(p.path)
    bounds, planet, vehicle = dict(p.state_bounds), scenario.make_planet(), scenario.make_vehicle()
    # the bank actuator flies |sigma| <= the vehicle's bank limit (systems.actuators.BankActuator):
    # a plan past it is one the closed loop cannot fly (paper 002's problem file allows +-360 deg;
    # in 4 segments SNOPT's MaRV plan banked 268.9 deg, the -91.1 deg it meant, which the actuator
    # clipped to 180 deg: into the ground 36 s later, and the plan was refused)
    lo, hi = bounds.get("sigma", (-math.inf, math.inf))
    bounds["sigma"] = (max(lo, -vehicle.bank_limit), min(hi, vehicle.bank_limit))
    if spec.problem == MISSION:  # the closed loop stops where it first meets the terminal altitude
        # the floor implies the bound at the nodes; the bound is a simple bound the solver keeps
        # every iterate inside (the plans of the measured campaigns were solved with both)
        geodetic = scenario.altitude_datum == "ellipsoid"
        h_stop = scenario.guidance.terminal_altitude_km * 1e3
        # a geodetic floor as a state bound: its lowest state altitude between the entry's and
        # the target's latitudes (the geodetic altitude of a state altitude grows with |lat|)
        bounds["h"] = (min(float(planet.state_altitude(h_stop, lat)) for lat in (initial["lat"], lat_f))
                       if geodetic else final["h"], math.inf)
        path.append(PathConstraint(InterfaceFloor(h_stop, spec.terminal_velocity_m_s, planet=planet if geodetic else None),
                                   min=0.0, scale=FLOOR_MARGIN_M, name=FLOOR_LABEL))
    return dc.replace(p, vehicle=vehicle, planet=planet,
                      atmosphere=scenario.make_atmosphere(), initial=initial, final=final, path=path,
                      state_bounds=bounds, name=f"{scenario.name}_{p.name}")


def without_interface_floor(problem):
    """``problem`` without its ``InterfaceFloor`` path constraint (the same object when it has
    none): the pre-flight plan's first solve (planner.plan_terminal)."""
    path = [c for c in problem.path if c.label != FLOOR_LABEL]
    return problem if len(path) == len(problem.path) else dc.replace(problem, path=path)


def inside_bounds(c, margin: float):
    """Path constraint ``c`` with each finite bound moved ``margin`` (relative) inside."""
    lo = c.min + margin * abs(c.min) if math.isfinite(c.min) else c.min
    hi = c.max - margin * abs(c.max) if math.isfinite(c.max) else c.max
    return dc.replace(c, min=lo, max=hi, name=c.label)


def mission_path_limits(problem) -> list[PathLimit]:
    """The problem's path constraints on flight conditions as flown limits (named 'path_<label>')."""
    out = []
    for c in problem.path:
        if callable(c.quantity) or PATH_QUANTITIES[c.quantity][0] is None:
            continue
        column, unit = PATH_QUANTITIES[c.quantity]
        unit, scale = DISPLAY_UNITS.get(unit, (unit, 1.0))
        out.append(PathLimit(f"path_{c.label}", column, upper=c.max, lower=c.min, unit=unit, scale=scale))
    return out
