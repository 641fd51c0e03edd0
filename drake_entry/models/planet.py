"""Rotating Earth: central and J2 gravity, oblate geometry, geodetic altitude and latitude.

The equations of motion use a geocentric radius r = R_ref + h, where ``h`` is the state
altitude above the reference sphere. On an oblate planet the atmosphere is evaluated at
the geodetic altitude above the ellipsoid (paper 001, Sec. II.A).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models import geodesy

__all__ = ["MU_EARTH", "R_EQUATOR", "J2_EARTH", "OMEGA_EARTH", "FLATTENING_WGS84", "G0", "Earth"]

# WGS-84 / EGM constants.
MU_EARTH = 3.986004418e14  # m^3/s^2 (paper 000 eq. 28, corrected units)
R_EQUATOR = 6378137.0  # m
J2_EARTH = 1.0826271e-3  # paper 000 eq. 28
OMEGA_EARTH = 7.2921150e-5  # rad/s
FLATTENING_WGS84 = 1.0 / 298.257223563
G0 = 9.80665  # m/s^2, standard gravity used for load factors


@dataclass(frozen=True)
class Earth:
    """Planet model.

    Attributes:
      mu: gravitational parameter [m^3/s^2].
      reference_radius: radius of the sphere the state altitude is measured from [m].
      equatorial_radius: ellipsoid semi-major axis, R in the J2 term [m].
      j2: second zonal harmonic (0 disables J2).
      omega: rotation rate [rad/s] (0 for a non-rotating planet).
      flattening: ellipsoid flattening (0 for a sphere).
      g0: standard gravity for load factors [m/s^2].
    """

    mu: float = MU_EARTH
    reference_radius: float = R_EQUATOR
    equatorial_radius: float = R_EQUATOR
    j2: float = J2_EARTH
    omega: float = OMEGA_EARTH
    flattening: float = FLATTENING_WGS84
    g0: float = G0

    def __post_init__(self):
        for name, lo in (("mu", 0.0), ("reference_radius", 0.0), ("equatorial_radius", 0.0)):
            if not getattr(self, name) > lo:
                raise ScenarioError(f"Earth.{name} must be > {lo}, got {getattr(self, name)}")
        if not 0.0 <= self.flattening < 1.0:
            raise ScenarioError(f"Earth.flattening must be in [0, 1), got {self.flattening}")
        if self.g0 <= 0:
            raise ScenarioError(f"Earth.g0 must be > 0, got {self.g0}")

    @staticmethod
    def spherical(*, rotating: bool = True, j2: bool = False, **kwargs) -> "Earth":
        """Spherical Earth (paper 000 eq. 102): no flattening, J2 off unless asked."""
        return Earth(
            j2=J2_EARTH if j2 else 0.0,
            omega=OMEGA_EARTH if rotating else 0.0,
            flattening=0.0,
            **kwargs,
        )

    @staticmethod
    def oblate(**kwargs) -> "Earth":
        """Oblate, rotating WGS-84 Earth with J2 (paper 001 eqs. 1-7)."""
        return Earth(**kwargs)

    def with_(self, **changes) -> "Earth":
        return replace(self, **changes)

    @property
    def is_spherical(self) -> bool:
        return self.flattening == 0.0

    def radius(self, h):
        """Geocentric radius [m] for state altitude h [m]."""
        return self.reference_radius + h

    def potential(self, r, lat):
        """Gravitational potential [J/kg] (negative), central + J2 (zonal degree 2)."""
        s = np.sin(lat)
        return -self.mu / r + self.mu * self.j2 * self.equatorial_radius**2 / (2.0 * r**3) * (
            3.0 * s * s - 1.0
        )

    def gravity(self, r, lat):
        """Gravity components (g_r, g_n) [m/s^2] at radius r [m], geocentric latitude lat.

        g_r is the magnitude pointing to the planet centre, g_n the component pointing
        north (negative in the northern hemisphere: J2 pulls towards the equator).
        g_r = mu/r^2 [1 + 3/2 J2 (R/r)^2 (1 - 3 sin^2 lat)]  (paper 000 eq. 28, corrected;
        paper 001 eq. 7 with g_R = -g_r), g_n = -3 mu/r^2 J2 (R/r)^2 sin lat cos lat
        (paper 001 eq. 7).
        """
        if self.j2 == 0.0:
            return self.mu / (r * r), 0.0 * lat
        s = np.sin(lat)
        c = np.cos(lat)
        k = self.j2 * (self.equatorial_radius / r) ** 2
        g_c = self.mu / r**2
        return g_c * (1.0 + 1.5 * k * (1.0 - 3.0 * s * s)), -3.0 * g_c * k * s * c

    def geodetic(self, r, lat):
        """Geodetic altitude [m] and latitude [rad] of geocentric (r, lat).

        Exact for a sphere; for an ellipsoid, Bowring's method with two iterations
        (sub-millimetre below 1000 km). float / ndarray only.
        """
        r = np.asarray(r, dtype=float)
        lat = np.asarray(lat, dtype=float)
        if self.is_spherical:
            return r - self.equatorial_radius, lat
        a = self.equatorial_radius
        f = self.flattening
        b = a * (1.0 - f)
        e2 = f * (2.0 - f)
        ep2 = e2 / (1.0 - e2)
        p = r * np.cos(lat)
        z = r * np.sin(lat)
        beta = np.arctan2(z * a, p * b)
        for _ in range(2):
            phi = np.arctan2(z + ep2 * b * np.sin(beta) ** 3, p - e2 * a * np.cos(beta) ** 3)
            beta = np.arctan2((1.0 - f) * np.sin(phi), np.cos(phi))
        n = a / np.sqrt(1.0 - e2 * np.sin(phi) ** 2)
        cphi = np.cos(phi)
        h = np.where(
            np.abs(cphi) > 1e-8,
            p / np.where(np.abs(cphi) > 1e-8, cphi, 1.0) - n,
            np.abs(z) - b,
        )
        return h, phi

    def from_geodetic(self, altitude, latitude) -> tuple[float, float]:
        """State altitude h [m] above the reference sphere and geocentric latitude [rad] of
        a point at geodetic ``altitude`` [m] and ``latitude`` [rad] (exact; the inverse of
        ``geodetic``). Paper 001 gives its entry point and sites geodetically."""
        a, f = self.equatorial_radius, self.flattening
        e2 = f * (2.0 - f)
        s, c = np.sin(latitude), np.cos(latitude)
        n = a / np.sqrt(1.0 - e2 * s * s)
        p, z = (n + altitude) * c, (n * (1.0 - e2) + altitude) * s
        return float(np.hypot(p, z) - self.reference_radius), float(np.arctan2(z, p))

    def atmospheric_altitude(self, h, lat):
        """Altitude [m] at which to evaluate the atmosphere for state altitude h, latitude lat.

        Sphere: h itself. Ellipsoid: the first-order geodetic altitude
        h* = r - R_eq (1 - f sin^2 lat) (paper 001, Sec. II.A), written so it works for
        every scalar type.
        """
        if self.is_spherical:
            return h
        s = np.sin(lat)
        return self.radius(h) - self.equatorial_radius * (1.0 - self.flattening * s * s)

    def state_altitude(self, geodetic_altitude, lat):
        """State altitude h [m] whose ``atmospheric_altitude`` at latitude ``lat`` [rad] is
        ``geodetic_altitude`` [m] (its exact inverse; any scalar type)."""
        if self.is_spherical:
            return geodetic_altitude
        s = np.sin(lat)
        return geodetic_altitude + self.equatorial_radius * (1.0 - self.flattening * s * s) - self.reference_radius

    def specific_energy(self, h, V, lat=0.0):
        """Specific mechanical energy E = V^2/2 + potential [J/kg] (paper 000 Sec. V.A)."""
        return 0.5 * V * V + self.potential(self.radius(h), lat)

    def great_circle_angle(self, lon1, lat1, lon2, lat2):
        """Central angle [rad] between two points on the sphere (haversine form)."""
        return geodesy.central_angle(lon1, lat1, lon2, lat2)

    def great_circle_distance(self, lon1, lat1, lon2, lat2):
        """Surface distance [m] on the reference sphere between two points."""
        return self.reference_radius * self.great_circle_angle(lon1, lat1, lon2, lat2)
