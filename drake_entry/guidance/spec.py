"""Scenario-spec pieces every guidance method shares (pure data; YAML schema fields).

A method's spec is a dataclass deriving from ``GuidanceSpecBase`` (or ``ReversingBankSpec``
when it commands a bank magnitude and lets the shared reversal logic choose the sign); the
scenario's ``guidance:`` field selects it with the YAML tag ``!ClassName``.
"""

import dataclasses as dc
import math

from drake_entry.errors import ScenarioError, check_range

__all__ = ["MAX_REPLAN_PERIOD_S", "MAX_REPLAN_LATENCY_S", "MAX_REPLAN_LATENCY_FACTOR", "check_replanning",
           "check_alpha_in_speed",
           "GuidanceSpecBase", "ReplansOnBoard", "ReversingBankSpec", "ReplanningSpec"]

#: the longest on-board re-planning period [s]
MAX_REPLAN_PERIOD_S = 1e4
#: the longest guidance computing latency [s] and latency factor (x the measured wall time)
MAX_REPLAN_LATENCY_S, MAX_REPLAN_LATENCY_FACTOR = 600.0, 1e3


def check_replanning(spec) -> None:
    """The one rule of the on-board re-planning fields of every method that plans on board
    (``ReplansOnBoard``; systems/replan_scheduler.py): ``replan_period_s`` is 0 (no re-plan after
    the first plan) or from the guidance period ``period_s`` to MAX_REPLAN_PERIOD_S seconds;
    ``replan_latency_s`` and ``replan_latency_factor`` are finite and >= 0."""
    value, period = spec.replan_period_s, spec.period_s
    if not (isinstance(value, (int, float)) and (value == 0 or period <= value <= MAX_REPLAN_PERIOD_S)):
        shown = value if not isinstance(value, float) or math.isfinite(value) else str(value)
        raise ScenarioError(f"guidance.replan_period_s = {shown} is out of range; allowed: 0 (no re-plan after the "
                            f"first plan) or from guidance.period_s = {period} to {MAX_REPLAN_PERIOD_S:g} s")
    check_range("guidance.replan_latency_s", spec.replan_latency_s, 0.0, MAX_REPLAN_LATENCY_S)
    check_range("guidance.replan_latency_factor", spec.replan_latency_factor, 0.0, MAX_REPLAN_LATENCY_FACTOR)


def check_alpha_in_speed(alpha_deg, speeds_m_s, lowest_deg: float, highest_deg: float) -> None:
    """The one rule of an alpha schedule in speed (``guidance.alpha_deg`` at
    ``guidance.alpha_velocity_m_s``, linear between them): one alpha per speed, at least one, the
    speeds increasing, every alpha in [lowest_deg, highest_deg]."""
    if not alpha_deg or len(alpha_deg) != len(speeds_m_s):
        raise ScenarioError(f"guidance.alpha_deg has {len(alpha_deg)} values and guidance.alpha_velocity_m_s "
                            f"{len(speeds_m_s)}: an alpha schedule in speed needs one alpha per speed, at least one")
    if any(b <= a for a, b in zip(speeds_m_s, speeds_m_s[1:])):
        raise ScenarioError(f"guidance.alpha_velocity_m_s = {speeds_m_s} must increase")
    for a in alpha_deg:
        check_range("guidance.alpha_deg", a, lowest_deg, highest_deg)


@dc.dataclass
class GuidanceSpecBase:
    """Fields of every guidance method."""

    #: the closed loop stops at the terminal energy (False) or on reaching the terminal altitude
    #: (True: a mission whose terminal box is an altitude window, e.g. paper 001's DRS)
    stops_at_altitude = False

    # guidance terminal interface: the closed loop stops at the (central-gravity) energy of
    # this altitude and Mach, and its terminal errors are measured there
    terminal_altitude_km: float = 25.0
    terminal_mach: float = 2.5
    # guidance and control update period [s] (navigation, guidance, actuator sampling)
    period_s: float = 1.0

    def terminal_speed(self, speed_of_sound: float) -> float:
        """V_f [m/s] of the terminal interface given the speed of sound there [m/s] (a method
        whose mission gives V_f rather than Mach overrides this)."""
        return self.terminal_mach * speed_of_sound

    def alpha_profile(self) -> tuple[str, list[float], list[float]] | None:
        """The angle-of-attack profile this method flies when it is a fixed schedule of its own
        (variable, breakpoints, values [deg]; the scenario's ``alpha`` block's variables), else
        None: another method flying this mission takes it as the mission's alpha
        (drake_entry.guidance.derivation)."""
        return None

    def path_limits(self, scenario) -> list:
        """The mission's own path limits (drake_entry.models.verdict.PathLimit) that every flight must
        hold besides the vehicle's; none by default."""
        return []

    def validate(self, scenario) -> None:
        """Raise a one-line ScenarioError on a bad field (``scenario`` gives the context)."""
        check_range("guidance.period_s", self.period_s, 0.01, 60.0)
        check_range("guidance.terminal_altitude_km", self.terminal_altitude_km, 0.0, scenario.entry.altitude_km)
        check_range("guidance.terminal_mach", self.terminal_mach, 0.1, 30.0)


@dc.dataclass
class ReplansOnBoard(GuidanceSpecBase):
    """A method that plans on board (systems/replan_scheduler.py: drag-energy, SCvx, LGL terminal,
    the swarm bank re-solved on board, FNPEG's corrector): one re-plan concept, one rule
    (``check_replanning``)."""

    # on-board re-planning from the navigation estimate every replan_period_s [s] (0: no re-plan
    # after the first plan)
    replan_period_s: float = 0.0
    # guidance computing latency: a plan computed from the estimate at t flies from t +
    # replan_latency_s [s] (a flight computer's stated time) + replan_latency_factor x its measured
    # wall time on this machine (which makes rows depend on the machine; 0 = applied at once)
    replan_latency_s: float = 0.0
    replan_latency_factor: float = 0.0

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_replanning(self)

    def latency(self) -> dict:
        """The latency arguments of the method's guidance system."""
        return {"latency_s": self.replan_latency_s, "latency_factor": self.replan_latency_factor}


@dc.dataclass
class ReversingBankSpec(GuidanceSpecBase):
    """A method that commands |sigma| and flies it with the shared bank-reversal logic
    (heading-error corridor, paper 000 Sec. VI.D; systems.bank_reversal)."""

    # heading-error corridor half-width [deg], linear in speed between the two velocities [m/s]
    reversal_heading_deg: list[float] = dc.field(default_factory=lambda: [5.0, 15.0])
    reversal_velocity_m_s: list[float] = dc.field(default_factory=lambda: [1000.0, 6000.0])

    def validate(self, scenario) -> None:
        super().validate(scenario)
        if len(self.reversal_heading_deg) != 2 or len(self.reversal_velocity_m_s) != 2:
            raise ScenarioError("guidance.reversal_heading_deg and reversal_velocity_m_s need two values each")
        if not self.reversal_velocity_m_s[0] < self.reversal_velocity_m_s[1]:
            raise ScenarioError(f"guidance.reversal_velocity_m_s = {self.reversal_velocity_m_s} must be increasing")
        for v in self.reversal_heading_deg:
            check_range("guidance.reversal_heading_deg", v, 1e-3, 180.0)


@dc.dataclass
class ReplanningSpec(ReplansOnBoard):
    """A method whose plans are flown in time through the shared actuators and re-planned on
    board from the navigation estimate (systems/replanning_guidance.py: paper 001's SCvx, paper
    002's LGL)."""

    # each command is read this far ahead on the plan [s]: the actuators' lag (half the guidance
    # period for the hold, 1/bandwidth for the loop: 1.0 s at 1 s with the 2 rad/s loop)
    command_lead_s: float = 1.0
    # on-board re-planning (replan_period_s) only while the plan in use has more than
    # replan_min_time_to_go_s [s] to go
    replan_min_time_to_go_s: float = 300.0
    # the re-plan period shrinks to this fraction of the time to go (never below period_s; 0:
    # every replan_period_s): re-plans come closer together as the end nears
    replan_time_to_go_fraction: float = 0.0
    # re-plans predict with the nominal lift and drag times the low-passed ratios of the sensed to
    # the modelled accelerations (a density, aerodynamic or mass error the flight has shown;
    # models.acceleration_ratios)
    replan_model_scales: bool = False
    # between re-plans the commands track the plan in use: "tvlqr" (a time-varying LQR of the
    # plan's linearised dynamics, planning.tracking; the plans are then verified flown with it)
    # or "none" (its controls in time only; a method may offer more: FEEDBACKS);
    # feedback_state_weight: the LQR's path weight (TrackingWeights.entry_commands); the
    # feedback's bank and alpha offsets are bounded by the two limits [deg]
    feedback: str = "none"
    feedback_state_weight: float = 1.0e-3
    feedback_bank_limit_deg: float = 30.0
    feedback_alpha_limit_deg: float = 5.0

    #: the feedback kinds the method offers
    FEEDBACKS = ("tvlqr", "none")

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_range("guidance.command_lead_s", self.command_lead_s, 0.0, 10.0)
        check_range("guidance.replan_min_time_to_go_s", self.replan_min_time_to_go_s, 0.0, 1e4)
        check_range("guidance.replan_time_to_go_fraction", self.replan_time_to_go_fraction, 0.0, 1.0)
        if self.feedback not in self.FEEDBACKS:
            raise ScenarioError(f"guidance.feedback = '{self.feedback}' is unknown; allowed: {', '.join(self.FEEDBACKS)}")
        check_range("guidance.feedback_state_weight", self.feedback_state_weight, 1e-9, 1e3)
        check_range("guidance.feedback_bank_limit_deg", self.feedback_bank_limit_deg, 0.0, 180.0)
        check_range("guidance.feedback_alpha_limit_deg", self.feedback_alpha_limit_deg, 0.0, 45.0)

    def feedback_offset_limits(self) -> tuple[float, float]:
        """The feedback's bank and alpha offset bounds [rad]."""
        return math.radians(self.feedback_bank_limit_deg), math.radians(self.feedback_alpha_limit_deg)
