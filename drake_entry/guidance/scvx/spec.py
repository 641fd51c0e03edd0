"""Scenario spec of paper 001's guidance; YAML tag ``guidance: !Scvx``."""

import dataclasses as dc
import math
from typing import Optional

from drake_entry.errors import FieldError, ScenarioError, check_range
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.settings import EntryProblemSettings, FlightCheck, ScvxSettings
from drake_entry.guidance.spec import ReplanningSpec

__all__ = ["Scvx", "shared_fields"]


@dc.dataclass
class Scvx(ReplanningSpec):
    """An SCvx plan (paper 001) from the entry state to the target's DRS box (eqs. 64-70),
    its bank and angle of attack flown in time through the shared actuators, re-planned from
    the navigation estimate every ``replan_period_s`` (0: the pre-flight plan is flown). The
    entry point is the scenario's ``entry``, the site its ``target`` (both geocentric; the
    mission converts them to paper 001's geodetic form). The mission and planner fields carry
    the names and units of ScvxMission, EntryProblemSettings and ScvxSettings
    (drake_entry/guidance/scvx), which check them."""

    stops_at_altitude = True
    # the closed loop stops on reaching this altitude (the DRS point): a state altitude (above
    # the reference sphere, as the scenario's entry), so on an oblate Earth the DRS window's
    # geodetic altitudes lie higher (at 36.8 deg, 10.5 km geodetic is 2.8 km above the
    # equatorial sphere); terminal_mach is not used to stop
    terminal_altitude_km: float = 10.5
    terminal_mach: float = 0.7
    # DRS box: miss cone radius [m] (eq. 69), geodetic altitude window [m] (eq. 64) and the
    # plan's design margin inside it [m], Mach (eq. 64), vertical speed [m/s] (eq. 65)
    site_radius_m: float = 10e3
    final_altitude_m: list[float] = dc.field(default_factory=lambda: [10e3, 13e3])
    # (None: the formulation's default, 1200 m for the lossless bank, 200 m for a bank state)
    final_altitude_margin_m: Optional[float] = None
    final_mach_max: float = 1.0
    # the DRS point's lowest Mach (0: paper 001's subsonic DRS has none; a TAEM box's lower edge)
    final_mach_min: float = 0.0
    # a plan's flown DRS Mach may exceed final_mach_max by this (0: paper 001's; a derived plan
    # aims inside the box's window, and the box is what the flight is judged by)
    flown_mach_margin: float = 0.0
    final_vertical_speed_min_m_s: float = -140.0
    # the DRS point's highest vertical speed [m/s] (None: paper 001's box has none; a glider's
    # derived box asks a definite descent, so that the altitude stop falls where the plan ends)
    final_vertical_speed_max_m_s: Optional[float] = None
    # path bounds (eq. 70) and the smallest bank magnitude of the lossless bank (eq. 43) [deg]
    flight_path_bounds_deg: list[float] = dc.field(default_factory=lambda: [-30.0, 0.5])
    heading_bounds_deg: list[float] = dc.field(default_factory=lambda: [-10.0, 270.0])
    bank_min_deg: float = 5.0
    # alpha(V) law [deg] (high speed, low speed) blended between the two speeds [m/s]; the
    # bounds [deg] and rate limit [deg/s] of a planned alpha
    alpha_deg: list[float] = dc.field(default_factory=lambda: [40.0, 25.0])
    alpha_speeds_m_s: list[float] = dc.field(default_factory=lambda: [2000.0, 5000.0])
    alpha_bounds_deg: list[float] = dc.field(default_factory=lambda: [15.0, 45.0])
    alpha_rate_limit_deg_s: float = 1.0
    # the alpha actuator's acceleration limit [deg/s^2] the plans are flown with (not in paper
    # 001: a labelled choice well above what its 1 deg/s alpha rate needs)
    alpha_accel_limit_deg_s2: float = 5.0
    # planner: formulation (direct | direct_bank | hybrid | lossless), objective (Table 2),
    # Lobatto mesh, SCvx iteration cap and SOCP solver (clarabel | scs)
    formulation: str = "direct"
    objective: str = "heat_load"
    segments: int = 33
    nodes_per_segment: int = 4
    # design margins of the plans flown (not the paper's): heat flux and load this fraction
    # inside the vehicle's limits at the nodes, gamma this far [deg] inside the flight-path
    # bounds (above the lower, below the upper), |bank| this far [deg] inside the vehicle's
    # limit, so that the closed loop, dispersed, holds the limits its verdict checks (None:
    # EntryProblemSettings' defaults: 0.02, [1.0, 0.2] deg, 2 deg); the heat-flux and load
    # margin grows from 0 at a plan's first node to its value this far into the plan [s] (a
    # re-plan starts where the vehicle is, possibly riding a limit; None: 60 s)
    path_margin: Optional[float] = None
    path_margin_ramp_s: Optional[float] = None
    flight_path_margins_deg: Optional[list[float]] = None
    bank_margin_deg: Optional[float] = None
    max_iterations: int = 100
    solver: str = "clarabel"

    def mission(self, scenario) -> ScvxMission:
        """The ScvxMission: entry state and target from the scenario (geocentric, converted to
        paper 001's geodetic form), the rest from this spec."""
        t = scenario.target
        fields = {k: getattr(self, k) for k in shared_fields(self, ScvxMission)}  # a margin may be None
        fields.update({k: tuple(v) for k, v in fields.items() if isinstance(v, list)})  # ScvxMission's pairs
        return _named(lambda: ScvxMission.from_geocentric(
            scenario.make_planet(), scenario.initial_state(), math.radians(t.longitude_deg),
            math.radians(t.latitude_deg), name=scenario.name, **fields))

    def flight_check(self) -> FlightCheck:
        """How the plans are verified: flown through the closed loop's actuators at the guidance
        period with the guidance's command lead and its feedback between re-plans."""
        return FlightCheck(period_s=self.period_s, lead_s=self.command_lead_s, feedback=self.feedback,
                           alpha_acceleration_deg_s2=self.alpha_accel_limit_deg_s2,
                           feedback_state_weight=self.feedback_state_weight,
                           feedback_offset_limits=self.feedback_offset_limits())

    def planner_settings(self) -> tuple[EntryProblemSettings, ScvxSettings]:
        given = {k: getattr(self, k) for k in shared_fields(self, EntryProblemSettings) if getattr(self, k) is not None}
        return (_named(lambda: EntryProblemSettings(**given)),
                _named(lambda: ScvxSettings.for_solver(self.solver, max_iterations=self.max_iterations)))

    def path_limits(self, scenario) -> list:
        """The flight-path-angle bounds of eq. 70 (flight_path_bounds_deg), held in flight."""
        return [self.mission(scenario).flight_path_limit()]

    def validate(self, scenario) -> None:
        super().validate(scenario)
        self.mission(scenario)
        self.planner_settings()
        check_range("guidance.alpha_accel_limit_deg_s2", self.alpha_accel_limit_deg_s2, 1e-3, 1000.0)
        if self.terminal_mach > self.final_mach_max:
            raise ScenarioError(f"guidance.terminal_mach = {self.terminal_mach} exceeds guidance.final_mach_max = "
                                f"{self.final_mach_max}")


def shared_fields(spec, settings_class) -> list[str]:
    """The spec's fields that ``settings_class`` has under the same name (the spec passes them on;
    max_iterations and solver go to ScvxSettings.for_solver)."""
    theirs = {f.name for f in dc.fields(settings_class)}
    return [f.name for f in dc.fields(spec) if f.name in theirs and f.name not in ("max_iterations", "solver")]


def _named(build):
    """build(), a FieldError of the settings it builds re-raised naming the spec's field
    ('guidance.x'), the field the user wrote."""
    try:
        return build()
    except FieldError as e:
        raise e.under("guidance") from None
