"""Drag-energy dynamics (paper 000 Sec. V): D, D' and D'' = a_D + b_D u with energy
E = V^2/2 - mu/r as the independent variable and u = (L/D) cos(sigma) (eq. 38).

Every term of eqs. 40-63 is kept: density derivatives of any altitude-only atmosphere
(eqs. 42-43), Mach derivatives through the temperature profile (eqs. 45-46, 59), the
aerodynamic alpha and Mach derivatives (eqs. 44, 60-61), the gravity derivative in V''
(eq. 47) and the Earth-rate correction C_gamma of the flight-path-angle equation
(eq. 50). D'' is evaluated as a function of u by eqs. 41-47 and split into a_D, b_D
(eqs. 62-63); the split is exact because u enters only through gamma' (eq. 48).

Corrections to the paper (docs/methods/drag-energy.md and our own derivation):
  - eq. 59: M_hV = -(T_h / T) / (2 a), the paper drops the 1/a factor (a: speed of sound);
  - eq. 44: the mixed aerodynamic term appears once with factor 2 (C_D,aM = C_D,Ma).
Derivatives ' are d/dE [per J/kg].
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle

__all__ = ["AlphaProfile", "DragDynamics", "gamma_correction", "drag_acceleration", "DragTerms", "drag_dynamics"]


@dataclass(frozen=True)
class AlphaProfile:
    """alpha(E) and its energy derivatives at one energy: [rad], [rad/(J/kg)], [rad/(J/kg)^2]."""

    alpha: float
    d_alpha: float = 0.0
    dd_alpha: float = 0.0


@dataclass(frozen=True)
class DragDynamics:
    """Drag acceleration [m/s^2] and its energy derivatives at one state.

    Attributes:
      D, D_prime: D and D' = dD/dE.
      a_D, b_D: D'' = a_D + b_D u (eq. 62).
      a_Dgamma, b_Dgamma: D' = a_Dgamma + b_Dgamma sin(gamma) (eqs. 73-74).
      lift_to_drag: C_L / C_D (u = lift_to_drag cos(sigma)).
      mach, rho: Mach number and density there.
    """

    D: float
    D_prime: float
    a_D: float
    b_D: float
    a_Dgamma: float
    b_Dgamma: float
    lift_to_drag: float
    mach: float
    rho: float

    def D_second(self, u: float) -> float:
        """D'' for the vertical control u (eq. 62)."""
        return self.a_D + self.b_D * u

    def feedforward(self, D_second_ref: float) -> float:
        """u_FF = (D''_ref - a_D) / b_D (eq. 95)."""
        return (D_second_ref - self.a_D) / self.b_D


def gamma_correction(D, V, r, gamma, lat, heading, omega) -> float:
    """C_gamma of eq. 50: Earth-rate terms of gamma-dot divided by dE/dt = -D V."""
    cl, sl = math.cos(lat), math.sin(lat)
    return (-2.0 * omega * cl * math.sin(heading) / (D * V)
            - omega**2 * r * cl / (D * V * V) * (math.cos(gamma) * cl + math.sin(gamma) * sl * math.cos(heading)))


def drag_acceleration(h: float, V: float, alpha: float, vehicle: Vehicle, atmosphere: Atmosphere) -> float:
    """D = rho V^2 S C_D / (2 m) [m/s^2] (eqs. 40, 65)."""
    rho, a = atmosphere.air_data(h)
    _, cd = vehicle.aero.coefficients(alpha, V / a)
    return 0.5 * rho * V * V * vehicle.area_over_mass * cd


class DragTerms:
    """The parts of eqs. 40-63 that do not depend on the flight-path angle, at altitude h [m]
    and speed V [m/s] for the scheduled alpha(E): air data, Mach and aerodynamic partials,
    D and the D' split a_Dgamma, b_Dgamma (eqs. 73-74). ``at(gamma)`` completes them to a
    DragDynamics; the planner's state extraction solves eq. 94 for gamma in between, with
    one model evaluation per node.

    The air is read where the plant reads it: at ``planet.atmospheric_altitude(h, lat)``, the
    geodetic altitude on an oblate planet (SPHYNX's state altitude lies 5-12 km under it). The
    offset R_eq (1 - f sin^2 lat) drifts as the vehicle changes latitude: with ``heading`` the air's
    altitude rate carries it, dh_air/dE = -(sin(gamma) + c) / D with c = R_eq f sin(2 lat)
    cos(psi) / r (cos(gamma) taken as 1, so D' stays linear in sin(gamma), eq. 94; the drift's own
    rate is left out of D''). On a -0.12 deg glide at 47 deg, c is 0.028 deg and moves D' by 50 %.
    With ``drag`` [m/s^2] (the accelerometer's) D is that drag: a constant density or
    drag-coefficient factor enters eqs. 40-63 through D alone (the ratios rho_h / rho, C_D' / C_D
    are unchanged; b_D does not scale with it), so the terms are exact for such a factor."""

    def __init__(self, h: float, V: float, alpha: AlphaProfile, vehicle: Vehicle, planet: Earth,
                 atmosphere: Atmosphere, *, lat: float = 0.0, heading: float | None = None,
                 drag: float | None = None):
        self.V, self.alpha, self.planet = V, alpha, planet
        self.r = r = planet.radius(h)
        self.drift = (0.0 if heading is None or planet.is_spherical else
                      planet.equatorial_radius * planet.flattening * math.sin(2.0 * lat) * math.cos(heading) / r)
        self.g = planet.mu / (r * r)
        self.g_h = -2.0 * self.g / r
        dens, temp = atmosphere.derivatives(float(planet.atmospheric_altitude(h, lat)))
        self.rho, self.rho_h, self.rho_hh = dens
        T, T_h, T_hh = temp
        a = math.sqrt(atmosphere.gamma * atmosphere.gas_constant * T)
        self.M = M = V / a
        self.M_h = -0.5 * M * T_h / T  # eq. 46
        self.M_V = 1.0 / a
        self.M_hh = 0.75 * M * (T_h / T) ** 2 - 0.5 * M * T_hh / T  # eq. 59
        self.M_hV = -0.5 * T_h / (T * a)  # eq. 59, corrected
        self.cd, CL = vehicle.aero.drag_derivatives(alpha.alpha, M)
        self.CD = self.cd.value
        self.lift_to_drag = CL / self.CD
        self.D = 0.5 * self.rho * V * V * vehicle.area_over_mass * self.CD if drag is None else float(drag)
        self.a_Dgamma = self.first(0.0)[-1]
        self.b_Dgamma = self.first(1.0)[-1] - self.a_Dgamma

    def first(self, s: float):
        """h', the air's altitude rate h_air', V', M', C_D', rho', D' for sin(gamma) = s (eqs. 37,
        40, 42, 44, 45)."""
        D, V, g = self.D, self.V, self.g
        hp = -s / D
        hp_air = -(s + self.drift) / D
        Vp = 1.0 / V + g * s / (D * V)
        Mp = self.M_h * hp_air + self.M_V * Vp
        CDp = self.cd.d_alpha * self.alpha.d_alpha + self.cd.d_mach * Mp
        rhop = self.rho_h * hp_air
        return hp, hp_air, Vp, Mp, CDp, rhop, D * (rhop / self.rho + 2.0 * Vp / V + CDp / self.CD)

    def at(self, gamma: float, *, lat: float = 0.0, heading: float = 0.0, earth_rate: bool = True) -> DragDynamics:
        """D, D', a_D, b_D, a_Dgamma, b_Dgamma at flight-path angle gamma [rad]."""
        D, V, g, r, rho, CD, cd, al = self.D, self.V, self.g, self.r, self.rho, self.CD, self.cd, self.alpha
        M_h, M_V = self.M_h, self.M_V
        sg, cg = math.sin(gamma), math.cos(gamma)
        w = self.planet.omega if earth_rate else 0.0
        C_gamma = gamma_correction(D, V, r, gamma, lat, heading, w) if w else 0.0
        a_gamma = cg / D * (g / (V * V) - 1.0 / r) + C_gamma  # eq. 49
        b_gamma = -1.0 / (V * V)
        hp, ha, Vp, Mp, CDp, rhop, Dp = self.first(sg)  # ha: the air's altitude rate
        gp = self.g_h * hp

        def second(u):
            """D'' for vertical control u (eqs. 41-47, 53-61)."""
            gam_p = a_gamma + b_gamma * u  # eq. 48
            hpp = (sg + self.drift) * Dp / (D * D) - cg * gam_p / D  # eq. 47, of the air's altitude
            Vpp = (-Vp / (V * V) + gp * sg / (D * V) + g * cg * gam_p / (D * V)
                   - g * sg / (D * D * V * V) * (Dp * V + D * Vp))  # eq. 47
            rhopp = self.rho_hh * ha * ha + self.rho_h * hpp  # eq. 42
            Mpp = self.M_hh * ha * ha + 2.0 * self.M_hV * ha * Vp + M_h * hpp + M_V * Vpp  # eq. 45 (M_VV = 0)
            CDpp = (cd.d_alpha_alpha * al.d_alpha**2 + 2.0 * cd.d_alpha_mach * al.d_alpha * Mp
                    + cd.d_alpha * al.dd_alpha + cd.d_mach_mach * Mp * Mp + cd.d_mach * Mpp)  # eq. 44/61
            return Dp * Dp / D + D * (rhopp / rho - (rhop / rho) ** 2 + 2.0 * Vpp / V - 2.0 * (Vp / V) ** 2
                                      + CDpp / CD - (CDp / CD) ** 2)  # eq. 41

        a_D = second(0.0)
        # b_D = dD''/du, the terms of eqs. 41-47 through gamma' only (u enters nowhere else);
        # written out, not second(1) - second(0), which cancels to 0 where |a_D| >> |b_D|
        hpp_u = -cg * b_gamma / D  # eq. 47
        Vpp_u = g * cg * b_gamma / (D * V)  # eq. 47
        Mpp_u = M_h * hpp_u + M_V * Vpp_u  # eq. 45
        b_D = D * (self.rho_h * hpp_u / rho + 2.0 * Vpp_u / V + cd.d_mach * Mpp_u / CD)  # eq. 41
        return DragDynamics(D, Dp, a_D, b_D, self.a_Dgamma, self.b_Dgamma, self.lift_to_drag, self.M, rho)


def drag_dynamics(h: float, V: float, gamma: float, alpha: AlphaProfile, vehicle: Vehicle, planet: Earth,
                  atmosphere: Atmosphere, *, lat: float = 0.0, heading: float = 0.0,
                  earth_rate: bool = True, drag: float | None = None) -> DragDynamics:
    """D, D', a_D, b_D, a_Dgamma, b_Dgamma at state altitude h [m], speed V [m/s], flight-path
    angle gamma [rad], for the scheduled alpha(E). ``lat`` [rad] places the air (DragTerms);
    ``lat``, ``heading`` [rad] feed the Earth-rate correction (eq. 50) when ``earth_rate`` and the
    planet rotates; ``drag`` [m/s^2]: the sensed drag (DragTerms)."""
    return DragTerms(h, V, alpha, vehicle, planet, atmosphere, lat=lat, heading=heading, drag=drag).at(
        gamma, lat=lat, heading=heading, earth_rate=earth_rate)
