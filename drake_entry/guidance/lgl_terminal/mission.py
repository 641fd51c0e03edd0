"""Paper 002's mission as the terminal guidance flies it: the problem file's conditions on the
scenario's vehicle, planet, entry state and target, its path constraints planned inside their
bounds, and those bounds as flown limits (pure data: loading a scenario imports no solver)."""
from __future__ import annotations

import dataclasses as dc
import math

from drake_entry.errors import ScenarioError
from drake_entry.models.verdict import PathLimit
from drake_entry.planning.ocp import PATH_QUANTITIES
from drake_entry.planning.ocp_yaml import load_problem

__all__ = ["load_guidance_problem", "problem_for_scenario", "mission_path_limits"]


def load_guidance_problem(spec):
    """The spec's OptimalControlProblem as its file states it (controls must be 'rates')."""
    problem, _ = load_problem(spec.problem)
    if problem.controls != "rates":
        raise ScenarioError(f"guidance.problem '{spec.problem}' has controls '{problem.controls}'; the terminal "
                            f"guidance flies alpha and bank states: controls must be 'rates'")
    return problem


def problem_for_scenario(spec, scenario, *, margin: bool = True):
    """The problem flown: the scenario's vehicle, planet, atmosphere and entry state, its target as
    the final longitude and latitude, the spec's final flight-path angle when given, the path
    constraints ``spec.path_margin`` inside their bounds (``margin=False``: as the file gives
    them, the bounds the verdict checks); the rest (final speed and alpha, bounds, objective)
    from the problem file."""
    p = load_guidance_problem(spec)
    x0 = scenario.initial_state()
    initial = dict(p.initial)
    initial.update({n: float(v) for n, v in zip(("h", "lon", "lat", "V", "gamma", "psi"), x0)})
    final = dict(p.final)
    final.update(h=scenario.guidance.terminal_altitude_km * 1e3, lon=math.radians(scenario.target.longitude_deg),
                 lat=math.radians(scenario.target.latitude_deg))
    if spec.final_flight_path_deg is not None:
        final["gamma"] = math.radians(spec.final_flight_path_deg)
    path = [_inside(c, spec.path_margin) for c in p.path] if margin else list(p.path)
    return dc.replace(p, vehicle=scenario.make_vehicle(), planet=scenario.make_planet(),
                      atmosphere=scenario.make_atmosphere(), initial=initial, final=final, path=path,
                      name=f"{scenario.name}_{p.name}")


def _inside(c, margin: float):
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
        out.append(PathLimit(f"path_{c.label}", column, upper=c.max, lower=c.min, unit=unit))
    return out
