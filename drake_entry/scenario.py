"""Scenario files: dataclass schemas read with ``pydrake.common.yaml.yaml_load_typed``.

Packaged scenarios live in ``drake_entry/scenarios/*.yaml`` (horus2b, shefex3, cav_h,
marv); ``load_scenario(name_or_path)`` reads either. Fields not in SI carry their unit
in the name. Every bad value raises a one-line ``ScenarioError`` naming the field and the
allowed range.
"""
import dataclasses as dc
import os
from importlib import resources
from typing import Optional

import numpy as np

from .atmosphere import US76_H_MAX, US76_H_MIN, Atmosphere, ExponentialAtmosphere, US76Atmosphere
from .errors import ScenarioError, load_yaml_typed
from .planet import Earth
from .schedules import VARIABLES, Schedule
from .vehicles import Vehicle, load_vehicle


@dc.dataclass
class EntryStateSpec:
    """Entry-interface state (paper 000 Table 1 layout)."""

    altitude_km: float = 0.0
    longitude_deg: float = 0.0
    latitude_deg: float = 0.0
    velocity_m_s: float = 0.0
    flight_path_deg: float = 0.0
    # heading from north, clockwise
    heading_deg: float = 0.0


@dc.dataclass
class TargetSpec:
    """Target site (runway or TAEM interface point)."""

    longitude_deg: float = 0.0
    latitude_deg: float = 0.0


@dc.dataclass
class TerminalSpec:
    """Terminal interface: the run stops at the first condition reached; tolerances are
    the mission's acceptance box (paper 000 Table 1)."""

    altitude_km: Optional[float] = None
    mach: Optional[float] = None
    velocity_m_s: Optional[float] = None
    energy_MJ_kg: Optional[float] = None
    altitude_tolerance_km: float = 0.0
    mach_tolerance: float = 0.0
    distance_tolerance_km: float = 0.0


@dc.dataclass
class PlanetSpec:
    # spherical | oblate
    model: str = "spherical"
    rotating: bool = True
    j2: bool = False


@dc.dataclass
class AtmosphereSpec:
    # us76 | exponential
    model: str = "us76"
    # exponential model only (paper 000 eq. 29)
    rho0_kg_m3: float = 1.2256
    scale_height_m: float = 7200.0


@dc.dataclass
class ScheduleSpec:
    """Piecewise-linear command: values [deg] at breakpoints of ``variable``
    (time s | energy J/kg | mach | velocity m/s)."""

    variable: str = "time"
    breakpoints: list[float] = dc.field(default_factory=lambda: [0.0])
    values_deg: list[float] = dc.field(default_factory=lambda: [0.0])
    smooth: bool = False


@dc.dataclass
class SimulationSpec:
    # hard stop [s] if no terminal condition triggers
    max_time_s: float = 3000.0
    # runge_kutta5 | runge_kutta3 | radau3
    integrator: str = "runge_kutta5"
    accuracy: float = 1e-8
    max_step_s: float = 10.0
    # trajectory sample period for logs and plots [s]
    log_period_s: float = 1.0


@dc.dataclass
class Scenario:
    """A mission: vehicle, environment, entry interface, target, terminal interface,
    open-loop command schedules and simulation settings."""

    name: str = ""
    description: str = ""
    source: str = ""
    vehicle: str = ""
    # which aero model of the vehicle file ('' = its default)
    aero: str = ""
    planet: PlanetSpec = dc.field(default_factory=PlanetSpec)
    atmosphere: AtmosphereSpec = dc.field(default_factory=AtmosphereSpec)
    entry: EntryStateSpec = dc.field(default_factory=EntryStateSpec)
    target: TargetSpec = dc.field(default_factory=TargetSpec)
    terminal: TerminalSpec = dc.field(default_factory=TerminalSpec)
    alpha: ScheduleSpec = dc.field(default_factory=ScheduleSpec)
    bank: ScheduleSpec = dc.field(default_factory=ScheduleSpec)
    simulation: SimulationSpec = dc.field(default_factory=SimulationSpec)

    # -- models ----------------------------------------------------------------------
    def make_vehicle(self) -> Vehicle:
        return load_vehicle(self.vehicle, aero=self.aero or None)

    def make_planet(self) -> Earth:
        p = self.planet
        if p.model == "spherical":
            return Earth.spherical(rotating=p.rotating, j2=p.j2)
        if p.model == "oblate":
            return Earth.oblate(omega=Earth().omega if p.rotating else 0.0, j2=Earth().j2 if p.j2 else 0.0)
        raise ScenarioError(f"planet.model '{p.model}' is unknown; allowed: spherical, oblate")

    def make_atmosphere(self) -> Atmosphere:
        a = self.atmosphere
        if a.model == "us76":
            return US76Atmosphere()
        if a.model == "exponential":
            try:
                return ExponentialAtmosphere(a.rho0_kg_m3, a.scale_height_m)
            except ValueError as e:
                raise ScenarioError(f"atmosphere: {e}") from None
        raise ScenarioError(f"atmosphere.model '{a.model}' is unknown; allowed: us76, exponential")

    def initial_state(self) -> np.ndarray:
        """Entry state x0 = [h, lon, lat, V, gamma, psi] in SI / rad."""
        e = self.entry
        return np.array([e.altitude_km * 1e3, np.radians(e.longitude_deg), np.radians(e.latitude_deg),
                         e.velocity_m_s, np.radians(e.flight_path_deg), np.radians(e.heading_deg)])

    def schedule(self, which: str) -> Schedule:
        s = getattr(self, which)
        try:
            return Schedule(tuple(s.breakpoints), tuple(np.radians(s.values_deg)), s.variable, s.smooth)
        except ValueError as e:
            raise ScenarioError(f"{which}: {e}") from None

    def validate(self) -> "Scenario":
        """Check every field against its allowed range; return self."""
        _range("entry.altitude_km", self.entry.altitude_km, US76_H_MIN / 1e3, US76_H_MAX / 1e3)
        _range("entry.velocity_m_s", self.entry.velocity_m_s, 1.0, 12000.0)
        _range("entry.flight_path_deg", self.entry.flight_path_deg, -89.0, 89.0)
        _range("entry.latitude_deg", self.entry.latitude_deg, -89.0, 89.0)
        _range("entry.longitude_deg", self.entry.longitude_deg, -360.0, 360.0)
        _range("entry.heading_deg", self.entry.heading_deg, -360.0, 360.0)
        _range("target.latitude_deg", self.target.latitude_deg, -90.0, 90.0)
        _range("target.longitude_deg", self.target.longitude_deg, -360.0, 360.0)
        t = self.terminal
        if all(v is None for v in (t.altitude_km, t.mach, t.velocity_m_s, t.energy_MJ_kg)):
            raise ScenarioError("terminal: give at least one of altitude_km, mach, velocity_m_s, energy_MJ_kg")
        if t.altitude_km is not None:
            _range("terminal.altitude_km", t.altitude_km, 0.0, self.entry.altitude_km)
        if t.mach is not None:
            _range("terminal.mach", t.mach, 0.0, 50.0)
        sim = self.simulation
        _range("simulation.max_time_s", sim.max_time_s, 1.0, 1e5)
        _range("simulation.accuracy", sim.accuracy, 1e-14, 1e-1)
        _range("simulation.max_step_s", sim.max_step_s, 1e-4, 1e3)
        _range("simulation.log_period_s", sim.log_period_s, 1e-3, 1e3)
        if sim.integrator not in INTEGRATORS:
            raise ScenarioError(f"simulation.integrator '{sim.integrator}' is unknown; allowed: {', '.join(INTEGRATORS)}")
        for which in ("alpha", "bank"):
            if getattr(self, which).variable not in VARIABLES:
                raise ScenarioError(f"{which}.variable '{getattr(self, which).variable}' is unknown; "
                                    f"allowed: {', '.join(VARIABLES)}")
            self.schedule(which)
        self.make_planet()
        self.make_atmosphere()
        if not self.vehicle:
            raise ScenarioError("vehicle: missing; give a packaged vehicle name or a vehicle YAML path")
        try:
            self.make_vehicle()
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        return self


INTEGRATORS = ("runge_kutta5", "runge_kutta3", "radau3")


def _range(field: str, value, lo: float, hi: float):
    if value is None or not (lo <= value <= hi):
        raise ScenarioError(f"{field} = {value} is out of range; allowed [{lo:g}, {hi:g}]")


PACKAGED_SCENARIOS = ("horus2b", "shefex3", "cav_h", "marv")


def load_scenario(name_or_path: str) -> Scenario:
    """Read and validate a scenario: a packaged name or a YAML file path."""
    if name_or_path in PACKAGED_SCENARIOS:
        text = resources.files("drake_entry").joinpath(f"scenarios/{name_or_path}.yaml").read_text()
        scenario = load_yaml_typed(Scenario, text=text, where=f"scenario '{name_or_path}'")
    elif os.path.exists(name_or_path):
        scenario = load_yaml_typed(Scenario, path=name_or_path)
    else:
        raise ScenarioError(f"scenario '{name_or_path}' is neither a packaged scenario "
                            f"({', '.join(PACKAGED_SCENARIOS)}) nor a file")
    return scenario.validate()
