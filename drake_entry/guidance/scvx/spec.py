"""Scenario spec of paper 001's guidance; YAML tag ``guidance: !Scvx``."""

import dataclasses as dc

from ...errors import ScenarioError, check_range
from ..spec import GuidanceSpecBase

#: EntryProblemSettings formulations and objectives (planning/scvx/entry.py; checked there too)
FORMULATIONS = ("direct", "direct_bank", "hybrid", "lossless")


@dc.dataclass
class Scvx(GuidanceSpecBase):
    """An SCvx plan (paper 001) from the entry state to the target's DRS box (eqs. 64-70),
    its bank and angle of attack flown in time through the shared actuators, re-planned from
    the navigation estimate every ``replan_period_s`` (0: the pre-flight plan is flown). The
    entry point is the scenario's ``entry``, the site its ``target`` (both geocentric; the
    mission converts them to paper 001's geodetic form)."""

    stops_at_altitude = True
    # the closed loop stops on reaching this altitude (the DRS point): a state altitude (above
    # the reference sphere, as the scenario's entry), so on an oblate Earth the DRS window's
    # geodetic altitudes lie higher (at 36.8 deg, 10.5 km geodetic is 2.8 km above the
    # equatorial sphere); terminal_mach is not used to stop
    terminal_altitude_km: float = 10.5
    terminal_mach: float = 0.7
    # DRS box: geodetic altitude window [km] (eq. 64), Mach (eq. 65), vertical speed (eq. 66),
    # miss cone radius (eq. 68), and the plan's design margin inside the altitude window [m]
    drs_altitude_km: list[float] = dc.field(default_factory=lambda: [10.0, 13.0])
    drs_mach_max: float = 1.0
    drs_vertical_speed_min_m_s: float = -140.0
    site_radius_km: float = 10.0
    drs_altitude_margin_m: float = 500.0
    # path bounds (eq. 70) and the smallest bank magnitude of the lossless bank (eq. 43) [deg]
    flight_path_bounds_deg: list[float] = dc.field(default_factory=lambda: [-30.0, 0.5])
    heading_bounds_deg: list[float] = dc.field(default_factory=lambda: [-10.0, 270.0])
    bank_min_deg: float = 5.0
    # alpha(V) law [deg] (high speed, low speed) blended between the two speeds [m/s]; the
    # bounds [deg] and rate limit [deg/s] of a planned alpha
    alpha_deg: list[float] = dc.field(default_factory=lambda: [40.0, 25.0])
    alpha_speeds_m_s: list[float] = dc.field(default_factory=lambda: [2000.0, 5000.0])
    alpha_bounds_deg: list[float] = dc.field(default_factory=lambda: [15.0, 45.0])
    alpha_rate_deg_s: float = 1.0
    # planner: formulation (direct | direct_bank | hybrid | lossless), objective (Table 2),
    # Lobatto mesh, SCvx iteration cap and SOCP solver (clarabel | scs)
    formulation: str = "direct"
    objective: str = "heat_load"
    segments: int = 33
    nodes_per_segment: int = 4
    max_iterations: int = 60
    solver: str = "clarabel"
    # on-board re-planning from the navigation estimate every replan_period_s [s] (0 = fly the
    # pre-flight plan), while the plan in use has more than replan_min_time_to_go_s to go
    replan_period_s: float = 0.0
    replan_min_time_to_go_s: float = 300.0

    def validate(self, scenario) -> None:
        super().validate(scenario)
        for name, lo, hi in (("drs_altitude_km", 0.0, 100.0), ("flight_path_bounds_deg", -89.0, 30.0),
                             ("heading_bounds_deg", -360.0, 720.0), ("alpha_speeds_m_s", 0.0, 12e3),
                             ("alpha_bounds_deg", 0.0, 60.0)):
            v = list(getattr(self, name))
            if len(v) != 2 or not lo <= v[0] < v[1] <= hi:
                raise ScenarioError(f"guidance.{name} = {v} needs two values {lo:g} <= low < high <= {hi:g}")
        if len(self.alpha_deg) != 2:
            raise ScenarioError(f"guidance.alpha_deg = {list(self.alpha_deg)} needs two angles (high speed, low speed)")
        for v in self.alpha_deg:
            check_range("guidance.alpha_deg", v, 0.0, 60.0)
        check_range("guidance.drs_mach_max", self.drs_mach_max, 0.1, 10.0)
        check_range("guidance.drs_vertical_speed_min_m_s", self.drs_vertical_speed_min_m_s, -2000.0, 0.0)
        check_range("guidance.site_radius_km", self.site_radius_km, 1e-3, 5000.0)
        check_range("guidance.drs_altitude_margin_m", self.drs_altitude_margin_m, 0.0,
                    490.0 * (self.drs_altitude_km[1] - self.drs_altitude_km[0]))
        check_range("guidance.bank_min_deg", self.bank_min_deg, 0.0, 45.0)
        check_range("guidance.alpha_rate_deg_s", self.alpha_rate_deg_s, 1e-3, 90.0)
        if self.formulation not in FORMULATIONS:
            raise ScenarioError(f"guidance.formulation = {self.formulation!r}; allowed: {', '.join(FORMULATIONS)}")
        check_range("guidance.segments", self.segments, 1, 2000)
        check_range("guidance.nodes_per_segment", self.nodes_per_segment, 2, 12)
        check_range("guidance.max_iterations", self.max_iterations, 1, 10000)
        if self.solver not in ("clarabel", "scs"):
            raise ScenarioError(f"guidance.solver = {self.solver!r}; allowed: clarabel, scs")
        check_range("guidance.replan_period_s", self.replan_period_s, 0.0, 1e4)
        if self.replan_period_s and self.replan_period_s < self.period_s:
            raise ScenarioError(f"guidance.replan_period_s = {self.replan_period_s} must be 0 or >= guidance.period_s "
                                f"= {self.period_s}")
        check_range("guidance.replan_min_time_to_go_s", self.replan_min_time_to_go_s, 0.0, 1e4)
        if self.terminal_mach > self.drs_mach_max:
            raise ScenarioError(f"guidance.terminal_mach = {self.terminal_mach} exceeds guidance.drs_mach_max = "
                                f"{self.drs_mach_max}")
