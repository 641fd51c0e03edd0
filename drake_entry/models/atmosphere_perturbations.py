"""Atmospheric density and temperature perturbations along the flight, in the manner of
Earth-GRAM (Leslie & Justus, NASA/TM-2011-216467; White & Hoffman, NASA/TM-20210022157): each
perturbation is a large-scale part, one value per flight, plus a small-scale part, a random
process correlated over a vertical scale length; its 1-sigma is a profile in altitude (GRAM's
grows with altitude), given with its source in the scenario.

For a quantity q (density or temperature), at altitude h:

    d_q(h) = sigma_q(h) [sqrt(f) B_q + sqrt(1 - f) S_q(h)]

with f the large-scale share of the variance, B_q a standard normal drawn once per flight and
S_q a zero-mean unit-variance Gauss-Markov process in altitude,
corr(S_q(h1), S_q(h2)) = exp(-|h1 - h2| / L) (drawn exactly on a grid of ``step_km`` by its AR(1)
recursion, phi = exp(-step / L)); density and temperature share their draws with the correlation
``density_temperature_correlation``. So var d_q(h) = sigma_q(h)^2 and, where sigma is constant,
corr(d_q(h1), d_q(h2)) = f + (1 - f) exp(-|h1 - h2| / L). The perturbation depends on altitude
only: for a descending entry altitude orders the path, for a long glide at nearly constant
altitude the horizontal correlation GRAM also models is not represented. Every draw comes from
the sample's generator, so a sample re-runs alone. (No ``from __future__ import annotations``:
pydrake's YAML reads the spec's field types.)
"""
import dataclasses as dc
import math

import numpy as np
from scipy.signal import lfilter

from drake_entry.errors import ScenarioError

__all__ = ["MAX_PERTURBATION_SIGMA", "AltitudeProcessSpec", "AtmospherePerturbationSpec", "validate_process",
           "process_nodes_km", "validate_perturbations", "unit_profiles", "draw_profiles"]

#: a perturbation's 1-sigma is below this, so the density and temperature stay positive to 5 sigma
MAX_PERTURBATION_SIGMA = 0.2


@dc.dataclass
class AltitudeProcessSpec:
    """The altitude grid of a perturbation profile and the process it is drawn with (module
    docstring): shared by the density and temperature perturbations and the winds."""

    # altitudes [km] of the profiles below (increasing); the profiles hold beyond the ends
    altitude_km: list[float] = dc.field(default_factory=lambda: [0.0, 150.0])
    # share of the variance in the large-scale part (one value per flight), 0..1
    large_scale_fraction: float = 0.5
    # vertical correlation length of the small-scale part [km]
    vertical_scale_km: float = 5.0
    # the grid the small-scale process is drawn on [km] (linear between its nodes)
    step_km: float = 0.5
    # the altitude span of the drawn profile [km]; beyond it the end values hold
    top_km: float = 150.0


@dc.dataclass
class AtmospherePerturbationSpec(AltitudeProcessSpec):
    """Density and temperature perturbation profiles of a Monte-Carlo sample (module docstring)."""

    # 1-sigma of the density and of the temperature perturbation [fraction] at altitude_km
    density_sigma: list[float] = dc.field(default_factory=lambda: [0.0, 0.0])
    temperature_sigma: list[float] = dc.field(default_factory=lambda: [0.0, 0.0])
    # correlation of the density and temperature perturbations (both parts)
    density_temperature_correlation: float = 0.0


def validate_process(p: AltitudeProcessSpec, where: str, profiles) -> None:
    """One-line ScenarioErrors naming the field: the altitudes, the process, and each of
    ``profiles`` ((field name, inside(value) -> bool, the allowed range in words)) one finite
    value per altitude inside its range."""
    h = np.asarray(p.altitude_km, float)
    if h.ndim != 1 or h.size < 1 or not np.all(np.isfinite(h)) or np.any(np.diff(h) <= 0):
        raise ScenarioError(f"{where}.altitude_km = {p.altitude_km} must be finite and sorted increasing")
    for name, inside, allowed in profiles:
        values = getattr(p, name)
        if len(values) != h.size:
            raise ScenarioError(f"{where}.{name} needs one value per altitude ({h.size}), got {len(values)}")
        for i, v in enumerate(values):
            if not (math.isfinite(v) and inside(v)):
                raise ScenarioError(f"{where}.{name}[{i}] = {v} is out of range; allowed: {allowed}")
    checks = (("large_scale_fraction", 0.0, 1.0), ("vertical_scale_km", 1e-3, 1e3), ("step_km", 1e-2, 10.0),
              ("top_km", 1.0, 1e3))
    for name, lo, hi in checks:
        v = getattr(p, name)
        if not (math.isfinite(v) and lo <= v <= hi):
            raise ScenarioError(f"{where}.{name} = {v} is out of range; allowed: [{lo:g}, {hi:g}]")


def process_nodes_km(p: AltitudeProcessSpec) -> np.ndarray:
    """The altitude grid [km] a profile of ``p`` is drawn on."""
    return np.arange(0.0, p.top_km + 0.5 * p.step_km, p.step_km)


def validate_perturbations(p: AtmospherePerturbationSpec, where: str) -> None:
    """One-line ScenarioErrors naming the field."""
    inside = lambda v: 0.0 <= v < MAX_PERTURBATION_SIGMA  # noqa: E731
    allowed = f"[0, {MAX_PERTURBATION_SIGMA:g}) (the quantity stays positive to 5 sigma)"
    validate_process(p, where, [("density_sigma", inside, allowed), ("temperature_sigma", inside, allowed)])
    v = p.density_temperature_correlation
    if not (math.isfinite(v) and -1.0 <= v <= 1.0):
        raise ScenarioError(f"{where}.density_temperature_correlation = {v} is out of range; allowed: [-1, 1]")


def unit_profiles(rng, nodes_km: np.ndarray, large_scale_fraction: float, vertical_scale_km: float,
                  correlation: float) -> np.ndarray:
    """Two unit-variance profiles [n x 2] on the altitude grid ``nodes_km`` (evenly spaced): per
    column sqrt(f) B + sqrt(1 - f) S(h) (module docstring), the two columns correlated by
    ``correlation`` in both parts; every normal draw from the numpy generator ``rng``."""
    n = nodes_km.size
    step = float(nodes_km[1] - nodes_km[0]) if n > 1 else 1.0
    mix = math.sqrt(max(0.0, 1.0 - correlation * correlation))
    b = rng.standard_normal(2)
    bias = np.array([b[0], correlation * b[0] + mix * b[1]])
    e = rng.standard_normal((n, 2))
    e[:, 1] = correlation * e[:, 0] + mix * e[:, 1]
    phi = math.exp(-step / vertical_scale_km)
    root = math.sqrt(1.0 - phi * phi)
    # s[0] = e[0], s[k] = phi s[k-1] + root e[k]: the exact discretisation of corr exp(-dh / L)
    e[0] /= root
    s = lfilter([root], [1.0, -phi], e, axis=0)
    f = large_scale_fraction
    return math.sqrt(f) * bias + math.sqrt(1.0 - f) * s


def draw_profiles(p: AtmospherePerturbationSpec, generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(altitude nodes [m], density perturbation, temperature perturbation) of one sample: one
    draw of the sample's generator seeds the profile's normal draws."""
    rng = np.random.default_rng(int(generator()))
    nodes_km = process_nodes_km(p)
    unit = unit_profiles(rng, nodes_km, p.large_scale_fraction, p.vertical_scale_km,
                         p.density_temperature_correlation)
    sigma = np.column_stack([np.interp(nodes_km, p.altitude_km, p.density_sigma),
                             np.interp(nodes_km, p.altitude_km, p.temperature_sigma)])
    d = sigma * unit
    return nodes_km * 1e3, d[:, 0], d[:, 1]
