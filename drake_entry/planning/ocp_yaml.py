"""Optimal-control problems from YAML (``drake-entry optimize PROBLEM.yaml``).

Schema (units in the field names; a boundary entry is {value} fixed, {min, max}
bounded, or absent = free):

  name: marv
  vehicle: marv                 # packaged vehicle or YAML path; aero: optional model name
  mass_over_area_kg_m2: 1000.0  # optional override of m/S
  planet: {model: spherical, rotating: true, j2: false, radius_m: 6378145.0}   # as in scenarios
  atmosphere: {model: exponential, rho0_kg_m3: 1.225, scale_height_m: 7200.0}  # (default us76)
  controls: rates               # rates (alpha, sigma states; u_alpha, u_sigma controls) | direct
                                # | bank_rate (alpha over time; sigma, t states; u_sigma control)
  alpha_schedule: {breakpoints_s: [58, 88], values_deg: [42, 17.5]}   # bank_rate only; or
                  # {variable: velocity | energy | mach, breakpoints: [...] (m/s, J/kg, -), values_deg, smooth}
  initial: {altitude_km: {value: 37.0}, ...}
  final: {...}
  final_time_s: {min: 100.0, max: 2000.0}     # or {value: ...}
  state_bounds: {alpha_deg: {min: 0.0, max: 25.0}, ...}
  control_bounds: {alpha_rate_deg_s: {min: -10, max: 10}, bank_rate_deg_s: {...}}
  path: [{quantity: dynamic_pressure, min: 12000.0}, {quantity: sensed_acceleration, max: 45.0}]
  terminal: [{quantity: geodetic_altitude, min: 21000.0, max: 26000.0}]   # final node only
  objective: [{kind: control_margin, weight: 1.0, k: [1, 18, 20]}, ...]
  solve: {transcription: lgl, solver: snopt, nodes: 125, tolerance: 1.0e-7, coarse_nodes: 60}
"""
import dataclasses as dc
import math
import os
from importlib import resources
from typing import Dict, List, Optional

from drake_entry.errors import ScenarioError
from drake_entry.models.environment import AtmosphereSpec, PlanetSpec, atmosphere_from_spec, planet_from_spec
from drake_entry.models.schedules import VARIABLES, Schedule
from drake_entry.models.vehicles import load_vehicle
from drake_entry.planning.ocp import (
    CONTROL_LAYOUTS,
    DEVIATION_STATES,
    ObjectiveTerm,
    OptimalControlProblem,
    PathConstraint,
)
from drake_entry.typed_yaml import load_yaml_typed

__all__ = ["STATE_FIELDS", "CONTROL_FIELDS", "PACKAGED_PROBLEMS", "BoundSpec", "PathSpec", "AlphaScheduleSpec",
           "ObjectiveSpec", "SolveSpec", "ProblemSpec", "problem_from_spec", "load_problem_spec", "validate_solve",
           "load_problem"]

# YAML field -> (state or control name, factor to SI)
STATE_FIELDS = {"altitude_km": ("h", 1e3), "longitude_deg": ("lon", math.pi / 180), "latitude_deg": ("lat", math.pi / 180),
                "velocity_m_s": ("V", 1.0), "flight_path_deg": ("gamma", math.pi / 180),
                "heading_deg": ("psi", math.pi / 180), "alpha_deg": ("alpha", math.pi / 180),
                "bank_deg": ("sigma", math.pi / 180), "time_s": ("t", 1.0)}
CONTROL_FIELDS = {"alpha_rate_deg_s": ("u_alpha", math.pi / 180), "bank_rate_deg_s": ("u_sigma", math.pi / 180),
                  "alpha_deg": ("alpha", math.pi / 180), "bank_deg": ("sigma", math.pi / 180)}
PACKAGED_PROBLEMS = ("marv", "shefex3")


@dc.dataclass
class BoundSpec:
    value: Optional[float] = None
    min: Optional[float] = None
    max: Optional[float] = None


@dc.dataclass
class PathSpec:
    quantity: str = ""
    min: Optional[float] = None
    max: Optional[float] = None
    scale: Optional[float] = None  # the row's typical size (default: the finite bound)


@dc.dataclass
class AlphaScheduleSpec:
    """alpha [deg] over time (``breakpoints_s``) or, with ``variable`` velocity, energy or
    mach, over ``breakpoints`` in m/s, J/kg (central gravity) or Mach; ``smooth``: the
    quintic blend between breakpoints (models.schedules.Schedule)."""

    variable: str = "time"
    breakpoints_s: List[float] = dc.field(default_factory=list)
    breakpoints: List[float] = dc.field(default_factory=list)
    values_deg: List[float] = dc.field(default_factory=list)
    smooth: bool = False


@dc.dataclass
class ObjectiveSpec:
    kind: str = ""
    weight: float = 1.0
    k: List[float] = dc.field(default_factory=lambda: [1.0, 18.0, 20.0])
    alpha_bar_deg: Optional[float] = None
    alpha_max_deg: float = 25.0
    alpha_rate_max_deg_s: float = 10.0
    bank_rate_max_deg_s: float = 30.0
    target_longitude_deg: Optional[float] = None
    target_latitude_deg: Optional[float] = None
    scale: float = 1.0
    bank_max_deg: float = 60.0  # bank_effort
    rate_weight: float = 0.1  # bank_effort
    bank_centre_deg: float = 0.0  # bank_effort: the bank magnitude the effort is measured from
    # terminal_deviation (paper 003 eq. 1): state field (altitude_km, ...) -> reference / weight
    reference: Dict[str, float] = dc.field(default_factory=dict)
    weights: Dict[str, float] = dc.field(default_factory=dict)
    units: str = "si"  # terminal_deviation: si (rad, m, m/s) | canonical (h / R, V / sqrt(mu / R))


@dc.dataclass
class SolveSpec:
    transcription: str = "lgl"  # lgl | dircol (Drake DirectCollocation) | hermite_simpson (the same NLP, vectorised)
    solver: str = "auto"  # auto (SNOPT when available, else Ipopt) | snopt | ipopt
    nodes: int = 40
    # lgl only: equal LGL segments sharing their end nodes ((nodes - 1) a multiple of
    # segments, >= 3 nodes each; 1 = one global polynomial, paper 002)
    segments: int = 1
    tolerance: float = 1.0e-8
    max_iterations: int = 3000
    # solve first on this many nodes (lgl: one polynomial) and start from that solution (0 = propagated guess)
    coarse_nodes: int = 0
    # mesh refinement: raise the node count from `nodes` until the between-node error meets
    # the verification tolerance (nlp.mesh), up to max_nodes (0 = the transcription's default)
    refine: bool = False
    max_nodes: int = 0
    # the verification's tolerances (relative, GPOPS-II form; nlp.verify): between the nodes,
    # and the controls flown by the Drake Simulator
    dynamics_tolerance: float = 1.0e-3
    propagation_tolerance: float = 1.0e-2


@dc.dataclass
class ProblemSpec:
    name: str = "problem"
    description: str = ""
    source: str = ""
    vehicle: str = ""
    aero: str = ""
    mass_over_area_kg_m2: Optional[float] = None
    planet: PlanetSpec = dc.field(default_factory=PlanetSpec)
    # initial.altitude_km above the reference sphere (the state altitude) or the WGS-84
    # ellipsoid (geodetic, at the fixed initial latitude; an oblate planet); a geodetic final
    # altitude is a terminal constraint: {quantity: geodetic_altitude, min, max}
    altitude_datum: str = "sphere"
    atmosphere: AtmosphereSpec = dc.field(default_factory=AtmosphereSpec)
    controls: str = "rates"
    alpha_schedule: Optional[AlphaScheduleSpec] = None
    initial: Dict[str, BoundSpec] = dc.field(default_factory=dict)
    final: Dict[str, BoundSpec] = dc.field(default_factory=dict)
    final_time_s: BoundSpec = dc.field(default_factory=BoundSpec)
    state_bounds: Dict[str, BoundSpec] = dc.field(default_factory=dict)
    control_bounds: Dict[str, BoundSpec] = dc.field(default_factory=dict)
    path: List[PathSpec] = dc.field(default_factory=list)
    terminal: List[PathSpec] = dc.field(default_factory=list)
    objective: List[ObjectiveSpec] = dc.field(default_factory=list)
    solve: SolveSpec = dc.field(default_factory=SolveSpec)


def _bound(where: str, b: BoundSpec, factor: float, *, allow_free: bool = True):
    for name in ("value", "min", "max"):
        v = getattr(b, name)
        if v is not None and (v != v or (name == "value" and math.isinf(v)) or (name == "min" and v == math.inf)
                              or (name == "max" and v == -math.inf)):
            raise ScenarioError(f"{where}.{name} = {v} is not allowed: a finite number"
                                + ("" if name == "value" else " (or omit the bound)"))
    if b.value is not None:
        if b.min is not None or b.max is not None:
            raise ScenarioError(f"{where}: give either value or min/max, not both")
        return b.value * factor
    if b.min is None and b.max is None:
        if allow_free:
            return None
        raise ScenarioError(f"{where}: needs value or min/max")
    lo = -math.inf if b.min is None else b.min * factor
    hi = math.inf if b.max is None else b.max * factor
    if not lo <= hi:
        raise ScenarioError(f"{where}: min {b.min} > max {b.max}")
    return (lo, hi)


def _field(where: str, key: str, fields: dict, allowed: tuple) -> tuple:
    """(state or control name, factor to SI) of YAML field ``key``; a one-line error naming
    the allowed fields otherwise."""
    if key not in fields or fields[key][0] not in allowed:
        names = [k for k, (n, _) in fields.items() if n in allowed]
        raise ScenarioError(f"{where}.{key}: unknown field; allowed: {', '.join(names)}")
    return fields[key]


def _named(where: str, specs: dict, fields: dict, allowed: tuple) -> dict:
    out = {}
    for key, b in specs.items():
        name, factor = _field(where, key, fields, allowed)
        v = _bound(f"{where}.{key}", b, factor)
        if v is not None:
            out[name] = v
    return out


def _deviation_fields(where: str, values: dict, *, convert: bool) -> dict:
    """terminal_deviation's {YAML state field: value} as {state: value} (SI when ``convert``)."""
    out = {}
    for key, v in values.items():
        name, factor = _field(where, key, STATE_FIELDS, DEVIATION_STATES)
        out[name] = v * factor if convert else v
    return out


def _constraints(where: str, specs: list) -> list:
    out = []
    for i, c in enumerate(specs):
        try:
            out.append(PathConstraint(c.quantity, -math.inf if c.min is None else c.min,
                                      math.inf if c.max is None else c.max, scale=c.scale))
        except ValueError as e:
            raise ScenarioError(f"{where}[{i}]: {e}") from None
    return out


def _alpha_schedule(a: AlphaScheduleSpec) -> Schedule:
    """The Schedule of an ``alpha_schedule:`` block; one line naming the field otherwise."""
    if a.variable not in VARIABLES:
        raise ScenarioError(f"alpha_schedule.variable = '{a.variable}' is unknown; allowed: {', '.join(VARIABLES)}")
    time = a.variable == "time"
    given, other = ("breakpoints_s", "breakpoints") if time else ("breakpoints", "breakpoints_s")
    if getattr(a, other):
        raise ScenarioError(f"alpha_schedule.{other}: not with variable '{a.variable}'; give {given}")
    try:
        return Schedule(tuple(float(v) for v in getattr(a, given)), tuple(math.radians(v) for v in a.values_deg),
                        a.variable, bool(a.smooth))
    except ValueError as e:
        raise ScenarioError(f"alpha_schedule: {e}") from None


def problem_from_spec(spec: ProblemSpec) -> OptimalControlProblem:
    """OptimalControlProblem of a ProblemSpec (SI inside); one-line ScenarioError on bad input."""
    if spec.controls not in CONTROL_LAYOUTS:
        raise ScenarioError(f"controls = '{spec.controls}'; allowed: {', '.join(CONTROL_LAYOUTS)}")
    if (spec.controls == "bank_rate") != (spec.alpha_schedule is not None):
        raise ScenarioError("alpha_schedule: give it exactly with controls: bank_rate (alpha scheduled)")
    schedule = None
    if spec.alpha_schedule is not None:
        schedule = _alpha_schedule(spec.alpha_schedule)
    vehicle = load_vehicle(spec.vehicle, aero=spec.aero or None)
    if spec.mass_over_area_kg_m2 is not None:
        if not 0 < spec.mass_over_area_kg_m2 <= 1e5:
            raise ScenarioError(f"mass_over_area_kg_m2 = {spec.mass_over_area_kg_m2}; allowed (0, 1e5]")
        vehicle = dc.replace(vehicle, mass=spec.mass_over_area_kg_m2 * vehicle.reference_area)
    planet = planet_from_spec(spec.planet)
    atmosphere = atmosphere_from_spec(spec.atmosphere)
    layout = OptimalControlProblem.layout_names(spec.controls)
    states, controls = layout
    tf = _bound("final_time_s", spec.final_time_s, 1.0, allow_free=False)
    initial = _named("initial", spec.initial, STATE_FIELDS, states)
    if spec.altitude_datum not in ("sphere", "ellipsoid"):
        raise ScenarioError(f"altitude_datum = '{spec.altitude_datum}' is unknown; allowed: sphere, ellipsoid")
    if spec.altitude_datum == "ellipsoid":
        if spec.planet.model != "oblate":
            raise ScenarioError("altitude_datum 'ellipsoid' needs planet.model 'oblate' (a sphere has one datum)")
        if "altitude_km" in spec.final:
            raise ScenarioError("final.altitude_km with altitude_datum 'ellipsoid': give the geodetic final altitude "
                                "as terminal: [{quantity: geodetic_altitude, min, max}] (metres)")
        if not all(isinstance(initial.get(k), float) for k in ("h", "lat")):
            raise ScenarioError("altitude_datum 'ellipsoid' needs a fixed initial altitude_km and latitude_deg")
        initial["h"] = planet.state_altitude(initial["h"], initial["lat"])
    terms = []
    for i, o in enumerate(spec.objective):
        target = None
        if o.target_longitude_deg is not None and o.target_latitude_deg is not None:
            target = (math.radians(o.target_longitude_deg), math.radians(o.target_latitude_deg))
        try:
            terms.append(ObjectiveTerm(kind=o.kind, weight=o.weight, k=tuple(o.k),
                                       alpha_bar=None if o.alpha_bar_deg is None else math.radians(o.alpha_bar_deg),
                                       alpha_max=math.radians(o.alpha_max_deg),
                                       u_alpha_max=math.radians(o.alpha_rate_max_deg_s),
                                       u_sigma_max=math.radians(o.bank_rate_max_deg_s), target=target, scale=o.scale,
                                       bank_max=math.radians(o.bank_max_deg), rate_weight=o.rate_weight,
                                       bank_centre=math.radians(o.bank_centre_deg),
                                       reference=_deviation_fields(f"objective[{i}].reference", o.reference,
                                                                   convert=True) or None,
                                       weights=_deviation_fields(f"objective[{i}].weights", o.weights,
                                                                 convert=False) or None,
                                       units=o.units))
        except ValueError as e:
            raise ScenarioError(f"objective[{i}]: {e}") from None
    try:
        return OptimalControlProblem(
            vehicle=vehicle, planet=planet, atmosphere=atmosphere, controls=spec.controls, alpha_schedule=schedule,
            initial=initial,
            final=_named("final", spec.final, STATE_FIELDS, states), final_time=tf,
            state_bounds=_named("state_bounds", spec.state_bounds, STATE_FIELDS, states),
            control_bounds=_named("control_bounds", spec.control_bounds, CONTROL_FIELDS, controls),
            path=_constraints("path", spec.path), terminal=_constraints("terminal", spec.terminal),
            objective=terms, name=spec.name)
    except ValueError as e:
        raise ScenarioError(f"problem '{spec.name}': {e}") from None


def load_problem_spec(name_or_path: str) -> ProblemSpec:
    if name_or_path in PACKAGED_PROBLEMS:
        text = resources.files("drake_entry").joinpath(f"problems/{name_or_path}.yaml").read_text()
        return load_yaml_typed(ProblemSpec, text=text, where=f"problem '{name_or_path}'")
    if os.path.exists(name_or_path):
        return load_yaml_typed(ProblemSpec, path=name_or_path)
    raise ScenarioError(f"problem '{name_or_path}' is neither a packaged problem ({', '.join(PACKAGED_PROBLEMS)}) "
                        f"nor a file")


def validate_solve(s: SolveSpec) -> SolveSpec:
    """One-line ScenarioError on a bad ``solve:`` field."""
    for field, allowed in (("transcription", ("lgl", "dircol", "hermite_simpson")), ("solver", ("auto", "ipopt", "snopt"))):
        if getattr(s, field) not in allowed:
            raise ScenarioError(f"solve.{field} = '{getattr(s, field)}' is unknown; allowed: {', '.join(allowed)}")
    for field, lo in (("nodes", 3), ("segments", 1), ("max_iterations", 1), ("coarse_nodes", 0), ("max_nodes", 0)):
        v = getattr(s, field)
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise ScenarioError(f"solve.{field} = {v} is out of range; allowed: an integer >= {lo}")
    for field in ("tolerance", "dynamics_tolerance", "propagation_tolerance"):
        if not 0 < getattr(s, field) < 1:
            raise ScenarioError(f"solve.{field} = {getattr(s, field)} is out of range; allowed (0, 1)")
    return s


def load_problem(name_or_path: str) -> tuple[OptimalControlProblem, SolveSpec]:
    """(problem, solve settings) from a packaged name ('marv') or a YAML path."""
    spec = load_problem_spec(name_or_path)
    return problem_from_spec(spec), validate_solve(spec.solve)
