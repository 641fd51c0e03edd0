"""Vehicles: mass properties, aerodynamics, heat-flux form, path limits and bank limits.

``load_vehicle(name)`` reads a packaged YAML under ``drake_entry/vehicles/`` (horus2b,
cav_h, marv, shefex3, sphynx) or a user file path. Vehicle YAML files are dataclass
schemas (``VehicleSpec``) read with ``pydrake.common.yaml.yaml_load_typed``; a user can
also build a ``Vehicle`` in Python with any ``AeroModel`` (e.g. ``CallableAero``).
"""

import dataclasses as dc
import math
import numbers
import os
from typing import Optional

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models import aerodynamics as aero_mod
from drake_entry.models.constraints import HeatFlux, PathLimits, make_heat_flux
from drake_entry.typed_yaml import load_packaged_or_file, packaged_names

__all__ = ["AeroSpec", "HeatFluxSpec", "VehicleSpec", "Vehicle", "build_aero", "vehicle_from_spec",
           "PACKAGED_VEHICLES", "vehicle_spec", "LIMIT_FIELDS", "SIZE_RANGES", "load_vehicle"]

#: the allowed size of a vehicle file's vehicle: (field, low, high, unit), low excluded (a
#: dispersion then scales it within its own bounds). The highs bound every vehicle flown or
#: proposed (a 100-t orbiter, a 9-m diameter aeroshell: 64 m^2; inflatable decelerators to
#: about 30 m across: 700 m^2) by an order of magnitude, and keep rho V^2 S / m inside
#: floating point (an area of 1e308 overflowed to NaN in the trim root finder).
SIZE_RANGES = (("mass_kg", 0.0, 1e6, "kg"), ("reference_area_m2", 0.0, 1e4, "m^2"), ("nose_radius_m", 0.0, 100.0, "m"))


@dc.dataclass
class AeroSpec:
    """One aerodynamic model of a vehicle file."""

    #: fields naming a file: a relative path is read beside the vehicle file (typed_yaml.resolve_file_fields)
    FILE_FIELDS = ('table_csv', 'fill_csv')

    # table | horus_fit | cav_h | drag_polar | polynomial | newtonian
    model: str = ""
    # table: wide CSV (packaged data name or path) and optional long-format fill CSV
    table_csv: str = ""
    fill_csv: str = ""
    # horus_fit: paper 000 eqs. 32-33 coefficients, alpha in degrees
    aD: list[float] = dc.field(default_factory=list)
    aL: list[float] = dc.field(default_factory=list)
    # Mach clamp for fits and polynomials
    mach_min: float = 1.2
    mach_max: float = 20.0
    # drag_polar (paper 002 eqs. 4-5)
    cd0: float = 0.043
    k: float = 1.0
    cl_alpha: float = 1.0
    # polynomial: rows = powers of alpha, columns = powers of 1/M
    CL: list[list[float]] = dc.field(default_factory=list)
    CD: list[list[float]] = dc.field(default_factory=list)
    alpha_unit: str = "deg"
    # newtonian (representative lifting body)
    cp_max: float = 1.84
    cn_linear: float = 0.0
    ca0: float = 0.05
    ca_wave: float = 0.0
    # newtonian: C_D times this factor below Mach subsonic_blend_mach[0], blended to 1 at [1]
    subsonic_drag_factor: float = 1.0
    subsonic_blend_mach: list[float] = dc.field(default_factory=lambda: [0.8, 2.0])
    # where the numbers come from
    source: str = ""


@dc.dataclass
class HeatFluxSpec:
    # chapman | sutton_graves | normalised | lumped | betts_shuttle
    form: str = "chapman"
    # form constant (C1, k, c* or lumped k); empty = the form's published default
    coefficient: float | None = None
    velocity_exponent: float | None = None
    # normalised form (paper 001 eq. 9): the circular speed V_c [m/s]; empty = 7905.0
    circular_speed_m_s: float | None = None
    # angle-of-attack factor q_a = c_0 + c_1 alpha + ... multiplying the form (empty: 1)
    alpha_factor: list[float] = dc.field(default_factory=list)
    alpha_unit: str = "deg"  # unit of alpha in alpha_factor: deg | rad


@dc.dataclass
class VehicleSpec:
    """Schema of a vehicle YAML file."""

    name: str = ""  # short identifier
    description: str = ""  # one line for humans
    # true when the model is a labelled substitute, not the vehicle's real data
    representative: bool = False
    source: str = ""  # where the numbers come from
    mass_kg: float = 0.0  # vehicle mass
    reference_area_m2: float = 0.0  # aerodynamic reference area
    nose_radius_m: float = 0.0  # stagnation-point nose radius (heat flux)
    aero: dict[str, AeroSpec] = dc.field(default_factory=dict)  # named aerodynamic models (see AeroSpec)
    default_aero: str = ""  # the aero model used unless a scenario names one
    # stagnation-point heat-flux form (see HeatFluxSpec)
    heat_flux: HeatFluxSpec = dc.field(default_factory=HeatFluxSpec)
    heat_flux_max_kW_m2: float = float("inf")  # path limit
    dynamic_pressure_max_kPa: float = float("inf")  # path limit
    normal_load_max_g: float = float("inf")  # path limit (body normal axis)
    total_load_max_g: float = float("inf")  # path limit (sqrt(L^2 + D^2) / g0)
    bank_limit_deg: float = 90.0  # largest |bank| the actuator commands
    bank_rate_limit_deg_s: float = 20.0  # bank actuator rate limit
    bank_accel_limit_deg_s2: float = 10.0  # bank actuator acceleration limit
    # angle-of-attack actuator rate and acceleration limits (none: a method commanding alpha
    # uses its own paper's)
    alpha_rate_limit_deg_s: Optional[float] = None
    alpha_accel_limit_deg_s2: Optional[float] = None


#: the Vehicle limits it may leave as None (the alpha actuator: not every vehicle file states one)
_OPTIONAL_LIMITS = ("alpha_rate_limit", "alpha_accel_limit")


@dc.dataclass
class Vehicle:
    """A point-mass entry vehicle.

    Attributes:
      name: identifier.
      mass: [kg]. reference_area: S_ref [m^2]. nose_radius: R_N [m].
      aero: an AeroModel.
      heat_flux: the HeatFlux form of this vehicle.
      limits: PathLimits.
      bank_limit, bank_rate_limit, bank_accel_limit: [rad], [rad/s], [rad/s^2].
      alpha_rate_limit, alpha_accel_limit: the alpha actuator's limits [rad/s], [rad/s^2], or
        None where the vehicle states none.
      representative: True when the data are a labelled substitute.
      source: where the data come from.
    """

    name: str
    mass: float
    reference_area: float
    nose_radius: float
    aero: aero_mod.AeroModel
    heat_flux: HeatFlux | None = None
    limits: PathLimits = dc.field(default_factory=PathLimits)
    bank_limit: float = np.pi / 2
    bank_rate_limit: float = np.radians(20.0)
    bank_accel_limit: float = np.radians(10.0)
    alpha_rate_limit: float | None = None
    alpha_accel_limit: float | None = None
    representative: bool = False
    source: str = ""

    def __post_init__(self):
        for field, unit in (("mass", "kg"), ("reference_area", "m^2"), ("nose_radius", "m"), ("bank_rate_limit", "rad/s"),
                            ("bank_accel_limit", "rad/s^2"), ("alpha_rate_limit", "rad/s"),
                            ("alpha_accel_limit", "rad/s^2")):  # a file's vehicle is inside SIZE_RANGES; a dispersed one scaled
            v = getattr(self, field)
            optional = field in _OPTIONAL_LIMITS
            if v is None and optional:
                continue
            if isinstance(v, bool) or not (isinstance(v, numbers.Real) and 0 < v < math.inf):
                raise ScenarioError(f"Vehicle.{field} = {v!r} must be {'None or ' if optional else ''}a finite number > 0 "
                                    f"{unit}")
            setattr(self, field, float(v))
        if not 0 < self.bank_limit <= np.pi:
            raise ScenarioError(f"Vehicle.bank_limit must be in (0, 180] deg, got {np.degrees(self.bank_limit):.4g} deg")
        if self.heat_flux is None:
            self.heat_flux = HeatFlux.chapman(self.nose_radius)

    @property
    def bank_limit_deg(self) -> float:
        """The bank limit [deg] as the vehicle file states it (the radian round trip's last-bit
        error removed, so a setting equal to the stated limit is within it)."""
        return round(math.degrees(self.bank_limit), 9)

    @property
    def area_over_mass(self) -> float:
        """S_ref / m [m^2/kg]."""
        return self.reference_area / self.mass


def _resolve_data(path: str, field: str):
    """A packaged data file name or a filesystem path (``field``: the vehicle-file field naming it)."""
    if os.path.isdir(path):
        raise ScenarioError(f"{field} = '{path}' is a directory; give a CSV file")
    if os.path.exists(path):
        return open(path)
    try:
        return aero_mod.packaged_data(path)
    except FileNotFoundError:
        raise ScenarioError(f"{field} = '{path}' is neither a file nor a packaged data file (a relative path is "
                            f"read beside the vehicle file, then here)") from None


def build_aero(spec: AeroSpec, where: str = "aero") -> aero_mod.AeroModel:
    """AeroModel from its YAML spec."""
    m = spec.model
    try:
        if m == "table":
            if not spec.table_csv:
                raise ScenarioError(f"{where}.table_csv is required for model 'table'")
            with _resolve_data(spec.table_csv, "table_csv") as t:
                if spec.fill_csv:
                    with _resolve_data(spec.fill_csv, "fill_csv") as f:
                        table = aero_mod.read_wide_table(t, fill=f)
                else:
                    table = aero_mod.read_wide_table(t)
            table.source = spec.source
            return table
        if m == "horus_fit":
            return aero_mod.HorusFitAero(spec.aD, spec.aL, spec.mach_min, spec.mach_max)
        if m == "cav_h":
            return aero_mod.CavHAero()
        if m == "drag_polar":
            return aero_mod.DragPolarAero(spec.cd0, spec.k, spec.cl_alpha)
        if m == "polynomial":
            return aero_mod.PolynomialAero(spec.CL, spec.CD, spec.alpha_unit, spec.mach_min, spec.mach_max)
        if m == "newtonian":
            if len(spec.subsonic_blend_mach) != 2:
                raise ScenarioError(f"{where}.subsonic_blend_mach = {spec.subsonic_blend_mach} needs two Mach numbers")
            return aero_mod.NewtonianLiftingBodyAero(spec.cp_max, spec.cn_linear, spec.ca0, spec.ca_wave,
                                                     spec.subsonic_drag_factor, tuple(spec.subsonic_blend_mach))
    except ValueError as e:
        raise ScenarioError(f"{where}: {e}") from None
    raise ScenarioError(
        f"{where}.model '{m}' is unknown; allowed: table, horus_fit, cav_h, drag_polar, polynomial, newtonian"
    )


def vehicle_from_spec(spec: VehicleSpec, aero: str | None = None, where: str = "vehicle") -> Vehicle:
    """Vehicle from a VehicleSpec; ``aero`` picks one of the file's aero models."""
    for field, low, high, unit in SIZE_RANGES:
        v = getattr(spec, field)
        if not low < v <= high:
            raise ScenarioError(f"{where}.{field} = {v!r} is out of range; allowed: ({low:g}, {high:g}] {unit}")
    if not spec.aero:
        raise ScenarioError(f"{where}.aero is empty: give at least one aerodynamic model")
    key = aero or spec.default_aero or next(iter(spec.aero))
    if key not in spec.aero:
        raise ScenarioError(f"{where}: aero model '{key}' not found; this vehicle has: {', '.join(spec.aero)}")
    for field in ("bank_limit_deg",):
        if not 0 < getattr(spec, field) <= 180:
            raise ScenarioError(f"{where}.{field} = {getattr(spec, field)} is out of range (0, 180] deg")
    for field in ("bank_rate_limit_deg_s", "bank_accel_limit_deg_s2", "alpha_rate_limit_deg_s", "alpha_accel_limit_deg_s2"):
        v, optional = getattr(spec, field), field.startswith("alpha_")
        if not (v is None and optional) and not 0 < v < math.inf:
            raise ScenarioError(f"{where}.{field} = {v} is out of range: must be > 0 and finite"
                                + (" (or left out: none stated)" if optional else ""))
    try:
        hf = make_heat_flux(spec.heat_flux.form, nose_radius=spec.nose_radius_m,
                            coefficient=spec.heat_flux.coefficient,
                            velocity_exponent=spec.heat_flux.velocity_exponent,
                            circular_speed=spec.heat_flux.circular_speed_m_s,
                            alpha_factor=spec.heat_flux.alpha_factor, alpha_unit=spec.heat_flux.alpha_unit)
        limits = PathLimits(spec.heat_flux_max_kW_m2 * 1e3, spec.dynamic_pressure_max_kPa * 1e3,
                            spec.normal_load_max_g, spec.total_load_max_g)
    except ValueError as e:
        raise ScenarioError(f"{where}: {e}") from None
    return Vehicle(
        name=spec.name,
        mass=spec.mass_kg,
        reference_area=spec.reference_area_m2,
        nose_radius=spec.nose_radius_m,
        aero=build_aero(spec.aero[key], f"{where}.aero.{key}"),
        heat_flux=hf,
        limits=limits,
        bank_limit=np.radians(spec.bank_limit_deg),
        bank_rate_limit=np.radians(spec.bank_rate_limit_deg_s),
        bank_accel_limit=np.radians(spec.bank_accel_limit_deg_s2),
        alpha_rate_limit=None if spec.alpha_rate_limit_deg_s is None else math.radians(spec.alpha_rate_limit_deg_s),
        alpha_accel_limit=None if spec.alpha_accel_limit_deg_s2 is None else math.radians(spec.alpha_accel_limit_deg_s2),
        representative=spec.representative,
        source=spec.source,
    )


PACKAGED_VEHICLES = packaged_names("vehicles")


def vehicle_spec(name_or_path: str) -> VehicleSpec:
    """Read a vehicle YAML: a packaged name (``PACKAGED_VEHICLES``) or a file path."""
    return load_packaged_or_file(VehicleSpec, name_or_path, kind="vehicle", folder="vehicles")


#: the vehicle-file fields a scenario may replace for its mission (Scenario.vehicle_limits)
LIMIT_FIELDS = ("heat_flux_max_kW_m2", "dynamic_pressure_max_kPa", "normal_load_max_g", "total_load_max_g",
                "bank_limit_deg", "bank_rate_limit_deg_s", "bank_accel_limit_deg_s2", "alpha_rate_limit_deg_s",
                "alpha_accel_limit_deg_s2")


def load_vehicle(name: str, *, aero: str | None = None, limits: dict | None = None) -> Vehicle:
    """Load a vehicle by packaged name or YAML path.

    Args:
      name: a packaged vehicle (``PACKAGED_VEHICLES``) or a path to a vehicle YAML.
      aero: which of the file's aero models to use (default: the file's default_aero).
      limits: path and bank limits replacing the file's (keys: LIMIT_FIELDS, the file's units).
    """
    spec = vehicle_spec(name)
    if limits:
        unknown = sorted(set(limits) - set(LIMIT_FIELDS))
        if unknown:
            raise ScenarioError(f"vehicle_limits: {', '.join(unknown)} cannot be replaced; allowed: "
                                f"{', '.join(LIMIT_FIELDS)}")
        for k, v in limits.items():
            if not (isinstance(v, (int, float)) and v > 0):
                raise ScenarioError(f"vehicle_limits.{k} = {v} is out of range: must be > 0")
        spec = dc.replace(spec, **{k: float(v) for k, v in limits.items()})
    return vehicle_from_spec(spec, aero=aero, where=f"vehicle '{name}'")
