"""What the flight has shown of a density or aerodynamic error: the ratios of the sensed lift and
drag accelerations (the accelerometer's) to the nominal models' at the estimated state, low-passed.

A guidance that predicts with its nominal models scales them by these ratios (lift by k_L,
drag by k_D: ``ScaledAero``), so a density, aerodynamic or mass error seen so far is carried
into the prediction. Used by paper 004's on-board re-solution and the re-plans of paper 001's
SCvx and paper 002's LGL guidance (``sensed_vehicle``).
"""
from __future__ import annotations

import dataclasses as dc
import math

from drake_entry.models.aerodynamics import ScaledAero
from drake_entry.models.dynamics import aero_accelerations

__all__ = ["RATIO_TIME_CONSTANT_S", "RATIO_MIN_DRAG", "SensedAero", "filtered_ratios", "sensed_density_ratio",
           "sensed_limit_factors", "sensed_vehicle"]

#: time constant [s] of the low-pass, and the modelled drag [m/s^2] below which the ratios are
#: not updated (thin air: the ratio is noise)
RATIO_TIME_CONSTANT_S, RATIO_MIN_DRAG = 30.0, 0.5


def filtered_ratios(ratios, x, alpha: float, lift: float, drag: float, vehicle, planet, atmosphere,
                    step_s: float) -> tuple[float, float]:
    """(k_L, k_D) after one step of ``step_s`` [s] of the first-order low-pass (time constant
    RATIO_TIME_CONSTANT_S) from ``ratios`` toward sensed/modelled: ``lift``, ``drag`` [m/s^2]
    sensed, the models' at the estimate ``x`` [h, lon, lat, V, ...] and angle of attack
    ``alpha`` [rad]. Unchanged where the modelled drag is under RATIO_MIN_DRAG or lift is not
    positive."""
    k_l, k_d = float(ratios[0]), float(ratios[1])
    rho, a = atmosphere.air_data(planet.atmospheric_altitude(float(x[0]), float(x[2])))
    _, L, D = aero_accelerations(x, alpha, rho, a, vehicle)
    if D < RATIO_MIN_DRAG or not L > 0:
        return k_l, k_d
    w = min(1.0, step_s / RATIO_TIME_CONSTANT_S)
    return k_l + w * (lift / L - k_l), k_d + w * (drag / D - k_d)


@dc.dataclass
class SensedAero(ScaledAero):
    """The nominal aerodynamics times the ratios a flight has sensed (``sensed_vehicle``), and
    the vehicle's nominal path limits (``nominal_limits``: what a re-scaling starts from)."""

    nominal_limits: object = None


def sensed_density_ratio(scales) -> float:
    """The density ratio a guidance assumes from the sensed (k_L, k_D): their geometric mean (the
    density multiplies both; independent coefficient errors cancel on average), never below 1
    (thinner air than modelled only lowers q and the heat rate)."""
    k_l, k_d = (float(k) for k in scales)
    return max(1.0, math.sqrt(k_l * k_d))


def sensed_limit_factors(scales) -> dict:
    """What the nominal models' q and heat-rate bounds are divided by to hold the limits in the
    air the sensed (k_L, k_D) imply: k_rho and sqrt(k_rho), k_rho = ``sensed_density_ratio``
    (q = rho V^2 / 2 and the heat rate, proportional to sqrt(rho), are computed with the nominal
    density), by path quantity name."""
    k_rho = sensed_density_ratio(scales)
    return {"dynamic_pressure": k_rho, "heat_flux": math.sqrt(k_rho)}


def sensed_vehicle(vehicle, scales):
    """``vehicle`` predicting with its nominal lift and drag coefficients times ``scales`` =
    (k_L, k_D), the ratios the flight has shown, and its dynamic-pressure and heat-rate limits
    divided by k_rho and sqrt(k_rho), k_rho = ``sensed_density_ratio``: the models compute q =
    rho V^2 / 2 and the heat rate (proportional to sqrt(rho)) with the nominal density, so in air
    k_rho times denser a plan held to the nominal limits flies k_rho times over its q. A vehicle
    already so scaled (a plan re-planned before) is scaled from its nominal coefficients and
    limits, not compounded."""
    if isinstance(vehicle.aero, SensedAero):
        nominal, limits = vehicle.aero.base, vehicle.aero.nominal_limits
    else:
        nominal, limits = vehicle.aero, vehicle.limits
    k_l, k_d = (float(k) for k in scales)
    divisor = sensed_limit_factors(scales)
    sensed_limits = dc.replace(limits, dynamic_pressure_max=limits.dynamic_pressure_max / divisor["dynamic_pressure"],
                               heat_flux_max=limits.heat_flux_max / divisor["heat_flux"])
    return dc.replace(vehicle, aero=SensedAero(nominal, k_l, k_d, nominal_limits=limits), limits=sensed_limits)
