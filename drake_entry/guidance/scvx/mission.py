"""An entry-to-landing-site mission for the SCvx planner (paper 001 Sec. II.B, Table 1,
eqs. 64-70): entry interface, site, DRS box, state bounds, angle-of-attack law.

Positions are given as the paper gives them: geodetic altitude and latitude on the WGS-84
ellipsoid (on the site the geodetic and geocentric latitudes differ by 20 km); ``entry_state``
and ``site`` convert them to the planner's state (altitude above the reference sphere,
geocentric latitude).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import FieldError
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.models.verdict import PathLimit

__all__ = ["SITE_RADIUS_MAX_M", "ENTRY_SPEED_RANGE_M_S", "DEFAULT_DRS_ALTITUDE_MARGIN_M", "ScvxMission", "alpha_law"]

#: the largest site radius a mission accepts [m] (a minimum-miss abort opens its cone to it)
SITE_RADIUS_MAX_M = 5e6
#: the entry speeds a mission accepts [m/s] (a plan from below 500 m/s has nowhere to glide)
ENTRY_SPEED_RANGE_M_S = (500.0, 12e3)
#: ScvxMission.final_altitude_margin_m by the bank's form when not given [m]: the lossless bank's
#: |u| < 1 at the final pull-up is lift the real bank cannot dump, so it flies its DRS point
#: about 500 m above the plan's (measured on the nominal mission); a bank state flies within 20 m
DEFAULT_DRS_ALTITUDE_MARGIN_M = {"lossless": 1200.0, "rate": 200.0}


@dc.dataclass
class ScvxMission:
    """Entry interface, landing site and terminal (DRS) conditions.

    Attributes:
      entry_altitude_m: geodetic altitude of the entry interface point (EIP) [m].
      entry_longitude_deg, entry_latitude_deg: EIP longitude and geodetic latitude [deg].
      entry_speed_m_s, entry_flight_path_deg, entry_heading_deg: Earth-relative speed [m/s],
        flight-path angle and heading from north, clockwise [deg] at the EIP.
      site_longitude_deg, site_latitude_deg: landing site, geodetic latitude [deg].
      site_radius_m: largest miss of the DRS point from the site [m] (eq. 69).
      final_altitude_m: geodetic DRS altitude window [m] (eq. 64).
      final_altitude_margin_m: the plan keeps its DRS altitude this far inside final_altitude_m [m],
        a design margin (not the paper's: it plans to the window's edges) so that the flown
        point, within the plan's accuracy, stays inside the window; 0 plans to the edges; None
        (default): DEFAULT_DRS_ALTITUDE_MARGIN_M of the formulation's bank form
        (``drs_altitude_window``).
      final_mach_max: largest DRS Mach number (eq. 64: subsonic).
      final_mach_min: smallest DRS Mach number (0 in paper 001; a TAEM box's lower edge).
      flown_mach_margin: a plan's flown DRS point may exceed final_mach_max by this (0 in paper
        001): where the plan aims inside a narrower window than the mission's box checks.
      final_vertical_speed_min_m_s: lowest V sin(gamma) at the DRS point [m/s] (eq. 65).
      final_vertical_speed_max_m_s: highest V sin(gamma) there [m/s], or None (paper 001: none);
        planned, not checked on the flown DRS point (a design aim, not a box criterion).
      flight_path_bounds_deg: path bounds on gamma [deg] (eq. 70), buffered.
      heading_bounds_deg: hard bounds on the heading [deg] (eq. 70).
      bank_min_deg: smallest bank magnitude [deg] (eq. 43).
      entry_bank_deg, entry_alpha_deg: the bank and angle of attack held at the start [deg], or
        None (free). A descent abort starts from the attitude being flown (paper 001 Sec. IV.C);
        they bind where bank or alpha are states (the rate formulations).
      alpha_deg, alpha_speeds_m_s: the angle-of-attack law: alpha_deg[0] above
        alpha_speeds_m_s[1], alpha_deg[1] below alpha_speeds_m_s[0], a C2 blend between.
      name: label.
    """

    entry_altitude_m: float = 120e3
    entry_longitude_deg: float = -115.0
    entry_latitude_deg: float = 30.0
    entry_speed_m_s: float = 7643.7
    entry_flight_path_deg: float = -1.29
    entry_heading_deg: float = 43.04
    site_longitude_deg: float = -25.165
    site_latitude_deg: float = 36.974
    site_radius_m: float = 10e3
    final_altitude_m: tuple = (10e3, 13e3)
    final_altitude_margin_m: float | None = None
    final_mach_max: float = 1.0
    final_mach_min: float = 0.0
    flown_mach_margin: float = 0.0
    final_vertical_speed_min_m_s: float = -140.0
    final_vertical_speed_max_m_s: float | None = None
    flight_path_bounds_deg: tuple = (-30.0, 0.5)
    heading_bounds_deg: tuple = (-10.0, 270.0)
    bank_min_deg: float = 5.0
    entry_bank_deg: float | None = None
    entry_alpha_deg: float | None = None
    alpha_deg: tuple = (40.0, 25.0)
    alpha_speeds_m_s: tuple = (2000.0, 5000.0)
    alpha_bounds_deg: tuple = (15.0, 45.0)
    alpha_rate_limit_deg_s: float = 1.0
    name: str = "paper001_nominal"

    def __post_init__(self):
        def check(field, value, lo, hi, unit):
            if not (isinstance(value, (int, float)) and lo <= value <= hi):
                raise FieldError("ScvxMission", field, f"= {value!r} is out of range [{lo}, {hi}] {unit}")

        check("entry_altitude_m", self.entry_altitude_m, 0.0, 200e3, "m")
        check("entry_speed_m_s", self.entry_speed_m_s, *ENTRY_SPEED_RANGE_M_S, "m/s")
        check("entry_flight_path_deg", self.entry_flight_path_deg, -45.0, 5.0, "deg")
        for f in ("entry_latitude_deg", "site_latitude_deg"):
            check(f, getattr(self, f), -89.0, 89.0, "deg")
        for f in ("entry_longitude_deg", "site_longitude_deg", "entry_heading_deg"):
            check(f, getattr(self, f), -360.0, 360.0, "deg")
        check("site_radius_m", self.site_radius_m, 1.0, SITE_RADIUS_MAX_M, "m")
        check("final_mach_max", self.final_mach_max, 0.1, 10.0, "-")
        check("final_mach_min", self.final_mach_min, 0.0, self.final_mach_max, "- (below final_mach_max)")
        check("flown_mach_margin", self.flown_mach_margin, 0.0, 10.0, "-")
        check("final_vertical_speed_min_m_s", self.final_vertical_speed_min_m_s, -2000.0, 0.0, "m/s")
        if self.final_vertical_speed_max_m_s is not None:
            check("final_vertical_speed_max_m_s", self.final_vertical_speed_max_m_s, self.final_vertical_speed_min_m_s,
                  0.0, "m/s (at least final_vertical_speed_min_m_s)")
        check("bank_min_deg", self.bank_min_deg, 0.0, 45.0, "deg")
        check("alpha_rate_limit_deg_s", self.alpha_rate_limit_deg_s, 1e-3, 90.0, "deg/s")
        for f, lo, hi in (("final_altitude_m", 0.0, 100e3), ("flight_path_bounds_deg", -89.0, 30.0),
                          ("heading_bounds_deg", -360.0, 720.0), ("alpha_speeds_m_s", 0.0, 12e3),
                          ("alpha_bounds_deg", 0.0, 60.0)):
            v = tuple(getattr(self, f))
            if len(v) != 2 or not lo <= v[0] < v[1] <= hi:
                raise FieldError("ScvxMission", f, f"= {v} needs two values {lo} <= low < high <= {hi}")
        if self.final_altitude_margin_m is not None:
            check("final_altitude_margin_m", self.final_altitude_margin_m, 0.0,
                  0.49 * (self.final_altitude_m[1] - self.final_altitude_m[0]), "m (under half the DRS window)")
        if self.entry_bank_deg is not None:
            check("entry_bank_deg", self.entry_bank_deg, -180.0, 180.0, "deg")
        if self.entry_alpha_deg is not None:
            check("entry_alpha_deg", self.entry_alpha_deg, *self.alpha_bounds_deg, "deg (alpha_bounds_deg)")
        if len(self.alpha_deg) != 2 or not all(0.0 <= a <= 60.0 for a in self.alpha_deg):
            raise FieldError("ScvxMission", "alpha_deg", f"= {tuple(self.alpha_deg)} needs two angles in [0, 60] deg "
                                f"(high speed, low speed)")
        if not self.flight_path_bounds_deg[0] <= self.entry_flight_path_deg <= self.flight_path_bounds_deg[1] + 1e-9:
            raise FieldError("ScvxMission", "entry_flight_path_deg", f"= {self.entry_flight_path_deg} lies outside "
                                f"flight_path_bounds_deg = {tuple(self.flight_path_bounds_deg)}")
        if not self.heading_bounds_deg[0] <= self.entry_heading_deg <= self.heading_bounds_deg[1]:
            raise FieldError("ScvxMission", "entry_heading_deg", f"= {self.entry_heading_deg} lies outside "
                                f"heading_bounds_deg = {tuple(self.heading_bounds_deg)}")

    @staticmethod
    def from_geocentric(planet: Earth, x0, site_longitude: float, site_latitude: float, **fields) -> "ScvxMission":
        """The mission from a state x0 = [h above the reference sphere, lon, geocentric lat, V,
        gamma, psi] (SI, rad) and a site on the surface at geocentric (lon, lat) [rad]: the
        inverse of ``entry_state`` and ``site`` (exact); ``fields`` set the rest."""
        h, lat = planet.geodetic(planet.radius(float(x0[0])), float(x0[2]))
        e2 = planet.flattening * (2.0 - planet.flattening)
        site_lat = math.atan2(math.tan(site_latitude), 1.0 - e2) if abs(site_latitude) < math.pi / 2 else site_latitude
        deg = math.degrees
        return ScvxMission(entry_altitude_m=float(h), entry_longitude_deg=deg(float(x0[1])),
                           entry_latitude_deg=deg(float(lat)), entry_speed_m_s=float(x0[3]),
                           entry_flight_path_deg=deg(float(x0[4])), entry_heading_deg=deg(float(x0[5])),
                           site_longitude_deg=deg(site_longitude), site_latitude_deg=deg(site_lat), **fields)

    def entry_state(self, planet: Earth) -> np.ndarray:
        """[h, lon, lat, V, gamma, psi] at the EIP: altitude above the reference sphere,
        geocentric latitude (paper 001 Table 1 converted)."""
        h, lat = planet.from_geodetic(self.entry_altitude_m, math.radians(self.entry_latitude_deg))
        return np.array([h, math.radians(self.entry_longitude_deg), lat, self.entry_speed_m_s,
                         math.radians(self.entry_flight_path_deg), math.radians(self.entry_heading_deg)])

    def site(self, planet: Earth) -> tuple[float, float]:
        """Site longitude and geocentric latitude [rad]."""
        return math.radians(self.site_longitude_deg), planet.from_geodetic(0.0, math.radians(self.site_latitude_deg))[1]

    def drs_altitude_window(self, bank_form: str = "rate") -> tuple[float, float]:
        """The geodetic DRS altitudes [m] a plan aims between: final_altitude_m less the margin
        (``final_altitude_margin_m``, or the default of the bank form, 'lossless' or 'rate')."""
        margin = self.final_altitude_margin_m
        if margin is None:
            margin = min(DEFAULT_DRS_ALTITUDE_MARGIN_M[bank_form], 0.49 * (self.final_altitude_m[1]
                                                                          - self.final_altitude_m[0]))
        return self.final_altitude_m[0] + margin, self.final_altitude_m[1] - margin

    def flight_path_limit(self) -> PathLimit:
        """The flight-path bounds (eq. 70) as a path limit a flight must hold."""
        lo, hi = (math.radians(v) for v in self.flight_path_bounds_deg)
        return PathLimit("flight_path", "gamma", upper=hi, lower=lo, unit="deg", scale=180.0 / math.pi)

    def alpha_schedule(self) -> Schedule:
        """alpha(V) [rad], velocity-scheduled and C2 (its derivative enters the Jacobians)."""
        return alpha_law(self.alpha_deg, self.alpha_speeds_m_s)


def alpha_law(alpha_deg, alpha_speeds_m_s) -> Schedule:
    """The two-value angle-of-attack law alpha(V) [rad]: alpha_deg[0] above alpha_speeds_m_s[1],
    alpha_deg[1] below alpha_speeds_m_s[0], a C2 blend between."""
    lo, hi = alpha_speeds_m_s
    return Schedule((float(lo), float(hi)), (math.radians(alpha_deg[1]), math.radians(alpha_deg[0])),
                    "velocity", smooth=True)
