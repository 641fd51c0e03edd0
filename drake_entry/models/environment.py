"""The planet and atmosphere blocks of a mission or problem file (``planet:``, ``atmosphere:``)
and the models they build. Pure data read by pydrake's typed YAML (no ``from __future__ import
annotations``: it reads the field types); the scenario and the optimal-control problem files
share them."""
import dataclasses as dc
import os
from typing import Optional

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import Atmosphere, ExponentialAtmosphere, TableAtmosphere, US76Atmosphere
from drake_entry.models.planet import Earth

__all__ = ["PlanetSpec", "AtmosphereSpec", "planet_from_spec", "atmosphere_from_spec", "nrlmsis_atmosphere"]


@dc.dataclass
class PlanetSpec:
    # spherical | oblate
    model: str = "spherical"
    rotating: bool = True  # Earth rotation on (Coriolis and centrifugal terms)
    j2: bool = False  # J2 gravity term on
    # sphere / ellipsoid radius override [m] (paper 002: R_e = 6378145 m); None = WGS-84
    radius_m: Optional[float] = None


@dc.dataclass
class AtmosphereSpec:
    # us76 | exponential | table | nrlmsis
    model: str = "us76"
    # exponential model only (paper 000 eq. 29)
    rho0_kg_m3: float = 1.2256
    scale_height_m: float = 7200.0  # exponential model only
    # table model only: CSV path with columns altitude_m, density_kg_m3, temperature_K
    # (relative paths are read from the working directory)
    table_csv: str = ""
    # nrlmsis model only (NRLMSIS 2.1 through pymsis, for one place and time; the solar and
    # geomagnetic indices are given here, nothing is downloaded): UTC date and time (ISO 8601)
    nrlmsis_utc: str = ""
    nrlmsis_latitude_deg: float = 0.0
    nrlmsis_longitude_deg: float = 0.0
    # F10.7 solar flux of the day and its 81-day mean [sfu], daily Ap geomagnetic index
    f107_sfu: float = 150.0
    f107a_sfu: float = 150.0
    ap: float = 15.0
    # the profile is tabulated from 0 to nrlmsis_top_km every nrlmsis_step_km [km]
    nrlmsis_top_km: float = 200.0
    nrlmsis_step_km: float = 1.0


def planet_from_spec(p: PlanetSpec) -> Earth:
    """Earth model of a PlanetSpec (one-line ScenarioError on a bad field)."""
    kw = {}
    if p.radius_m is not None:
        if not p.radius_m > 0:
            raise ScenarioError(f"planet.radius_m = {p.radius_m}; allowed > 0")
        kw = dict(reference_radius=p.radius_m, equatorial_radius=p.radius_m)
    if p.model == "spherical":
        return Earth.spherical(rotating=p.rotating, j2=p.j2, **kw)
    if p.model == "oblate":
        return Earth.oblate(omega=Earth().omega if p.rotating else 0.0, j2=Earth().j2 if p.j2 else 0.0, **kw)
    raise ScenarioError(f"planet.model '{p.model}' is unknown; allowed: spherical, oblate")


def atmosphere_from_spec(a: AtmosphereSpec) -> Atmosphere:
    """Atmosphere model of an AtmosphereSpec (one-line ScenarioError on a bad field)."""
    if a.model == "us76":
        return US76Atmosphere()
    if a.model == "exponential":
        try:
            return ExponentialAtmosphere(a.rho0_kg_m3, a.scale_height_m)
        except ValueError as e:
            raise ScenarioError(f"atmosphere: {e}") from None
    if a.model == "table":
        if not a.table_csv:
            raise ScenarioError("atmosphere.table_csv is required for model 'table' (a CSV with the columns "
                                "altitude_m, density_kg_m3, temperature_K)")
        if not os.path.isfile(a.table_csv):
            raise ScenarioError(f"atmosphere.table_csv = '{a.table_csv}' is not a file")
        return TableAtmosphere.from_csv(a.table_csv)
    if a.model == "nrlmsis":
        return nrlmsis_atmosphere(a)
    raise ScenarioError(f"atmosphere.model '{a.model}' is unknown; allowed: us76, exponential, table, nrlmsis")


def nrlmsis_atmosphere(a: AtmosphereSpec) -> TableAtmosphere:
    """NRLMSIS 2.1 (Emmert et al. 2022, through the ``pymsis`` package) density and temperature at
    one place and UTC time with the given F10.7, F10.7a and Ap, tabulated every
    ``nrlmsis_step_km`` from 0 to ``nrlmsis_top_km`` as a TableAtmosphere (splines of ln rho and
    T; native on the Drake plant). Nothing is downloaded: the indices are the spec's."""
    import math

    import numpy as np

    where = "atmosphere"
    try:
        when = np.datetime64(a.nrlmsis_utc, "s") if a.nrlmsis_utc else None
    except ValueError:
        when = None
    if when is None or np.isnat(when):
        raise ScenarioError(f"{where}.nrlmsis_utc = {a.nrlmsis_utc!r}: give the UTC date and time, e.g. "
                            f"'2025-06-21T12:00:00'")
    checks = (("nrlmsis_latitude_deg", a.nrlmsis_latitude_deg, -90.0, 90.0),
              ("nrlmsis_longitude_deg", a.nrlmsis_longitude_deg, -360.0, 360.0),
              ("f107_sfu", a.f107_sfu, 50.0, 400.0), ("f107a_sfu", a.f107a_sfu, 50.0, 400.0), ("ap", a.ap, 0.0, 400.0),
              ("nrlmsis_top_km", a.nrlmsis_top_km, 10.0, 1000.0), ("nrlmsis_step_km", a.nrlmsis_step_km, 0.05, 10.0))
    for name, value, lo, hi in checks:
        if not (math.isfinite(value) and lo <= value <= hi):
            raise ScenarioError(f"{where}.{name} = {value} is out of range; allowed: [{lo:g}, {hi:g}]")
    import pymsis

    alts = np.arange(0.0, a.nrlmsis_top_km + 0.5 * a.nrlmsis_step_km, a.nrlmsis_step_km)
    out = pymsis.calculate(when, a.nrlmsis_longitude_deg, a.nrlmsis_latitude_deg, alts, f107s=a.f107_sfu,
                           f107as=a.f107a_sfu, aps=[[a.ap] * 7], version=2.1)
    rho = np.asarray(out[..., pymsis.Variable.MASS_DENSITY], float).ravel()
    T = np.asarray(out[..., pymsis.Variable.TEMPERATURE], float).ravel()
    source = (f"NRLMSIS 2.1 (pymsis {pymsis.__version__}) at {a.nrlmsis_latitude_deg:g} deg N, "
              f"{a.nrlmsis_longitude_deg:g} deg E, {a.nrlmsis_utc} UTC, F10.7 {a.f107_sfu:g}, F10.7a {a.f107a_sfu:g}, "
              f"Ap {a.ap:g}")
    return TableAtmosphere(alts * 1e3, rho, T, source=source)
