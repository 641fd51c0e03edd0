"""Drag-energy corridor (paper 000 Sec. VI.A, eqs. 64-70).

At each energy E = V^2/2 - mu/(R + h) the angle of attack is alpha(E), so every path
constraint is a function of altitude alone along the energy level. For each constraint
the altitude where it reaches its limit is found by a bracketing root solve (the paper
uses bisection; Brent's method here) and the drag there is that constraint's upper bound
(eqs. 65, 67, 69). The lower bound is the equilibrium glide with the full lift vertical
(L = g - V^2/r, sigma = 0). Margins shrink the corridor symmetrically.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.optimize import brentq

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.constraints import PathLimits
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle

__all__ = ["BOUND_NAMES", "Corridor", "compute_corridor"]

BOUND_NAMES = ("heat_flux", "normal_load", "dynamic_pressure", "total_load")


@dataclass
class Corridor:
    """Drag bounds [m/s^2] on an energy grid [J/kg] (increasing order).

    Attributes:
      energy: grid. alpha: alpha(E) [rad].
      upper: dict constraint -> D_max of that constraint (inf where it never binds).
      D_max, D_min: min of the upper bounds and the equilibrium-glide bound, margins applied.
      margin: relative margin applied to both bounds.
    """

    energy: np.ndarray
    alpha: np.ndarray
    upper: dict
    D_eq_glide: np.ndarray
    margin: float = 0.0
    D_max: np.ndarray = field(init=False)
    D_min: np.ndarray = field(init=False)

    def __post_init__(self):
        stack = np.vstack([self.upper[k] for k in self.upper])
        self.D_max = stack.min(axis=0) * (1.0 - self.margin)
        self.D_min = self.D_eq_glide * (1.0 + self.margin)

    def active(self) -> list[str]:
        """Name of the binding upper constraint at each grid energy."""
        names = list(self.upper)
        stack = np.vstack([self.upper[k] for k in names])
        return [names[i] for i in stack.argmin(axis=0)]

    def bounds(self, E) -> tuple[np.ndarray, np.ndarray]:
        """(D_min, D_max) interpolated in log-drag at energies E."""
        return (np.exp(np.interp(E, self.energy, np.log(self.D_min))),
                np.exp(np.interp(E, self.energy, np.log(self.D_max))))

    @property
    def empty_at(self) -> np.ndarray:
        """Energies where D_min > D_max (no feasible drag)."""
        return self.energy[self.D_min > self.D_max]


def _speed(E: float, r: float, mu: float) -> float:
    v2 = 2.0 * (E + mu / r)
    return math.sqrt(v2) if v2 > 0 else 0.0


def compute_corridor(energies, alpha_of_E: Callable[[float], float], vehicle: Vehicle, planet: Earth,
                     atmosphere: Atmosphere, limits: PathLimits | None = None, *, margin: float = 0.0,
                     h_floor: float = 0.0, lat_of_E: Callable[[float], float] | None = None) -> Corridor:
    """Corridor on the given energies [J/kg] (any order; stored increasing).

    Args:
      alpha_of_E: scheduled angle of attack [rad] at energy E.
      limits: path limits (default: the vehicle's).
      margin: relative safety margin on both bounds (e.g. 0.05).
      h_floor: lowest altitude searched [m] (of the air, where ``lat_of_E`` places it).
      lat_of_E: the latitude [rad] where the vehicle is expected at energy E: the air is read
        there, at ``planet.atmospheric_altitude`` (the geodetic altitude on an oblate planet, as
        the plant reads it); None reads it at the state altitude.
    """
    limits = limits or vehicle.limits
    if not 0.0 <= margin < 0.5:
        raise ScenarioError(f"corridor margin must be in [0, 0.5), got {margin}")
    E_grid = np.sort(np.asarray(energies, float))
    mu, S_m, g0 = planet.mu, vehicle.area_over_mass, planet.g0
    upper = {k: np.full(E_grid.size, np.inf) for k in BOUND_NAMES}
    D_eq = np.zeros(E_grid.size)
    alphas = np.array([alpha_of_E(E) for E in E_grid])

    for i, (E, alpha) in enumerate(zip(E_grid, alphas)):
        h_top = mu / (-E) - planet.reference_radius  # V = 0 on this energy level
        lat = None if lat_of_E is None else float(lat_of_E(E))
        h_lo = h_floor if lat is None else float(planet.state_altitude(h_floor, lat))  # state altitudes
        if not h_top > h_lo:
            raise ScenarioError(f"energy {E:.6g} J/kg is below the surface energy; corridor undefined there")
        h_hi = min(h_top - 1.0, atmosphere.h_max if lat is None else float(planet.state_altitude(atmosphere.h_max, lat)))
        sa, ca = math.sin(alpha), math.cos(alpha)

        def state(h):
            r = planet.radius(h)
            V = _speed(E, r, mu)
            rho, _, a = atmosphere.properties(h if lat is None else float(planet.atmospheric_altitude(h, lat)))
            cl, cd = vehicle.aero.coefficients(alpha, V / a if a > 0 else 0.0)
            q = 0.5 * rho * V * V
            return r, V, rho, q, q * S_m * cl, q * S_m * cd

        def drag_at(h):
            return state(h)[5]

        def excess(name):
            def f(h):
                r, V, rho, q, L, D = state(h)
                if name == "heat_flux":
                    return vehicle.heat_flux(rho, V) / limits.heat_flux_max - 1.0
                if name == "dynamic_pressure":
                    return q / limits.dynamic_pressure_max - 1.0
                if name == "normal_load":
                    return abs(L * ca + D * sa) / g0 / limits.normal_load_max - 1.0
                return math.hypot(L, D) / g0 / limits.total_load_max - 1.0
            return f

        for name in BOUND_NAMES:
            if not np.isfinite(getattr(limits, {"heat_flux": "heat_flux_max", "dynamic_pressure":
                                                  "dynamic_pressure_max", "normal_load": "normal_load_max",
                                                  "total_load": "total_load_max"}[name])):
                continue
            f = excess(name)
            if f(h_lo) < 0.0:  # never reached on this energy level
                continue
            upper[name][i] = drag_at(brentq(f, h_lo, h_hi, xtol=1e-3))

        def glide(h):
            r, V, rho, q, L, D = state(h)
            return L - (planet.mu / (r * r) - V * V / r)

        if glide(h_hi) >= 0.0:  # super-circular or lift to spare up to the top: no lower bound
            D_eq[i] = 0.0
        elif glide(h_lo) < 0.0:
            D_eq[i] = np.inf
        else:
            D_eq[i] = drag_at(brentq(glide, h_lo, h_hi, xtol=1e-3))
    return Corridor(E_grid, alphas, upper, D_eq, margin)
