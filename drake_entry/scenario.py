"""Scenario files: dataclass schemas read with ``pydrake.common.yaml.yaml_load_typed``.

Packaged scenarios live in ``drake_entry/scenarios/*.yaml`` (horus2b, shefex3, shefex3_ampi, cav_h,
cav_h_paper004, sphynx_paper001, marv); ``load_scenario(name_or_path)`` reads either. Fields not in SI carry their unit
in the name. Every bad value raises a one-line ``ScenarioError`` naming the field and the
allowed range.
"""
import dataclasses as dc
import math
from typing import Optional

import numpy as np

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance import REGISTRY, GuidanceSpec, known_tags
from drake_entry.models import dispersions as disp
from drake_entry.models.atmosphere import US76_H_MAX, US76_H_MIN, Atmosphere
from drake_entry.models.environment import AtmosphereSpec, PlanetSpec, atmosphere_from_spec, planet_from_spec
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import VARIABLES, Schedule
from drake_entry.models.vehicles import Vehicle, load_vehicle
from drake_entry.models.verdict import BOX_CRITERIA, PathLimit, acceptance_box, vehicle_path_limits
from drake_entry.typed_yaml import check_numbers, load_packaged_or_file, override, packaged_names

__all__ = ["RENAMED_GUIDANCE_FIELDS", "upgrade_scenario_yaml", "scenario_from_dump", "EntryStateSpec", "TargetSpec", "TerminalSpec", "SuccessRequirementSpec", "ScheduleSpec", "unstated_guidance", "stated_guidance", "PLANTS", "SimulationSpec",
           "ReferenceResultsSpec", "ERROR_COLUMNS", "Scenario", "INTEGRATORS", "SCHEDULE_VALUES_DEG",
           "SCHEDULE_BREAKPOINTS", "PACKAGED_SCENARIOS", "closed_loop_scenarios", "load_scenario", "apply_overrides",
           "load_campaign_scenario"]


@dc.dataclass
class EntryStateSpec:
    """Entry-interface state (paper 000 Table 1 layout)."""

    altitude_km: float = 0.0  # geometric altitude above the reference sphere
    longitude_deg: float = 0.0  # geocentric longitude
    latitude_deg: float = 0.0  # geocentric latitude
    velocity_m_s: float = 0.0  # Earth-relative speed
    flight_path_deg: float = 0.0  # Earth-relative flight-path angle, + up
    # heading from north, clockwise
    heading_deg: float = 0.0


@dc.dataclass
class TargetSpec:
    """Target site (runway or TAEM interface point)."""

    longitude_deg: float = 0.0  # geocentric longitude
    latitude_deg: float = 0.0  # geocentric latitude


@dc.dataclass
class TerminalSpec:
    """Terminal interface: an open-loop run stops at the first condition reached. The
    tolerances are the mission's acceptance box (paper 000 Table 1): a closed-loop flight
    is a success only inside every box criterion given (altitude, Mach, speed, flight-path
    angle and angle of attack about the values given, distance to the target); a criterion
    without its tolerance is not checked (drake_entry.models.verdict.BOX_CRITERIA)."""

    altitude_km: Optional[float] = None  # stop altitude (open loop) and the box centre
    mach: Optional[float] = None  # stop Mach number and the box centre
    velocity_m_s: Optional[float] = None  # stop speed (open loop)
    # specific energy E = V^2/2 - mu/r [MJ/kg] (negative: bound to the planet)
    energy_MJ_kg: Optional[float] = None
    altitude_tolerance_km: Optional[float] = None  # acceptance box: |h - altitude_km| <= this
    mach_tolerance: Optional[float] = None  # acceptance box: |M - mach| <= this
    distance_tolerance_km: Optional[float] = None  # acceptance box: distance to the target <= this
    velocity_tolerance_m_s: Optional[float] = None  # acceptance box: |V - velocity_m_s| <= this
    # terminal flight-path angle and angle of attack [deg] and their acceptance windows (+- deg)
    flight_path_deg: Optional[float] = None
    flight_path_tolerance_deg: Optional[float] = None
    alpha_deg: Optional[float] = None
    alpha_tolerance_deg: Optional[float] = None
    # terminal vertical speed V sin(gamma) [m/s] and its window (+- m/s), e.g. paper 001 eq. 65
    vertical_speed_m_s: Optional[float] = None
    vertical_speed_tolerance_m_s: Optional[float] = None
    # terminal geodetic altitude [km] and its window (+- km), whatever the scenario's altitude
    # datum (paper 001 eq. 64's DRS window is geodetic on a sphere-datum scenario)
    geodetic_altitude_km: Optional[float] = None
    geodetic_altitude_tolerance_km: Optional[float] = None
    # where each requirement comes from, by its name (a box criterion: altitude, mach, distance,
    # velocity, flight_path, alpha, vertical_speed, geodetic_altitude; a path limit: its name and
    # '_limit', e.g. heat_flux_limit, flight_path_limit): the report's requirement table prints it,
    # and a requirement that departs from its source says so here ("departure: ...")
    requirement_sources: dict[str, str] = dc.field(default_factory=dict)
    # what the source requires that this box does not judge, each with why (the report's
    # requirement table lists them as NOT JUDGED)
    departures: dict[str, str] = dc.field(default_factory=dict)
    # relative tolerance on every path limit (vehicle and mission): a limit counts as held up to
    # limit + this x |limit|, at every log sample and integrator step; 0: a limit is a limit
    path_limit_tolerance: float = 0.0


@dc.dataclass
class SuccessRequirementSpec:
    """The success probability a campaign of this mission must show, at a confidence
    (drake_entry.campaign.success_requirement; none: the report gives the bounds only)."""

    probability: Optional[float] = None  # e.g. 0.9973 (3 sigma); in (0, 1)
    confidence: float = 0.9  # of the one-sided Clopper-Pearson lower bound; in (0.5, 1)
    source: Optional[str] = None  # where the required probability comes from (the report's source column)

    def validate(self) -> None:
        """Each field in its range (ScenarioError naming it); an unstated probability passes."""
        if self.probability is not None and not 0.0 < self.probability < 1.0:
            raise ScenarioError(f"success_requirement.probability = {self.probability}: allowed in (0, 1), e.g. 0.9973")
        if not 0.5 < self.confidence < 1.0:
            raise ScenarioError(f"success_requirement.confidence = {self.confidence}: allowed in (0.5, 1), e.g. 0.9")
        if self.source is not None and not str(self.source).strip():
            raise ScenarioError("success_requirement.source is empty: say where the required probability comes from")


@dc.dataclass
class ScheduleSpec:
    """Piecewise-linear command: values [deg] at breakpoints of ``variable``
    (time s | energy J/kg | mach | velocity m/s)."""

    variable: str = "time"  # time | energy | mach | velocity
    # values of the variable (s, J/kg, -, m/s), increasing
    breakpoints: list[float] = dc.field(default_factory=lambda: [0.0])
    values_deg: list[float] = dc.field(default_factory=lambda: [0.0])  # command at each breakpoint
    smooth: bool = False  # quintic smoothstep between breakpoints (C2) instead of straight lines


#: the plant realisations ``simulation.plant`` names (systems/native_plant.add_plant builds them)
PLANTS = ("auto", "native", "python")


@dc.dataclass
class SimulationSpec:
    # hard stop [s] if no terminal condition triggers
    max_time_s: float = 3000.0
    # runge_kutta5 | runge_kutta3 | radau3
    integrator: str = "runge_kutta5"
    # error-control accuracy (also the witness-function localisation accuracy)
    accuracy: float = 1e-8
    max_step_s: float = 10.0  # largest integration step [s] (error-controlled runs)
    # closed-loop flights only: a fixed integration step [s] (0 = the error-controlled settings
    # above). A closed loop samples its fast dynamics (bank actuator, guidance, control) at the
    # guidance period, so a step dividing that period is exact at every event; open-loop
    # diagrams keep the continuous bank actuator, whose 8 rad/s loop needs error control.
    closed_loop_step_s: float = 0.0
    # trajectory sample period for logs and plots [s]
    log_period_s: float = 1.0
    # the plant's realisation: auto (native when every model has a symbolic form, else python) |
    # native (vehicle, air data and flight conditions evaluated by Drake in C++ from the models'
    # symbolic form; an aerodynamic table has none) | python (the reference LeafSystems)
    plant: str = "auto"


@dc.dataclass
class ReferenceResultsSpec:
    """Published Monte-Carlo statistics that a campaign's report puts beside its own (the
    terminal errors' mean and 1-sigma); empty: the report shows the campaign alone."""

    # where the numbers come from, e.g. "paper 000 Table 3"
    source: str = ""
    # row column (err_altitude_m, err_longitude_deg, err_latitude_deg, err_velocity_m_s,
    # err_range_m, err_crossrange_m, err_distance_m) -> [mean, 1-sigma] in its unit
    errors: dict[str, list[float]] = dc.field(default_factory=dict)
    # why the campaign's figures may differ from the published ones (printed under the comparison)
    note: str = ""


#: the terminal-error columns of a campaign row (reference results may give them; the report's order)
ERROR_COLUMNS = ("err_altitude_m", "err_longitude_deg", "err_latitude_deg", "err_velocity_m_s", "err_range_m",
                 "err_crossrange_m", "err_distance_m")


def unstated_guidance():
    """The guidance of a scenario that states no ``guidance:`` block: the first registered
    method's defaults, marked as not stated (``stated_guidance``)."""
    spec = next(iter(REGISTRY))()
    spec.unstated = True  # an attribute, not a field: never written to YAML
    return spec


def stated_guidance(scenario):
    """The guidance block ``scenario`` states, or None when its file states none (it flies the
    first registered method's defaults; a dumped scenario states what it flies)."""
    g = scenario.guidance
    return None if g is None or getattr(g, "unstated", False) else g


@dc.dataclass
class Scenario:
    """A mission: vehicle, environment, entry interface, target, terminal interface,
    open-loop command schedules and simulation settings."""

    #: fields naming a file: a relative path is read beside the scenario file (typed_yaml.resolve_file_fields)
    FILE_FIELDS = ('vehicle',)

    # a packaged scenario name, or a YAML path (relative to this file), whose every field this
    # file starts from: the file then states only what it changes (blocks merge field by field)
    based_on: str = ""
    name: str = ""  # short identifier, used in file names and reports
    description: str = ""  # one line for humans
    source: str = ""  # where the numbers come from (papers, data files)
    vehicle: str = ""  # packaged vehicle name or a vehicle YAML path (relative: beside this file)
    # which aero model of the vehicle file ('' = its default)
    aero: str = ""
    # the mission's path and bank limits where they differ from the vehicle file's (keys:
    # heat_flux_max_kW_m2, dynamic_pressure_max_kPa, normal_load_max_g, total_load_max_g,
    # bank_limit_deg, bank_rate_limit_deg_s, bank_accel_limit_deg_s2, alpha_rate_limit_deg_s,
    # alpha_accel_limit_deg_s2)
    vehicle_limits: dict[str, float] = dc.field(default_factory=dict)
    planet: PlanetSpec = dc.field(default_factory=PlanetSpec)  # the Earth model
    # what entry.altitude_km and terminal.altitude_km are measured from: 'sphere' (the state
    # altitude, above the reference sphere) or 'ellipsoid' (geodetic altitude above WGS-84, the
    # atmosphere's altitude; an oblate planet); latitudes stay geocentric either way
    altitude_datum: str = "sphere"
    atmosphere: AtmosphereSpec = dc.field(default_factory=AtmosphereSpec)  # the atmosphere model
    entry: EntryStateSpec = dc.field(default_factory=EntryStateSpec)  # entry-interface state
    target: TargetSpec = dc.field(default_factory=TargetSpec)  # target site (runway or TAEM point)
    terminal: TerminalSpec = dc.field(default_factory=TerminalSpec)  # terminal interface and the acceptance box
    # the success probability a campaign must show, and at what confidence (optional)
    success_requirement: SuccessRequirementSpec = dc.field(default_factory=SuccessRequirementSpec)
    # open-loop angle-of-attack schedule (a guidance method may command alpha instead)
    alpha: ScheduleSpec = dc.field(default_factory=ScheduleSpec)
    # open-loop bank schedule (open-loop runs; guidance replaces it in closed loop)
    bank: ScheduleSpec = dc.field(default_factory=ScheduleSpec)
    simulation: SimulationSpec = dc.field(default_factory=SimulationSpec)  # integrator, stop time and logging
    # the guidance method, selected by YAML tag (!DragEnergy, !BankProfile, ...; the
    # registry in drake_entry/guidance); untagged = drag-energy
    guidance: GuidanceSpec = dc.field(default_factory=unstated_guidance)
    # published campaign statistics for the report to compare with (optional)
    reference_results: ReferenceResultsSpec = dc.field(default_factory=ReferenceResultsSpec)
    # Monte-Carlo dispersions (Drake schema distributions: !Uniform, !Gaussian, ...)
    dispersions: disp.DispersionSpec = dc.field(default_factory=disp.DispersionSpec)

    # -- models ----------------------------------------------------------------------
    def loaded_from(self, data: dict) -> None:
        """After loading a file: a ``guidance:`` block it states is stated, even when it names the
        default method (the loader then fills the default in place: ``stated_guidance``)."""
        if isinstance(data, dict) and data.get("guidance") is not None:
            vars(self.guidance).pop("unstated", None)

    def make_vehicle(self) -> Vehicle:
        return load_vehicle(self.vehicle, aero=self.aero or None, limits=self.vehicle_limits)

    def make_planet(self) -> Earth:
        return planet_from_spec(self.planet)

    def make_atmosphere(self) -> Atmosphere:
        return atmosphere_from_spec(self.atmosphere)

    def path_limits(self, vehicle: Vehicle | None = None) -> list[PathLimit]:
        """The path limits every flight must hold (drake_entry.models.verdict): the vehicle's heat
        flux, dynamic pressure, loads and bank limit, then the guidance spec's mission limits.
        ``vehicle``: the already built vehicle (default: ``make_vehicle()``)."""
        v = self.make_vehicle() if vehicle is None else vehicle
        return vehicle_path_limits(v.limits, v.bank_limit) + list(self.guidance.path_limits(self))

    def _check_requirement_sources(self) -> None:
        """Every key of terminal.requirement_sources names a box criterion or a path limit
        ('<limit>_limit': a limit another guidance block brings may be named, e.g. SCvx's
        flight_path_limit on a mission another method flies) (ScenarioError listing the allowed
        names otherwise)."""
        names = [c.name for c in BOX_CRITERIA] + [f"{lim.name}_limit" for lim in self.path_limits()]
        for key, text in self.terminal.requirement_sources.items():
            if key not in names and not key.endswith("_limit"):
                raise ScenarioError(f"terminal.requirement_sources: '{key}' names no requirement of this scenario; "
                                    f"allowed: {', '.join(names)} (or another path limit's name and '_limit')")
            if not str(text).strip():
                raise ScenarioError(f"terminal.requirement_sources.{key} is empty: say where the requirement comes from")
        for requirement, why in self.terminal.departures.items():
            if not str(requirement).strip() or not str(why).strip():
                raise ScenarioError(f"terminal.departures: '{requirement}' needs the requirement and why it is not "
                                    "judged, both non-empty")

    def initial_state(self) -> np.ndarray:
        """Entry state x0 = [h, lon, lat, V, gamma, psi] in SI / rad (h: the state altitude,
        converted from the geodetic entry altitude with altitude_datum 'ellipsoid')."""
        e = self.entry
        h = e.altitude_km * 1e3
        if self.altitude_datum == "ellipsoid":
            h = self.make_planet().state_altitude(h, np.radians(e.latitude_deg))
        return np.array([h, np.radians(e.longitude_deg), np.radians(e.latitude_deg),
                         e.velocity_m_s, np.radians(e.flight_path_deg), np.radians(e.heading_deg)])

    def acceptance_box(self, planet: Earth, x, *, mach: float, distance_m: float, alpha_rad: float = math.nan) -> dict:
        """The acceptance box (drake_entry.models.verdict.acceptance_box) at a final state ``x``
        [h, lon, lat, V, gamma, ...] on ``planet``: the altitude geodetic with altitude_datum
        'ellipsoid', else the state altitude; speed and flight-path angle from ``x``; the Mach
        number, the distance to the target [m] and the angle of attack [rad] as measured (an
        alpha criterion with no alpha given is missed)."""
        geodetic = float(planet.atmospheric_altitude(x[0], x[2]))
        h = geodetic if self.altitude_datum == "ellipsoid" else x[0]
        return acceptance_box(self.terminal, altitude_m=float(h), mach=float(mach), distance_m=float(distance_m),
                              velocity_m_s=float(x[3]), flight_path_rad=float(x[4]), alpha_rad=float(alpha_rad),
                              vertical_speed_m_s=float(x[3] * math.sin(x[4])), geodetic_altitude_m=geodetic)

    def entry_energy(self) -> float:
        """Specific energy at the entry interface [J/kg] (central gravity, eq. 37 convention)."""
        x0 = self.initial_state()
        return float(self.make_planet().with_(j2=0.0).specific_energy(x0[0], x0[3]))

    def guidance_terminal_state(self) -> tuple[float, float, float]:
        """(h_f [m], V_f [m/s], E_f [J/kg]) of the guidance terminal interface: h_f the state
        altitude (with altitude_datum 'ellipsoid' the guidance's geodetic terminal altitude
        converted at the target's latitude), the speed of sound where the atmosphere is read
        there (``air_altitude``)."""
        g = self.guidance
        altitude = g.terminal_altitude_km * 1e3
        V = g.terminal_speed(float(self.make_atmosphere().speed_of_sound(self.air_altitude(altitude))))
        planet = self.make_planet()
        h = (float(planet.state_altitude(altitude, np.radians(self.target.latitude_deg)))
             if self.altitude_datum == "ellipsoid" else altitude)
        return h, V, float(planet.with_(j2=0.0).specific_energy(h, V))

    def air_altitude(self, altitude_m: float) -> float:
        """The altitude [m] the atmosphere is read at, over the target, for ``altitude_m`` in this
        scenario's datum: itself with altitude_datum 'ellipsoid' (geodetic), else the planet's
        atmospheric altitude of that state altitude (itself on a spherical planet; on SPHYNX's
        oblate Earth its 3.83-km state altitude is read at 11.5 km, geodetic, as the plant reads it)."""
        if self.altitude_datum == "ellipsoid":
            return float(altitude_m)
        return float(self.make_planet().atmospheric_altitude(altitude_m, np.radians(self.target.latitude_deg)))

    def schedule(self, which: str) -> Schedule:
        """The alpha or bank schedule in SI; 'normalized_energy' breakpoints
        e = (E0 - E)/(E0 - Ef) are converted to energy [J/kg]."""
        s = getattr(self, which)
        bp, values = list(s.breakpoints), list(np.radians(s.values_deg))
        variable = s.variable
        if variable == "normalized_energy":
            E0, Ef = self.entry_energy(), self.guidance_terminal_state()[2]
            energies = [E0 - e * (E0 - Ef) for e in bp]
            order = np.argsort(energies)
            bp, values = [energies[i] for i in order], [values[i] for i in order]
            variable = "energy"
        try:
            return Schedule(tuple(bp), tuple(values), variable, s.smooth)
        except ValueError as e:
            raise ScenarioError(f"{which}: {e}") from None

    def validate(self) -> "Scenario":
        """Check every field against its allowed range; return self."""
        check_numbers(self)  # a scenario built or changed in Python: no NaN, no infinity but an unbounded default
        if self.altitude_datum not in ("sphere", "ellipsoid"):
            raise ScenarioError(f"altitude_datum = '{self.altitude_datum}' is unknown; allowed: sphere, ellipsoid")
        if self.altitude_datum == "ellipsoid" and self.planet.model != "oblate":
            raise ScenarioError("altitude_datum 'ellipsoid' needs planet.model 'oblate' (a sphere has one datum)")
        check_range("entry.altitude_km", self.entry.altitude_km, US76_H_MIN / 1e3, US76_H_MAX / 1e3)
        check_range("entry.velocity_m_s", self.entry.velocity_m_s, 1.0, 12000.0)
        check_range("entry.flight_path_deg", self.entry.flight_path_deg, -89.0, 89.0)
        check_range("entry.latitude_deg", self.entry.latitude_deg, -89.0, 89.0)
        check_range("entry.longitude_deg", self.entry.longitude_deg, -360.0, 360.0)
        check_range("entry.heading_deg", self.entry.heading_deg, -360.0, 360.0)
        check_range("target.latitude_deg", self.target.latitude_deg, -90.0, 90.0)
        check_range("target.longitude_deg", self.target.longitude_deg, -360.0, 360.0)
        t = self.terminal
        if all(v is None for v in (t.altitude_km, t.mach, t.velocity_m_s, t.energy_MJ_kg)):
            raise ScenarioError("terminal: give at least one of altitude_km, mach, velocity_m_s, energy_MJ_kg")
        if t.altitude_km is not None:
            check_range("terminal.altitude_km", t.altitude_km, 0.0, self.entry.altitude_km)
        if t.mach is not None:
            check_range("terminal.mach", t.mach, 0.0, 50.0)
        if t.velocity_m_s is not None:
            check_range("terminal.velocity_m_s", t.velocity_m_s, 0.0, self.entry.velocity_m_s)
        if t.energy_MJ_kg is not None:  # between rest on the surface and the entry energy
            planet = self.make_planet().with_(j2=0.0)
            check_range("terminal.energy_MJ_kg", t.energy_MJ_kg, planet.specific_energy(0.0, 0.0) / 1e6,
                        self.entry_energy() / 1e6)
        for name in (c.tolerance for c in BOX_CRITERIA):  # every criterion's window, >= 0
            if getattr(t, name) is not None:
                check_range(f"terminal.{name}", getattr(t, name), 0.0, 1e5)
        if t.flight_path_deg is not None:
            check_range("terminal.flight_path_deg", t.flight_path_deg, -90.0, 90.0)
        if t.alpha_deg is not None:
            check_range("terminal.alpha_deg", t.alpha_deg, -90.0, 90.0)
        if t.vertical_speed_m_s is not None:
            check_range("terminal.vertical_speed_m_s", t.vertical_speed_m_s, -1e4, 1e4)
        if t.geodetic_altitude_km is not None:
            check_range("terminal.geodetic_altitude_km", t.geodetic_altitude_km, -1.0, self.entry.altitude_km + 100.0)
        for centre, tol in (("velocity_m_s", "velocity_tolerance_m_s"), ("flight_path_deg", "flight_path_tolerance_deg"),
                            ("alpha_deg", "alpha_tolerance_deg"), ("vertical_speed_m_s", "vertical_speed_tolerance_m_s"),
                            ("geodetic_altitude_km", "geodetic_altitude_tolerance_km")):
            if getattr(t, tol) is not None and getattr(t, centre) is None:
                raise ScenarioError(f"terminal.{tol} is given without terminal.{centre}, the value it is about")
        check_range("terminal.path_limit_tolerance", t.path_limit_tolerance, 0.0, 0.5)
        self.success_requirement.validate()
        for col, v in self.reference_results.errors.items():
            if col not in ERROR_COLUMNS:
                raise ScenarioError(f"reference_results.errors: '{col}' is not a terminal-error column; allowed: "
                                    f"{', '.join(ERROR_COLUMNS)}")
            if len(v) != 2 or not all(np.isfinite(v)) or v[1] < 0:
                raise ScenarioError(f"reference_results.errors.{col} = {v}; allowed: [mean, 1-sigma] with a finite "
                                    "mean and 1-sigma >= 0")
        if not self.vehicle:
            raise ScenarioError("vehicle: missing; give a packaged vehicle name or a vehicle YAML path")
        try:
            self.make_vehicle()
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        self.guidance.validate(self)  # the method's fields (period_s among them) before what depends on them
        self._check_requirement_sources()
        sim = self.simulation
        check_range("simulation.max_time_s", sim.max_time_s, 1.0, 1e5)
        check_range("simulation.accuracy", sim.accuracy, 1e-14, 1e-1)
        check_range("simulation.max_step_s", sim.max_step_s, 1e-4, 1e3)
        check_range("simulation.log_period_s", sim.log_period_s, 1e-3, 1e3)
        check_range("simulation.closed_loop_step_s", sim.closed_loop_step_s, 0.0, 60.0)
        step, period = sim.closed_loop_step_s, self.guidance.period_s
        if step != 0.0 and not (0.0 < step <= period and abs(period / step - round(period / step)) < 1e-9):
            raise ScenarioError(f"simulation.closed_loop_step_s = {step:g} s must be 0 (error control) or divide "
                                f"guidance.period_s = {period:g} s (e.g. {period:g}, {period / 2:g}, {period / 4:g})")
        if sim.plant not in PLANTS:
            raise ScenarioError(f"simulation.plant '{sim.plant}' is unknown; allowed: {', '.join(PLANTS)}")
        if sim.integrator not in INTEGRATORS:
            raise ScenarioError(f"simulation.integrator '{sim.integrator}' is unknown; allowed: {', '.join(INTEGRATORS)}")
        for which in ("alpha", "bank"):
            spec = getattr(self, which)
            for field in ("breakpoints", "values_deg"):
                for i, v in enumerate(getattr(spec, field)):
                    if not np.isfinite(v):
                        raise ScenarioError(f"{which}.{field}[{i}] = {v} is not a finite number")
            lo, hi = SCHEDULE_VALUES_DEG[which]
            for i, v in enumerate(spec.values_deg):
                check_range(f"{which}.values_deg[{i}]", v, lo, hi)
            if spec.variable in SCHEDULE_BREAKPOINTS:
                lo, hi = SCHEDULE_BREAKPOINTS[spec.variable]
                for i, v in enumerate(spec.breakpoints):
                    check_range(f"{which}.breakpoints[{i}] ({spec.variable})", v, lo, hi)
            if getattr(self, which).variable not in VARIABLES + ("normalized_energy",):
                raise ScenarioError(f"{which}.variable '{getattr(self, which).variable}' is unknown; "
                                    f"allowed: {', '.join(VARIABLES)}")
            self.schedule(which)
        self.make_planet()
        self.make_atmosphere()
        try:
            disp.validate(self.dispersions)
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        return self


INTEGRATORS = ("runge_kutta5", "runge_kutta3", "radau3")
# physical ranges of schedule values [deg] and breakpoints (by scheduling variable)
SCHEDULE_VALUES_DEG = {"alpha": (-90.0, 90.0), "bank": (-360.0, 360.0)}
SCHEDULE_BREAKPOINTS = {"time": (-1e5, 1e5), "normalized_energy": (-1.0, 2.0), "mach": (0.0, 100.0),
                        "velocity": (0.0, 3e4), "energy": (-1e8, 0.0)}


#: the scenarios shipped in drake_entry/scenarios (``<name>.yaml``), found in the package
PACKAGED_SCENARIOS = packaged_names("scenarios")


def closed_loop_scenarios() -> list[str]:
    """The packaged scenarios that declare a guidance method (a ``guidance:`` block): those a
    campaign can fly (read without building the schema)."""
    from importlib import resources

    folder = resources.files("drake_entry").joinpath("scenarios")

    def flies(name: str) -> bool:
        lines = folder.joinpath(f"{name}.yaml").read_text().splitlines()
        base = [line.split(":", 1)[1].split("#")[0].strip() for line in lines if line.startswith("based_on:")]
        return any(line.startswith("guidance:") for line in lines) or bool(base and base[0] in PACKAGED_SCENARIOS
                                                                          and flies(base[0]))

    return [n for n in PACKAGED_SCENARIOS if flies(n)]


def load_scenario(name_or_path: str) -> Scenario:
    """Read and validate a scenario: a packaged name or a YAML file path."""
    try:
        scenario = load_packaged_or_file(Scenario, name_or_path, kind="scenario", folder="scenarios")
    except ScenarioError as e:
        if "guidance.method: unknown field" in str(e):  # a scenario written before the method tags
            raise ScenarioError(f"{name_or_path}: guidance 'method:' is now a YAML tag: write "
                                f"'guidance: !DragEnergy' (known: {known_tags()})") from None
        raise
    return scenario.validate()


def apply_overrides(scenario: Scenario, overrides: dict | None):
    """Set dotted fields, e.g. {'guidance.replan_period_s': '0'}, through the same typed checks
    and loader as a scenario file (drake_entry.typed_yaml.override): a string value is read as
    YAML text, as after ``--set FIELD=``; other values are written as YAML first. Then the
    scenario is validated again. Every refusal is one ScenarioError naming the field path."""
    if overrides is None:
        overrides = {}
    if not isinstance(overrides, dict):
        raise ScenarioError(f"overrides must be a mapping of dotted field paths to values, e.g. "
                            f"{{'guidance.period_s': 2.0}}; got {type(overrides).__name__}")
    if not isinstance(scenario, Scenario):
        raise ScenarioError(f"apply_overrides needs a Scenario (load_scenario), got {type(scenario).__name__}")
    for key, value in overrides.items():
        override(scenario, key, value, where="override")
    scenario.validate()


#: guidance fields renamed when every method that re-plans on board got one re-plan concept
#: ({old name: today's}); a scenario stored before (a campaign manifest) is read with today's names
RENAMED_GUIDANCE_FIELDS = {"resolve_period_s": "replan_period_s", "corrector_period_s": "replan_period_s",
                           "resolve_until_e": "replan_until_e", "resolve_scaling": "acceleration_scaling"}


def upgrade_scenario_yaml(text: str) -> str:
    """A stored scenario's YAML (a campaign manifest's ``scenario_yaml``) with the guidance fields
    renamed since it was written (RENAMED_GUIDANCE_FIELDS) under today's names."""
    import re

    for old, new in RENAMED_GUIDANCE_FIELDS.items():
        text = re.sub(rf"^(\s+){old}:", rf"\g<1>{new}:", text, flags=re.MULTILINE)
    return text


def scenario_from_dump(text: str) -> Scenario:
    """A scenario this library wrote (``yaml_dump_typed`` of a validated Scenario: a campaign's
    ``scenario_yaml``, sent to every worker process as text because pydrake's schema distributions
    do not pickle), read back by Drake's loader alone: it was checked once, where it entered."""
    from pydrake.common.yaml import yaml_load_typed

    return yaml_load_typed(schema=Scenario, data=text)


def load_campaign_scenario(scenario_path: str, overrides: dict | None) -> Scenario:
    """The scenario a campaign flies: packaged name or file, with dotted overrides."""
    scenario = load_scenario(scenario_path)
    apply_overrides(scenario, overrides)
    return scenario
