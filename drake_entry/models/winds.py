"""Horizontal winds: a profile by altitude (east and north components), a Monte-Carlo sample's
wind (a mean profile plus perturbations correlated in altitude, in the manner of Earth-GRAM:
Leslie & Justus, NASA/TM-2011-216467), and the atmosphere that carries it.

The wind moves the air, not the vehicle: the equations of motion keep the Earth-relative state
and take the aerodynamic force from the air-relative velocity (models.dynamics). Each component's
perturbation is sigma(h) [sqrt(f) B + sqrt(1 - f) S(h)] as the density's
(models.atmosphere_perturbations), the east and north components independent. Altitude only: a
long glide at nearly constant altitude sees one wind (no horizontal correlation).
(No ``from __future__ import annotations``: pydrake's YAML reads the spec's field types.)
"""
import dataclasses as dc

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import Atmosphere, held_linear, held_linear_expression
from drake_entry.models.atmosphere_perturbations import (
    AltitudeProcessSpec,
    process_nodes_km,
    unit_profiles,
    validate_process,
)
from drake_entry.models.scalar import is_autodiff, is_symbolic, lift

__all__ = ["MAX_WIND_M_S", "WindSpec", "validate_winds", "draw_wind", "WindProfile", "WindyAtmosphere"]

#: no mean wind or 5-sigma wind beyond this speed [m/s] is accepted (the strongest measured
#: jets are below 200 m/s)
MAX_WIND_M_S = 300.0


@dc.dataclass
class WindSpec(AltitudeProcessSpec):
    """A Monte-Carlo sample's horizontal wind (module docstring)."""

    # mean wind towards the east and towards the north [m/s] at altitude_km
    east_mean_m_s: list[float] = dc.field(default_factory=lambda: [0.0, 0.0])
    north_mean_m_s: list[float] = dc.field(default_factory=lambda: [0.0, 0.0])
    # 1-sigma of each horizontal component's perturbation [m/s] at altitude_km
    sigma_m_s: list[float] = dc.field(default_factory=lambda: [0.0, 0.0])


def validate_winds(w: WindSpec, where: str) -> None:
    """One-line ScenarioErrors naming the field."""
    mean, mean_text = (lambda v: -MAX_WIND_M_S <= v <= MAX_WIND_M_S), f"[{-MAX_WIND_M_S:g}, {MAX_WIND_M_S:g}] m/s"
    validate_process(w, where, [("east_mean_m_s", mean, mean_text), ("north_mean_m_s", mean, mean_text),
                                ("sigma_m_s", lambda v: 0.0 <= v <= MAX_WIND_M_S / 5.0,
                                 f"[0, {MAX_WIND_M_S / 5.0:g}] m/s")])


def draw_wind(w: WindSpec, generator) -> "WindProfile":
    """One sample's wind profile: one draw of the sample's generator seeds its normal draws."""
    rng = np.random.default_rng(int(generator()))
    nodes_km = process_nodes_km(w)
    unit = unit_profiles(rng, nodes_km, w.large_scale_fraction, w.vertical_scale_km, 0.0)
    sigma = np.interp(nodes_km, w.altitude_km, w.sigma_m_s)
    east = np.interp(nodes_km, w.altitude_km, w.east_mean_m_s) + sigma * unit[:, 0]
    north = np.interp(nodes_km, w.altitude_km, w.north_mean_m_s) + sigma * unit[:, 1]
    return WindProfile(nodes_km * 1e3, east, north)


class WindProfile:
    """Wind towards the east and the north [m/s], linear in altitude between the nodes and held
    beyond the ends; evaluated at a float, AutoDiffXd or symbolic altitude [m].

    Args: altitude_m (increasing nodes [m]), east_m_s and north_m_s (the components there).
    """

    def __init__(self, altitude_m, east_m_s, north_m_s):
        h, e, n = (np.asarray(v, float) for v in (altitude_m, east_m_s, north_m_s))
        if not (h.ndim == 1 and h.size >= 2 and e.shape == h.shape and n.shape == h.shape
                and np.all(np.diff(h) > 0) and np.all(np.isfinite(e)) and np.all(np.isfinite(n))):
            raise ScenarioError("WindProfile needs increasing altitude nodes and finite east and north winds at each")
        self.nodes, self.east, self.north = h, e, n

    def __call__(self, h):
        """(east, north) wind [m/s] at altitude h [m] (the scalar type of h)."""
        if is_symbolic(h):
            return tuple(held_linear_expression(h, self.nodes, d) for d in (self.east, self.north))
        hv = float(h.value()) if is_autodiff(h) else float(h)
        out = []
        for d in (self.east, self.north):
            value, slope = (float(v) for v in held_linear(hv, self.nodes, d))
            out.append(lift([h], value, [slope]) if is_autodiff(h) else value)
        return tuple(out)


class WindyAtmosphere(Atmosphere):
    """``base``'s density and temperature with the horizontal wind ``winds`` (a WindProfile):
    every air-data call goes to ``base``; ``wind(h)`` gives the wind."""

    def __init__(self, base: Atmosphere, winds: WindProfile):
        self.base, self.winds = base, winds
        self.name = f"{base.name} with winds"
        self.h_min, self.h_max = base.h_min, base.h_max
        self.gas_constant, self.gamma = base.gas_constant, base.gamma

    def wind(self, h):
        return self.winds(h)

    @property
    def has_wind(self) -> bool:
        return True

    def air_data(self, h):
        return self.base.air_data(h)

    def properties(self, h):
        return self.base.properties(h)

    def symbolic_profile(self, h) -> tuple:
        return self.base.symbolic_profile(h)

    def density_derivatives(self, h):
        return self.base.density_derivatives(h)

    def temperature_derivatives(self, h):
        return self.base.temperature_derivatives(h)

    def derivatives(self, h):
        return self.base.derivatives(h)
