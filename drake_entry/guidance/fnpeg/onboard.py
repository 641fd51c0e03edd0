"""FNPEG on board: the predictor and corrector of one mission, and the commands of one
guidance cycle (Lu 2014 Sec. III-IV). ``FnpegSetup.from_scenario`` builds it from a scenario; the
closed loop's guidance system (systems/fnpeg_guidance.py) calls ``correct`` every corrector
period and ``bank_magnitude`` / ``alpha_command`` every guidance period."""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.guidance.fnpeg.corrector import Correction, CorrectorSettings, correct
from drake_entry.guidance.fnpeg.law import FeedbackSettings, commanded_bank
from drake_entry.guidance.fnpeg.predictor import Prediction, Predictor
from drake_entry.guidance.path_feedback import PathLimits
from drake_entry.models.schedules import Schedule, linear_bank

__all__ = ["FnpegSetup"]


@dc.dataclass
class FnpegSetup:
    """What FNPEG flies with: the on-board models, the terminal energy e_f [J/kg] (mu/r - V^2/2
    at the terminal altitude and speed), the target (lon, lat) [rad], s_f* [m], sigma_f [rad],
    the alpha profile, the feedback and corrector settings, and the predictor."""

    vehicle: object
    planet: object
    atmosphere: object
    e_f: float
    target: tuple
    final_range: float
    sigma_f: float
    alpha: Schedule
    feedback: FeedbackSettings
    corrector: CorrectorSettings
    predictor: Predictor
    hold_speed: float

    @staticmethod
    def from_scenario(scenario) -> "FnpegSetup":
        g = scenario.guidance
        vehicle, planet, atmosphere = scenario.make_vehicle(), scenario.make_planet(), scenario.make_atmosphere()
        h_f = g.terminal_altitude_km * 1e3
        e_f = planet.mu / planet.radius(h_f) - 0.5 * g.terminal_velocity_m_s ** 2

        def limit(value, unit):
            return value * unit if value > 0 else math.inf

        feedback = FeedbackSettings(
            planet.reference_radius, planet.g0, beta=g.scale_height_beta, damping_gain=g.damping_gain,
            damping_bank=math.radians(g.damping_bank_deg),
            damping_off_speed=g.terminal_velocity_m_s + g.damping_off_margin_m_s, ramp=g.damping_ramp_m_s,
            path=PathLimits(planet.reference_radius, planet.g0, beta=g.scale_height_beta, gain=g.path_gain,
                            horizon=g.path_horizon_s, load_max=limit(g.load_limit_g, planet.g0),
                            heat_max=limit(g.heat_rate_limit_kW_m2, 1e3),
                            q_max=limit(g.dynamic_pressure_limit_kPa, 1e3)),
            bank_limit=vehicle.bank_limit)
        alpha = Schedule(tuple(g.alpha_velocity_m_s), tuple(np.radians(g.alpha_deg)), "velocity")
        sigma_f = math.radians(g.bank_end_deg)
        predictor = Predictor(vehicle, planet, atmosphere, feedback, sigma_f=sigma_f, e_f=e_f, alpha=alpha,
                              step_s=g.predictor_step_s, constant=g.bank_profile == "constant")
        return FnpegSetup(vehicle, planet, atmosphere, e_f,
                          (math.radians(scenario.target.longitude_deg), math.radians(scenario.target.latitude_deg)),
                          g.final_range_km * 1e3, sigma_f, alpha, feedback,
                          CorrectorSettings(g.range_tolerance_km * 1e3, g.max_iterations, g.max_halvings,
                                            math.radians(g.first_difference_deg)),
                          predictor, g.terminal_velocity_m_s + g.hold_speed_margin_m_s)

    def range_to_go(self, x) -> float:
        """Great-circle distance [m] from the state's position to the target."""
        return float(self.planet.great_circle_distance(x[1], x[2], *self.target))

    def predict(self, x, sigma0: float, sign: float = 1.0, scales=(1.0, 1.0)) -> Prediction:
        return self.predictor.predict(x, sigma0, sign, scales)

    def correct(self, x, sigma0: float, sign: float, slope: float | None = None, scales=(1.0, 1.0)) -> Correction:
        """The corrector's sigma_0 [rad] from the state ``x`` with the bank sign ``sign`` held and
        the predictions' lift and drag times ``scales`` (k_L, k_D)."""
        s_to_go = self.range_to_go(x) - self.final_range
        return correct(lambda s0: s_to_go - self.predict(x, s0, sign, scales).range_m, sigma0, self.corrector, slope)

    def energy(self, x) -> float:
        return self.predictor.energy(x)

    def bank_magnitude(self, x, sigma0: float, L: float, D: float, heat: float, q: float) -> float:
        """|sigma_cmd| [rad] at the navigated state ``x`` (the profile at its energy is sigma0)
        with the altitude-rate feedback on the sensed lift and drag L, D [m/s^2], heat rate
        [W/m^2] and q [Pa]."""
        e = self.energy(x)
        base = linear_bank(e, e, self.e_f, sigma0, self.sigma_f)
        return float(commanded_bank(base, float(x[3]), float(x[4]), max(L, 1e-9), max(D, 1e-9), math.hypot(L, D),
                                    heat, q, self.feedback))

    def alpha_command(self, V: float) -> float:
        """alpha [rad] of the profile at speed V [m/s]."""
        return float(self.alpha(float(V)))
