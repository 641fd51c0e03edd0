"""The 3-DOF point-mass entry equations, written once for float, AutoDiffXd and Expression.

State x = [h, lon, lat, V, gamma, psi]: altitude above the reference sphere [m],
longitude and geocentric latitude [rad], Earth-relative speed [m/s], flight-path angle
[rad], heading [rad] from north, clockwise. Controls: bank sigma and angle of attack
alpha [rad].

With a spherical planet and J2 off this is paper 000 eq. 102. With J2 the radial and
meridional (north) gravity components of paper 001 eq. 7 enter; their projections are
derived from the potential here (paper 001 eqs. 4-6 mix heading conventions): the north
component g_n adds g_n cos(gamma) cos(psi) to V', -g_n sin(gamma) cos(psi) / V to gamma'
and -g_n sin(psi) / (V cos gamma) to psi'. On an oblate planet the atmosphere is
evaluated at the geodetic altitude (paper 001 Sec. II.A).

With a horizontal wind (the atmosphere's ``wind``: east and north components W_e, W_n) the
state stays Earth-relative; the air-relative velocity v_a = v - W sets the Mach number, the
dynamic pressure, the heat flux and the aerodynamic force: drag along -v_a, lift normal to v_a
and banked about it. That force's components along the Earth-relative velocity, its normal in
the vertical plane and the horizontal normal replace -D, L cos(sigma) and L sin(sigma) in
paper 000 eq. 102 (in still air they are equal).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from drake_entry.errors import NonFiniteStateError
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.constraints import dynamic_pressure, normal_load_factor, total_load_factor
from drake_entry.models.planet import Earth
from drake_entry.models.scalar import promote
from drake_entry.models.vehicles import Vehicle

__all__ = ["STATE_NAMES", "STATE_UNITS", "FlightConditions", "FLIGHT_CONDITION_NAMES", "air_data",
           "wind_at", "air_relative_velocity", "airspeed", "aero_accelerations", "air_relative_force_components", "state_derivatives", "equations_of_motion", "equations_of_motion_lift_components",
           "flight_conditions", "conditions_from", "specific_energy", "energy_rate", "energy_domain_derivatives"]

STATE_NAMES = ("h", "lon", "lat", "V", "gamma", "psi")
STATE_UNITS = ("m", "rad", "rad", "m/s", "rad", "rad")


class FlightConditions(NamedTuple):
    """Quantities along a trajectory, SI units."""

    rho: object  # density [kg/m^3]
    mach: object  # Mach number [-]
    dynamic_pressure: object  # q [Pa]
    heat_flux: object  # stagnation heat flux [W/m^2]
    normal_load: object  # n_z [g]
    total_load: object  # n [g]
    lift: object  # L, lift acceleration [m/s^2]
    drag: object  # D, drag acceleration [m/s^2]
    energy: object  # specific mechanical energy E = V^2/2 + potential [J/kg]


FLIGHT_CONDITION_NAMES = FlightConditions._fields


def air_data(x, planet: Earth, atmosphere: Atmosphere):
    """Density [kg/m^3] and speed of sound [m/s] at state x."""
    return atmosphere.air_data(planet.atmospheric_altitude(x[0], x[2]))


def wind_at(x, planet: Earth, atmosphere: Atmosphere):
    """(east, north) wind [m/s] at state x, or None in still air."""
    return atmosphere.wind(planet.atmospheric_altitude(x[0], x[2]))


def air_relative_velocity(x, wind):
    """Air-relative velocity (east, north, up) [m/s] and its horizontal and total magnitudes."""
    V, gamma, psi = x[3], x[4], x[5]
    fn = math if isinstance(gamma, float) and isinstance(wind[0], float) else np
    horizontal = V * fn.cos(gamma)
    ve = horizontal * fn.sin(psi) - wind[0]
    vn = horizontal * fn.cos(psi) - wind[1]
    vu = V * fn.sin(gamma)
    vh = fn.sqrt(ve * ve + vn * vn)
    return (ve, vn, vu), vh, fn.sqrt(vh * vh + vu * vu)


def airspeed(x, wind):
    """Air-relative speed V_a [m/s] at state x in the wind (east, north) [m/s]; V in still air."""
    return x[3] if wind is None else air_relative_velocity(x, wind)[2]


def aero_accelerations(x, alpha, rho, speed_of_sound, vehicle: Vehicle, wind=None, speed=None):
    """Mach, lift and drag accelerations L, D [m/s^2] (paper 001 eq. 8 divided by m), at the
    air-relative speed in the wind (east, north) [m/s] when one is given; ``speed``: that speed
    [m/s] when already computed (the native plant takes it as an input, so its expression is not
    repeated wherever the aerodynamic model uses the Mach number)."""
    V = airspeed(x, wind) if speed is None else speed
    mach = V / speed_of_sound
    cl, cd = vehicle.aero.coefficients(alpha, mach)
    qS_m = 0.5 * rho * V * V * vehicle.area_over_mass
    return mach, qS_m * cl, qS_m * cd


def air_relative_force_components(x, bank, L, D, wind, velocity=None):
    """The aerodynamic acceleration's components (L_vertical, L_horizontal, D_along) [m/s^2] in the
    Earth-relative velocity frame, for ``equations_of_motion_lift_components``: drag D along the
    air-relative velocity, lift L normal to it at bank sigma (module docstring); in still air
    exactly (L cos sigma, L sin sigma, D). ``velocity``: ``air_relative_velocity(x, wind)`` when
    already computed."""
    (ve, vn, vu), vh, va = air_relative_velocity(x, wind) if velocity is None else velocity
    gamma, psi = x[4], x[5]
    fn = math if isinstance(gamma, float) and isinstance(vh, float) and isinstance(bank, float) else np
    lc, ls = L * fn.cos(bank), L * fn.sin(bank)
    # force in (east, north, up): -D v_a/|v_a| + L cos(sigma) (lift-up normal) + L sin(sigma) (right normal)
    fe = -D * ve / va - lc * vu * ve / (va * vh) + ls * vn / vh
    fnorth = -D * vn / va - lc * vu * vn / (va * vh) - ls * ve / vh
    fu = -D * vu / va + lc * vh / va
    sg, cg, sp, cp = fn.sin(gamma), fn.cos(gamma), fn.sin(psi), fn.cos(psi)
    along = fe * cg * sp + fnorth * cg * cp + fu * sg
    vertical = -fe * sg * sp - fnorth * sg * cp + fu * cg
    horizontal = fe * cp - fnorth * sp
    return vertical, horizontal, -along


def state_derivatives(x, bank, alpha, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere):
    """xdot for x = [h, lon, lat, V, gamma, psi] (paper 000 eq. 102; J2 per paper 001 eq. 7).

    Args:
      x: state (sequence of 6 scalars of one type).
      bank: sigma [rad]. alpha: angle of attack [rad].
    Returns:
      numpy array (dtype float or object) of the six time derivatives, SI.
    """
    x = [promote(v) for v in x]
    bank, alpha = promote(bank), promote(alpha)
    rho, a = air_data(x, planet, atmosphere)
    wind = wind_at(x, planet, atmosphere)
    _, L, D = aero_accelerations(x, alpha, rho, a, vehicle, wind)
    return equations_of_motion(x, bank, L, D, planet, wind)


def equations_of_motion(x, bank, L, D, planet: Earth, wind=None, air_velocity=None):
    """xdot given the lift and drag accelerations L, D [m/s^2] (paper 000 eq. 102), in the wind
    (east, north) [m/s] when one is given (module docstring; ``air_velocity``: its
    ``air_relative_velocity`` when already computed)."""
    if wind is not None:
        components = air_relative_force_components(x, bank, L, D, wind, air_velocity)
        return equations_of_motion_lift_components(x, *components, planet)
    fn = math if isinstance(x[4], float) and isinstance(bank, float) else np  # float fast path
    return equations_of_motion_lift_components(x, L * fn.cos(bank), L * fn.sin(bank), D, planet)


def equations_of_motion_lift_components(x, L_vertical, L_horizontal, D, planet: Earth):
    """xdot given the lift components L cos(sigma), L sin(sigma) and the drag D [m/s^2].

    The form the lossless bank relaxation needs (paper 001 eqs. 40-41: L u1, L u2 with
    u1 = cos sigma, u2 = sin sigma); ``equations_of_motion`` calls it with the real bank."""
    h, lon, lat, V, gamma, psi = x
    r = planet.radius(h)
    g_r, g_n = planet.gravity(r, lat)
    w = planet.omega
    fn = math if isinstance(gamma, float) and isinstance(L_vertical, float) else np  # float fast path
    sg, cg = fn.sin(gamma), fn.cos(gamma)
    sp, cp = fn.sin(psi), fn.cos(psi)
    sl, cl = fn.sin(lat), fn.cos(lat)
    tan_g = sg / cg
    h_dot = V * sg
    lon_dot = V * cg * sp / (r * cl)
    lat_dot = V * cg * cp / r
    V_dot = -D - g_r * sg + g_n * cg * cp + w * w * r * cl * (sg * cl - cg * sl * cp)
    gamma_dot = (
        L_vertical / V
        + (V / r - g_r / V) * cg
        - g_n * sg * cp / V
        + 2.0 * w * cl * sp
        + w * w * r / V * cl * (cg * cl + sg * sl * cp)
    )
    psi_dot = (
        L_horizontal / (V * cg)
        + V / r * cg * sp * sl / cl
        - g_n * sp / (V * cg)
        + 2.0 * w * (sl - cl * tan_g * cp)
        + w * w * r / (V * cg) * sl * cl * sp
    )
    if fn is math:  # float path: stop on NaN/inf here (an error-controlled integrator would
        total = h_dot + lon_dot + lat_dot + V_dot + gamma_dot + psi_dot  # shrink its step for ever)
        if total - total != 0.0:
            raise NonFiniteStateError(f"non-finite state derivative at h = {h:.6g} m, V = {V:.6g} m/s, "
                                      f"gamma = {gamma:.6g} rad, L cos(bank) = {L_vertical:.6g}, "
                                      f"L sin(bank) = {L_horizontal:.6g}, D = {D:.6g}")
    return np.array([h_dot, lon_dot, lat_dot, V_dot, gamma_dot, psi_dot])


def flight_conditions(x, bank, alpha, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere) -> FlightConditions:
    """Density, Mach, q, heat flux, load factors, L, D and energy at state x (Mach, q and heat flux
    at the air-relative speed in a wind)."""
    rho, a = air_data(x, planet, atmosphere)
    wind = wind_at(x, planet, atmosphere)
    mach, L, D = aero_accelerations(x, alpha, rho, a, vehicle, wind)
    return conditions_from(x, alpha, rho, mach, L, D, vehicle, planet, airspeed(x, wind))


def conditions_from(x, alpha, rho, mach, L, D, vehicle: Vehicle, planet: Earth, speed=None) -> FlightConditions:
    """FlightConditions from already computed air data and aerodynamic accelerations; ``speed``
    is the air-relative speed [m/s] (None: the state's speed, still air)."""
    V = x[3] if speed is None else speed
    return FlightConditions(
        rho=rho,
        mach=mach,
        dynamic_pressure=dynamic_pressure(rho, V),
        heat_flux=vehicle.heat_flux(rho, V, alpha),
        normal_load=normal_load_factor(L, D, alpha, planet.g0),
        total_load=total_load_factor(L, D, planet.g0),
        lift=L,
        drag=D,
        energy=specific_energy(x, planet),
    )


def specific_energy(x, planet: Earth):
    """E = V^2/2 + potential(r, lat) [J/kg] (paper 000 Sec. V.A: V^2/2 - mu/r without J2)."""
    return 0.5 * x[3] * x[3] + planet.potential(planet.radius(x[0]), x[2])


def energy_rate(x, xdot, planet: Earth):
    """dE/dt [W/kg] along xdot, by the chain rule (equals -D V without rotation and J2,
    paper 000 eq. 39)."""
    h, lat, V = x[0], x[2], x[3]
    r = planet.radius(h)
    g_r, g_n = planet.gravity(r, lat)
    # potential partials: dPhi/dr = g_r, dPhi/dlat = -r g_n
    return V * xdot[3] + g_r * xdot[0] - r * g_n * xdot[2]


def energy_domain_derivatives(x, bank, alpha, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere):
    """dx/dE = xdot / Edot, energy as the independent variable (paper 000 eq. 37 generalised).

    Also returns dt/dE as a seventh entry so time can be recovered.
    """
    xdot = state_derivatives(x, bank, alpha, vehicle, planet, atmosphere)
    edot = energy_rate(x, xdot, planet)
    return np.append(xdot / edot, 1.0 / edot)
