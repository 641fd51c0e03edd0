"""Scenario-spec pieces every guidance method shares (pure data; YAML schema fields).

A method's spec is a dataclass deriving from ``GuidanceSpecBase`` (or ``ReversingBankSpec``
when it commands a bank magnitude and lets the shared reversal logic choose the sign); the
scenario's ``guidance:`` field selects it with the YAML tag ``!ClassName``.
"""

import dataclasses as dc

from drake_entry.errors import ScenarioError, check_range


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
