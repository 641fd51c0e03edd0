"""Scenario spec of FNPEG (Lu 2014's predictor-corrector); YAML tag ``guidance: !Fnpeg``."""

import dataclasses as dc

from drake_entry.errors import ScenarioError, check_range
from drake_entry.guidance.spec import ReplansOnBoard, ReversingBankSpec, check_alpha_in_speed

__all__ = ["Fnpeg"]


@dc.dataclass
class Fnpeg(ReversingBankSpec, ReplansOnBoard):
    """|sigma| linear in e = mu/r - V^2/2 from sigma_0 (solved on board every
    ``replan_period_s`` by the damped secant on the predicted range error) to
    ``bank_end_deg`` at the terminal energy (or held at sigma_0: ``bank_profile: constant``),
    with Lu's altitude-rate feedback for phugoid damping and path limits; bank sign from the
    shared reversal logic; alpha a profile in velocity. Engages when the sensed aerodynamic acceleration reaches
    ``engage_acceleration_m_s2`` (before: ``bank_before_engagement_deg``)."""

    # the terminal interface (Lu's e_f: altitude and speed); the flight stops at its energy
    terminal_altitude_km: float = 28.0
    terminal_velocity_m_s: float = 2000.0
    # range to go to the scenario's target at e_f [km] (Lu's s_f*; 0 = end at the target)
    final_range_km: float = 0.0
    # the profile: sigma_f fixed [deg] (Lu 2008: 60-70), sigma_0's first guess [deg]
    bank_end_deg: float = 60.0
    # 'linear' (sigma_0 to sigma_f, Lu 2008/2014) or 'constant' (sigma_0 to the end: Lu 2008's
    # comparison profile; bank_end_deg is then unused)
    bank_profile: str = "linear"
    bank_start_guess_deg: float = 45.0
    bank_before_engagement_deg: float = 0.0
    engage_acceleration_m_s2: float = 1.52
    # alpha profile: values [deg] at speeds [m/s] (linear between, held outside)
    alpha_deg: list[float] = dc.field(default_factory=lambda: [10.0])
    alpha_velocity_m_s: list[float] = dc.field(default_factory=lambda: [0.0])
    alpha_rate_deg_s: float = 5.0
    alpha_accel_deg_s2: float = 10.0
    # corrector (Lu 2014; first difference, halvings and cap as in a public implementation)
    # the corrector runs at engagement and then every replan_period_s [s] (0: at engagement only)
    replan_period_s: float = 1.0
    range_tolerance_km: float = 0.1
    max_iterations: int = 15
    max_halvings: int = 10
    first_difference_deg: float = 1.0
    # sigma_0 is held (not corrected) below this speed above V_f [m/s]: dz/dsigma_0 -> 0 at the end
    hold_speed_margin_m_s: float = 300.0
    # the predictions fly the nominal lift and drag times the low-passed sensed/modelled ratios
    # (what the flight has shown of a density or aerodynamic error), else the nominal models
    acceleration_scaling: bool = True
    # predictor: fixed Runge-Kutta 3 step [s]
    predictor_step_s: float = 4.0
    # altitude-rate feedback (Lu 2014 Sec. IV; gains nondimensional, 0 = off)
    damping_gain: float = 20.0
    damping_bank_deg: float = 60.0
    damping_off_margin_m_s: float = 1000.0
    damping_ramp_m_s: float = 1000.0
    path_gain: float = 0.0
    path_horizon_s: float = 16.0
    scale_height_beta: float = 900.0
    # the limits the path feedback enforces (0 = not enforced): heat rate, total load, q
    heat_rate_limit_kW_m2: float = 0.0
    load_limit_g: float = 0.0
    dynamic_pressure_limit_kPa: float = 0.0

    def terminal_speed(self, speed_of_sound: float) -> float:
        return self.terminal_velocity_m_s

    def alpha_profile(self) -> tuple[str, list[float], list[float]]:
        return "velocity", list(self.alpha_velocity_m_s), list(self.alpha_deg)

    def validate(self, scenario) -> None:
        super().validate(scenario)
        check_range("guidance.terminal_velocity_m_s", self.terminal_velocity_m_s, 1.0, scenario.entry.velocity_m_s)
        check_range("guidance.final_range_km", self.final_range_km, 0.0, 1e4)
        limit = scenario.make_vehicle().bank_limit_deg
        check_range("guidance.bank_end_deg", self.bank_end_deg, 0.0, limit)
        if self.bank_profile not in ("linear", "constant"):
            raise ScenarioError(f"guidance.bank_profile = '{self.bank_profile}'; allowed: 'linear' or 'constant'")
        check_range("guidance.bank_start_guess_deg", self.bank_start_guess_deg, 0.0, 90.0)
        check_range("guidance.bank_before_engagement_deg", self.bank_before_engagement_deg, 0.0, limit)
        check_range("guidance.engage_acceleration_m_s2", self.engage_acceleration_m_s2, 0.0, 100.0)
        check_alpha_in_speed(self.alpha_deg, self.alpha_velocity_m_s, -10.0, 60.0)
        check_range("guidance.alpha_rate_deg_s", self.alpha_rate_deg_s, 1e-3, 100.0)
        check_range("guidance.alpha_accel_deg_s2", self.alpha_accel_deg_s2, 1e-3, 1000.0)
        check_range("guidance.range_tolerance_km", self.range_tolerance_km, 1e-4, 100.0)
        check_range("guidance.max_iterations", self.max_iterations, 1, 100)
        check_range("guidance.max_halvings", self.max_halvings, 0, 30)
        check_range("guidance.first_difference_deg", self.first_difference_deg, 1e-4, 10.0)
        check_range("guidance.hold_speed_margin_m_s", self.hold_speed_margin_m_s, 0.0, 5000.0)
        check_range("guidance.predictor_step_s", self.predictor_step_s, 0.05, 30.0)
        check_range("guidance.damping_gain", self.damping_gain, 0.0, 1000.0)
        check_range("guidance.damping_bank_deg", self.damping_bank_deg, 0.0, 89.0)
        check_range("guidance.damping_off_margin_m_s", self.damping_off_margin_m_s, 0.0, 1e4)
        check_range("guidance.damping_ramp_m_s", self.damping_ramp_m_s, 1.0, 1e4)
        check_range("guidance.path_gain", self.path_gain, 0.0, 1000.0)
        check_range("guidance.path_horizon_s", self.path_horizon_s, 0.1, 200.0)
        check_range("guidance.scale_height_beta", self.scale_height_beta, 10.0, 1e5)
        for name in ("heat_rate_limit_kW_m2", "load_limit_g", "dynamic_pressure_limit_kPa"):
            check_range(f"guidance.{name}", getattr(self, name), 0.0, 1e6)
