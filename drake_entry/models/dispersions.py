"""Dispersions: declared in scenario YAML with Drake's schema distributions, drawn per
Monte-Carlo sample from that sample's RandomGenerator.

    dispersions:
      entry:                      # paper 000 Table 2 (uniform)
        altitude_m: !Uniform {min: -250, max: 250}
        velocity_m_s: !Uniform {min: -15, max: 15}
        ...
      density_scale: !Gaussian {mean: 1.0, stddev: 0.05}    # bias on the density
      density_wave_amplitude: !Uniform {min: 0.0, max: 0.05} # altitude-correlated part
      density_wave_length_km: 8.0
      lift_scale: !Gaussian {mean: 1.0, stddev: 0.03}
      drag_scale: !Gaussian {mean: 1.0, stddev: 0.03}
      mass_scale: 1.0
      nav_bias: !GaussianVector {mean: [0, 0, 0, 0, 0, 0], stddev: [50, 1e-6, 1e-6, 1, 1e-4, 1e-4]}
      nav_noise_sigma: [10.0, 0.0, 0.0, 0.5, 0.0, 0.0]

Every field also takes a plain number (deterministic). Fields not in SI carry their unit in
the name. ``draw(spec, generator)`` returns a ``Draw`` with SI values, always consuming the
generator in the same order so that a sample depends on (seed, index) only.
"""

import dataclasses as dc
import math
import typing

import numpy as np
import pydrake.common.schema as schema

from drake_entry.errors import ScenarioError
from drake_entry.models.aerodynamics import AERO_REGIMES, RegimeAero, ScaledAero
from drake_entry.models.atmosphere import DENSITY_WAVE_AMPLITUDE_BOUND, DispersedAtmosphere, PerturbedAtmosphere
from drake_entry.models.atmosphere_perturbations import (
    AtmospherePerturbationSpec,
    draw_profiles,
    validate_perturbations,
)
from drake_entry.models.covariance import check_covariance, covariance_root
from drake_entry.models.inertial_navigation import (
    InertialNavigationSpec,
    draw_inertial_errors,
    validate_inertial_navigation,
)
from drake_entry.models.winds import WindProfile, WindSpec, WindyAtmosphere, draw_wind, validate_winds

__all__ = ["Scalar", "Vector", "EntryDispersionSpec", "AeroRegimeDispersionSpec", "ENTRY_TABLE_TO_SI", "MAX_AERO_SIGMA",
           "PERTURBATION_COLUMNS_KM", "AtmospherePerturbationSpec", "WindSpec",
           "InertialNavigationSpec",
           "DispersionSpec", "Draw", "draw", "GAUSSIAN_REACH", "validate", "entry_spread", "force_dispersions",
           "force_ratio_high"]

Scalar = typing.Union[float, schema.Deterministic, schema.Gaussian, schema.Uniform]
Vector = typing.Union[schema.DeterministicVectorX, schema.GaussianVectorX, schema.UniformVectorX]


@dc.dataclass
class EntryDispersionSpec:
    """Deviation of the entry-interface state from the nominal."""

    altitude_m: Scalar = 0.0
    longitude_deg: Scalar = 0.0
    latitude_deg: Scalar = 0.0
    velocity_m_s: Scalar = 0.0
    flight_path_deg: Scalar = 0.0
    heading_deg: Scalar = 0.0


@dc.dataclass
class AeroRegimeDispersionSpec:
    """Aerodynamic uncertainty by Mach regime (models.aerodynamics.RegimeAero): per regime a
    relative C_L and C_D error, drawn jointly Gaussian with their correlation, blended across the
    regime boundaries; and a trim angle-of-attack error."""

    # Mach numbers between the regimes subsonic | transonic | supersonic | hypersonic
    mach_boundaries: list[float] = dc.field(default_factory=lambda: [0.8, 1.2, 5.0])
    # the errors change linearly from one regime's to the next over this Mach width at each boundary
    blend_mach: float = 0.2
    # 1-sigma of the relative C_L and C_D errors per regime (subsonic, transonic, supersonic,
    # hypersonic) and the correlation of the two within a regime
    lift_sigma: list[float] = dc.field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])
    drag_sigma: list[float] = dc.field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])
    correlation: list[float] = dc.field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])
    # 1-sigma of the trim angle-of-attack error [deg] (Gaussian, mean 0)
    trim_alpha_sigma_deg: float = 0.0


@dc.dataclass
class DispersionSpec:
    """Everything a Monte-Carlo sample may disperse (defaults: nothing)."""

    # where these dispersions come from (a paper's table, or a labelled choice): the report's
    # dispersion table cites it
    source: str = ""
    entry: EntryDispersionSpec = dc.field(default_factory=EntryDispersionSpec)
    # true density = nominal * density_scale * (1 + amplitude sin(2 pi h / wavelength + phase))
    density_scale: Scalar = 1.0
    density_wave_amplitude: Scalar = 0.0
    density_wave_length_km: float = 8.0
    # true aerodynamic coefficients = nominal * scale; true mass = nominal * scale
    lift_scale: Scalar = 1.0
    drag_scale: Scalar = 1.0
    mass_scale: Scalar = 1.0
    # navigation: constant bias [state units, SI / rad] and white-noise sigma
    nav_bias: Vector = dc.field(default_factory=lambda: schema.DeterministicVectorX(value=[0.0] * 6))
    nav_noise_sigma: list[float] = dc.field(default_factory=lambda: [0.0] * 6)
    # aerodynamic errors by Mach regime and a trim error (none when absent)
    aero_regimes: typing.Optional[AeroRegimeDispersionSpec] = None
    # entry delivery covariance: a zero-mean Gaussian deviation of [altitude m, longitude deg,
    # latitude deg, speed m/s, flight-path deg, heading deg] with this 6 x 6 covariance (symmetric,
    # positive semi-definite), added to the ``entry`` deviations (none when absent)
    entry_covariance: typing.Optional[list[list[float]]] = None
    # density and temperature perturbations along the flight: a per-flight part and a part
    # correlated over a vertical scale length, 1-sigma by altitude (models.atmosphere_perturbations;
    # none when absent)
    atmosphere_perturbations: typing.Optional[AtmospherePerturbationSpec] = None
    # horizontal wind: a mean profile by altitude plus perturbations correlated in altitude
    # (models.winds; still air when absent)
    winds: typing.Optional[WindSpec] = None
    # navigation from an inertial error model (models.inertial_navigation) instead of nav_bias and
    # nav_noise_sigma (none when absent)
    inertial_navigation: typing.Optional[InertialNavigationSpec] = None

    @staticmethod
    def paper000_table2() -> "DispersionSpec":
        """Paper 000 Table 2: uniform entry-interface dispersions, nothing else."""
        u = lambda a: schema.Uniform(min=-a, max=a)  # noqa: E731
        return DispersionSpec(entry=EntryDispersionSpec(u(250.0), u(0.1), u(0.1), u(15.0), u(0.01), u(0.01)))


@dc.dataclass(frozen=True)
class Draw:
    """One sample's dispersions in SI / rad."""

    entry_delta: np.ndarray
    density_scale: float = 1.0
    density_wave_amplitude: float = 0.0
    density_wave_length: float = 8000.0
    density_wave_phase: float = 0.0
    lift_scale: float = 1.0
    drag_scale: float = 1.0
    mass_scale: float = 1.0
    nav_bias: np.ndarray = dc.field(default_factory=lambda: np.zeros(6))
    nav_noise_sigma: np.ndarray = dc.field(default_factory=lambda: np.zeros(6))
    nav_seed: int = 0
    #: aerodynamic errors by Mach regime (relative, per regime of AERO_REGIMES), the boundaries
    #: and blend width of the regimes, and the trim error [rad] (empty: none)
    aero_lift_errors: tuple = ()
    aero_drag_errors: tuple = ()
    aero_boundaries: tuple = ()
    aero_blend_mach: float = 0.2
    trim_alpha: float = 0.0
    #: the atmosphere perturbation profile: altitude nodes [m] and the density and temperature
    #: perturbations (fractions) there (empty: none)
    perturbation_altitude_m: tuple = ()
    density_perturbation: tuple = ()
    temperature_perturbation: tuple = ()
    #: the wind profile: altitude nodes [m] and the east and north wind there [m/s] (empty: still air)
    wind_altitude_m: tuple = ()
    wind_east_m_s: tuple = ()
    wind_north_m_s: tuple = ()
    #: the flight's inertial navigation errors (models.inertial_navigation.InertialErrors; None:
    #: nav_bias and nav_noise_sigma)
    inertial: typing.Any = None

    def columns(self) -> dict:
        """Flat record for result tables (entry deviations in table units)."""
        d = self.entry_delta
        out = {"disp_dh_m": d[0], "disp_dlon_deg": math.degrees(d[1]), "disp_dlat_deg": math.degrees(d[2]),
               "disp_dV_m_s": d[3], "disp_dgamma_deg": math.degrees(d[4]), "disp_dpsi_deg": math.degrees(d[5]),
               "disp_density_scale": self.density_scale, "disp_density_wave": self.density_wave_amplitude,
               "disp_lift_scale": self.lift_scale, "disp_drag_scale": self.drag_scale,
               "disp_mass_scale": self.mass_scale}
        for k, v in zip(("h", "lon", "lat", "V", "gamma", "psi"), self.nav_bias):
            out[f"disp_nav_bias_{k}"] = v
        if self.aero_lift_errors:
            for regime, dl, dd in zip(AERO_REGIMES, self.aero_lift_errors, self.aero_drag_errors):
                out[f"disp_dCL_{regime}"], out[f"disp_dCD_{regime}"] = dl, dd
            out["disp_trim_alpha_deg"] = math.degrees(self.trim_alpha)
        if self.perturbation_altitude_m:
            for km in PERTURBATION_COLUMNS_KM:
                out[f"disp_drho_{km}km"] = np.interp(km * 1e3, self.perturbation_altitude_m, self.density_perturbation)
                out[f"disp_dT_{km}km"] = np.interp(km * 1e3, self.perturbation_altitude_m,
                                                   self.temperature_perturbation)
        if self.wind_altitude_m:
            for km in PERTURBATION_COLUMNS_KM:
                out[f"disp_wind_east_{km}km"] = np.interp(km * 1e3, self.wind_altitude_m, self.wind_east_m_s)
                out[f"disp_wind_north_{km}km"] = np.interp(km * 1e3, self.wind_altitude_m, self.wind_north_m_s)
        if self.inertial is not None:
            out.update(self.inertial.columns())
        return {k: float(v) for k, v in out.items()}

    def atmosphere(self, base):
        """The sample's true atmosphere over the nominal ``base``: the density factor and wave,
        then the perturbation profiles and the wind when drawn."""
        air = DispersedAtmosphere(base, scale=self.density_scale, amplitude=self.density_wave_amplitude,
                                  wavelength=self.density_wave_length, phase=self.density_wave_phase)
        if self.perturbation_altitude_m:
            air = PerturbedAtmosphere(air, self.perturbation_altitude_m, self.density_perturbation,
                                      self.temperature_perturbation)
        if self.wind_altitude_m:
            air = WindyAtmosphere(air, WindProfile(self.wind_altitude_m, self.wind_east_m_s, self.wind_north_m_s))
        return air

    def aerodynamics(self, base):
        """The sample's true aerodynamics over the nominal ``base``: the scale factors, then the
        errors by Mach regime and the trim error when drawn."""
        aero = ScaledAero(base, self.lift_scale, self.drag_scale)
        if not self.aero_lift_errors:
            return aero
        return RegimeAero(aero, tuple(self.aero_lift_errors), tuple(self.aero_drag_errors), tuple(self.aero_boundaries),
                          self.aero_blend_mach, self.trim_alpha)


def _sample(x, generator) -> float:
    return float(x) if isinstance(x, (int, float)) else float(x.Sample(generator))


def draw(spec: DispersionSpec, generator) -> Draw:
    """Draw one sample (fixed order of draws; see module doc)."""
    e = spec.entry
    raw = [_sample(getattr(e, f.name), generator) for f in dc.fields(EntryDispersionSpec)]
    delta = np.array([raw[0], math.radians(raw[1]), math.radians(raw[2]), raw[3], math.radians(raw[4]),
                      math.radians(raw[5])])
    scales = {k: _sample(getattr(spec, k), generator) for k in
              ("density_scale", "density_wave_amplitude", "lift_scale", "drag_scale", "mass_scale")}
    phase = 2.0 * math.pi * schema.Uniform(min=0.0, max=1.0).Sample(generator)
    bias = np.asarray(spec.nav_bias.Sample(generator), float).ravel()
    nav_seed = int(generator())  # last draw: seeds the navigation noise sequence
    for k in ("density_scale", "lift_scale", "drag_scale", "mass_scale"):
        if not scales[k] > 0:
            raise ScenarioError(f"dispersions.{k} drew {scales[k]:g}; it must stay > 0 (narrow its distribution)")
    aero = {}
    if spec.aero_regimes is not None:  # drawn after the rest, so a scenario without it draws as before
        a = spec.aero_regimes
        lift, drag = [], []
        for sl, sd, rho in zip(a.lift_sigma, a.drag_sigma, a.correlation):
            z1, z2 = _normal(generator), _normal(generator)
            lift.append(sl * z1)
            drag.append(sd * (rho * z1 + math.sqrt(max(0.0, 1.0 - rho * rho)) * z2))
        aero = {"aero_lift_errors": tuple(lift), "aero_drag_errors": tuple(drag),
                "aero_boundaries": tuple(a.mach_boundaries), "aero_blend_mach": float(a.blend_mach),
                "trim_alpha": math.radians(a.trim_alpha_sigma_deg * _normal(generator))}
        too_low = [e for e in (*lift, *drag) if not e > -1.0]
        if too_low:
            raise ScenarioError(f"dispersions.aero_regimes drew a relative error of {too_low[0]:g}; a coefficient must "
                                f"stay positive (narrow lift_sigma / drag_sigma)")
    if spec.entry_covariance is not None:  # after the rest, for the same reason
        delivered = covariance_root(spec.entry_covariance) @ np.array([_normal(generator) for _ in range(6)])
        delta = delta + delivered * ENTRY_TABLE_TO_SI
    profile = {}
    if spec.atmosphere_perturbations is not None:  # after the rest, for the same reason
        h, d_rho, d_T = draw_profiles(spec.atmosphere_perturbations, generator)
        profile = {"perturbation_altitude_m": tuple(h), "density_perturbation": tuple(d_rho),
                   "temperature_perturbation": tuple(d_T)}
        if not (d_rho.min() > -1.0 and d_T.min() > -1.0):
            raise ScenarioError("dispersions.atmosphere_perturbations drew a perturbation of -100 % or less; narrow "
                                "density_sigma / temperature_sigma")
    if spec.winds is not None:  # after the rest, for the same reason
        wind = draw_wind(spec.winds, generator)
        profile.update(wind_altitude_m=tuple(wind.nodes), wind_east_m_s=tuple(wind.east),
                       wind_north_m_s=tuple(wind.north))
    if spec.inertial_navigation is not None:  # after the rest, for the same reason
        profile["inertial"] = draw_inertial_errors(spec.inertial_navigation, lambda: _normal(generator))
    return Draw(delta, scales["density_scale"], scales["density_wave_amplitude"],
                spec.density_wave_length_km * 1e3, phase, scales["lift_scale"], scales["drag_scale"],
                scales["mass_scale"], bias, np.asarray(spec.nav_noise_sigma, float), nav_seed, **aero, **profile)


#: altitudes [km] at which a row records the drawn density and temperature perturbations
PERTURBATION_COLUMNS_KM = (30, 50, 70)

#: the entry deviations' table units [m, deg, deg, m/s, deg, deg] to SI [m, rad, rad, m/s, rad, rad]
ENTRY_TABLE_TO_SI = np.array([1.0, math.pi / 180, math.pi / 180, 1.0, math.pi / 180, math.pi / 180])


def _normal(generator) -> float:
    """One standard normal draw from the sample's generator."""
    return float(schema.Gaussian(mean=0.0, stddev=1.0).Sample(generator))


def _check_distribution(where: str, d) -> None:
    """Finite parameters; Uniform min <= max; Gaussian stddev >= 0 (scalars and vectors)."""
    if isinstance(d, (int, float)):
        params = {"value": d}
    elif isinstance(d, (schema.Deterministic, schema.DeterministicVectorX)):
        params = {"value": d.value}
    elif isinstance(d, (schema.Gaussian, schema.GaussianVectorX)):
        params = {"mean": d.mean, "stddev": d.stddev}
    elif isinstance(d, (schema.Uniform, schema.UniformVectorX)):
        params = {"min": d.min, "max": d.max}
    else:
        raise ScenarioError(f"{where}: {type(d).__name__} is not a supported distribution")
    for name, v in params.items():
        if not np.all(np.isfinite(np.asarray(v, float))):
            raise ScenarioError(f"{where}.{name} = {v} is not finite")
    if "stddev" in params and np.any(np.asarray(params["stddev"], float) < 0):
        raise ScenarioError(f"{where}: Gaussian stddev = {params['stddev']} must be >= 0")
    if "min" in params and np.any(np.asarray(params["min"], float) > np.asarray(params["max"], float)):
        raise ScenarioError(f"{where}: Uniform min = {params['min']} is above max = {params['max']}")


#: a Gaussian scale is refused when its mean minus this many standard deviations is <= 0 (a
#: draw that far out has probability 3e-7)
GAUSSIAN_REACH = 5.0


def _support_floor(d) -> float:
    """The lowest value a scalar distribution draws (Gaussian: mean - GAUSSIAN_REACH stddev)."""
    if isinstance(d, (int, float)):
        return float(d)
    if isinstance(d, schema.Deterministic):
        return float(d.value)
    if isinstance(d, schema.Uniform):
        return float(d.min)
    if isinstance(d, schema.Gaussian):
        return float(d.mean) - GAUSSIAN_REACH * float(d.stddev)
    return math.nan


def _support_ceiling(d) -> float:
    """The highest value a scalar distribution draws (Gaussian: mean + GAUSSIAN_REACH stddev)."""
    if isinstance(d, schema.Uniform):
        return float(d.max)
    if isinstance(d, schema.Gaussian):
        return float(d.mean) + GAUSSIAN_REACH * float(d.stddev)
    return _support_floor(d)


def _three_sigma(d) -> float:
    """The half-width a scalar deviation reaches about 0: a uniform's farther bound, a Gaussian's
    |mean| + 3 stddev, a constant's |value|."""
    if isinstance(d, schema.Uniform):
        return max(abs(float(d.min)), abs(float(d.max)))
    if isinstance(d, schema.Gaussian):
        return abs(float(d.mean)) + 3.0 * float(d.stddev)
    return abs(_support_floor(d))


def entry_spread(spec: DispersionSpec) -> np.ndarray:
    """The entry deviations' 3-sigma half-widths [m, deg, deg, m/s, deg, deg] (the ``entry``
    block's, ``_three_sigma``, combined root-sum-square with the delivery covariance's 3 sqrt(C_ii))."""
    e = spec.entry
    out = np.array([_three_sigma(getattr(e, f.name)) for f in dc.fields(EntryDispersionSpec)])
    if spec.entry_covariance is not None:
        out = np.hypot(out, 3.0 * np.sqrt(np.maximum(np.diag(np.asarray(spec.entry_covariance, float)), 0.0)))
    return out


def _mean_and_sigma(d) -> tuple[float, float]:
    """A scalar distribution's mean and standard deviation (a uniform's (max - min) / sqrt(12),
    a constant's 0)."""
    if isinstance(d, schema.Uniform):
        return 0.5 * (float(d.min) + float(d.max)), (float(d.max) - float(d.min)) / math.sqrt(12.0)
    if isinstance(d, schema.Gaussian):
        return float(d.mean), float(d.stddev)
    return _support_floor(d), 0.0


def force_ratio_high(spec: DispersionSpec, sigmas: float = 3.0) -> float:
    """How far above the nominal models' the aerodynamic acceleration of a sample may reach: the
    product of the mean density, max(lift, drag) and 1/mass scales times 1 + ``sigmas`` x the
    root-sum-square of their relative standard deviations (with the atmosphere perturbations'
    largest density sigma and the aerodynamic regimes' largest lift or drag sigma) plus the
    density waves' largest amplitude; winds left out (they change the airspeed, not the
    coefficients). 1 when nothing of these is dispersed."""
    (rho, s_rho), (lift, s_lift), (drag, s_drag), (mass, s_mass) = (
        _mean_and_sigma(getattr(spec, name)) for name in ("density_scale", "lift_scale", "drag_scale", "mass_scale"))
    coefficient = max(lift, drag)
    parts = [s_rho / rho, max(s_lift / lift, s_drag / drag), s_mass / mass]
    if spec.atmosphere_perturbations is not None:
        parts.append(max(spec.atmosphere_perturbations.density_sigma, default=0.0))
    if spec.aero_regimes is not None:
        parts.append(max(max(spec.aero_regimes.lift_sigma), max(spec.aero_regimes.drag_sigma)))
    wave = _three_sigma(spec.density_wave_amplitude)
    return rho * coefficient / mass * (1.0 + sigmas * math.hypot(*parts) + wave)


def force_dispersions(spec: DispersionSpec) -> list[str]:
    """The dispersions that make a sample's lift or drag differ from the nominal models' at the
    same state (density, its waves and perturbations, winds, aerodynamic scales and regimes,
    mass), by their field names; empty when only the entry and the navigation are dispersed."""
    names = [name for name, nominal in (("density_scale", 1.0), ("lift_scale", 1.0), ("drag_scale", 1.0),
                                        ("mass_scale", 1.0), ("density_wave_amplitude", 0.0))
             if not _support_floor(getattr(spec, name)) == nominal == _support_ceiling(getattr(spec, name))]
    regimes = spec.aero_regimes
    if regimes is not None and (any(regimes.lift_sigma) or any(regimes.drag_sigma) or regimes.trim_alpha_sigma_deg):
        names.append("aero_regimes")
    return names + [name for name in ("atmosphere_perturbations", "winds") if getattr(spec, name) is not None]


def validate(spec: DispersionSpec, where: str = "dispersions") -> None:
    """Shape and range checks that do not need a draw."""
    for f in dc.fields(EntryDispersionSpec):
        _check_distribution(f"{where}.entry.{f.name}", getattr(spec.entry, f.name))
    for name in ("density_scale", "density_wave_amplitude", "lift_scale", "drag_scale", "mass_scale", "nav_bias"):
        _check_distribution(f"{where}.{name}", getattr(spec, name))
    for name in ("density_scale", "lift_scale", "drag_scale", "mass_scale"):
        low = _support_floor(getattr(spec, name))
        if not low > 0:
            raise ScenarioError(f"{where}.{name} reaches {low:g}; a scale must stay > 0 over its whole distribution "
                                f"(the value, a Uniform's min, a Gaussian's mean - {GAUSSIAN_REACH:g} stddev)")
    amplitude = spec.density_wave_amplitude
    reach = max(abs(_support_floor(amplitude)), abs(_support_ceiling(amplitude)))
    if not reach < DENSITY_WAVE_AMPLITUDE_BOUND:
        raise ScenarioError(f"{where}.density_wave_amplitude reaches {reach:g}; allowed: |amplitude| < "
                            f"{DENSITY_WAVE_AMPLITUDE_BOUND:g} over its whole distribution (density stays positive)")
    if np.asarray(spec.nav_bias.Mean()).size != 6:
        raise ScenarioError(f"{where}.nav_bias needs 6 entries [h, lon, lat, V, gamma, psi]")
    if len(spec.nav_noise_sigma) != 6 or not all(0 <= v < math.inf for v in spec.nav_noise_sigma):
        raise ScenarioError(f"{where}.nav_noise_sigma needs 6 entries >= 0")
    if not spec.density_wave_length_km > 0:
        raise ScenarioError(f"{where}.density_wave_length_km must be > 0, got {spec.density_wave_length_km}")
    if spec.aero_regimes is not None:
        _validate_aero_regimes(spec.aero_regimes, f"{where}.aero_regimes")
    if spec.entry_covariance is not None:
        check_covariance(spec.entry_covariance, f"{where}.entry_covariance",
                         "[altitude m, longitude deg, latitude deg, speed m/s, flight-path deg, heading deg]")
    if spec.atmosphere_perturbations is not None:
        validate_perturbations(spec.atmosphere_perturbations, f"{where}.atmosphere_perturbations")
    if spec.winds is not None:
        validate_winds(spec.winds, f"{where}.winds")
    if spec.inertial_navigation is not None:
        validate_inertial_navigation(spec.inertial_navigation, f"{where}.inertial_navigation")
        fixed_bias = isinstance(spec.nav_bias, schema.DeterministicVectorX) and not any(spec.nav_bias.value)
        if not fixed_bias or any(spec.nav_noise_sigma):
            raise ScenarioError(f"{where}: nav_bias / nav_noise_sigma and inertial_navigation are two navigation "
                                f"models; give one")


#: a relative aerodynamic error's 1-sigma is below this, so the coefficient stays positive to 5 sigma
MAX_AERO_SIGMA = 1.0 / GAUSSIAN_REACH


def _validate_aero_regimes(a: AeroRegimeDispersionSpec, where: str) -> None:
    n = len(AERO_REGIMES)
    if len(a.mach_boundaries) != n - 1:
        raise ScenarioError(f"{where}.mach_boundaries needs {n - 1} Mach numbers (between {', '.join(AERO_REGIMES)}), "
                            f"got {len(a.mach_boundaries)}")
    gaps = np.diff([0.0, *a.mach_boundaries])
    if not all(math.isfinite(b) for b in a.mach_boundaries) or not np.all(gaps > 0):
        raise ScenarioError(f"{where}.mach_boundaries = {a.mach_boundaries} must be finite, positive and increasing")
    if not (math.isfinite(a.blend_mach) and 0 < a.blend_mach <= gaps.min()):
        raise ScenarioError(f"{where}.blend_mach = {a.blend_mach} is out of range; allowed: > 0 and at most the "
                            f"narrowest regime ({gaps.min():g})")
    for name in ("lift_sigma", "drag_sigma", "correlation"):
        values = getattr(a, name)
        if len(values) != n:
            raise ScenarioError(f"{where}.{name} needs {n} values (one per regime: {', '.join(AERO_REGIMES)}), "
                                f"got {len(values)}")
        if name == "correlation":
            inside, allowed = (lambda v: -1.0 <= v <= 1.0), "[-1, 1]"
        else:
            inside = (lambda v: 0.0 <= v < MAX_AERO_SIGMA)
            allowed = f"[0, {MAX_AERO_SIGMA:g}) (a coefficient stays positive to {GAUSSIAN_REACH:g} sigma)"
        for i, v in enumerate(values):
            if not (math.isfinite(v) and inside(v)):
                raise ScenarioError(f"{where}.{name}[{i}] ({AERO_REGIMES[i]}) = {v} is out of range; allowed: {allowed}")
    if not (math.isfinite(a.trim_alpha_sigma_deg) and 0 <= a.trim_alpha_sigma_deg <= 10):
        raise ScenarioError(f"{where}.trim_alpha_sigma_deg = {a.trim_alpha_sigma_deg} is out of range; allowed: "
                            f"[0, 10] deg")
