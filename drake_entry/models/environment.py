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

__all__ = ["PlanetSpec", "AtmosphereSpec", "planet_from_spec", "atmosphere_from_spec"]


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
    # us76 | exponential | table
    model: str = "us76"
    # exponential model only (paper 000 eq. 29)
    rho0_kg_m3: float = 1.2256
    scale_height_m: float = 7200.0  # exponential model only
    # table model only: CSV path with columns altitude_m, density_kg_m3, temperature_K
    # (relative paths are read from the working directory)
    table_csv: str = ""


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
    raise ScenarioError(f"atmosphere.model '{a.model}' is unknown; allowed: us76, exponential, table")
