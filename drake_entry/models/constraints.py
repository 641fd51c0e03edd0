"""Path constraints: heat flux (every form the papers use), dynamic pressure, load factors,
and the equilibrium-glide condition. Functions are generic over the scalar type.

All heat-flux forms reduce to q_dot = q_a(alpha) K rho^n V^m [W/m^2], with the angle-of-attack
factor q_a = 1 unless a form gives one (Betts' shuttle wing leading edge: a cubic in alpha);
the named constructors keep each paper's constants and never mix the V^3 and V^3.15
families (docs/references.md, "Heat flux").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["FT", "SLUG", "BTU_FT2_S", "HeatFlux", "make_heat_flux", "dynamic_pressure", "signed_normal_load_factor", "normal_load_factor",
           "total_load_factor", "equilibrium_glide_lift", "PathLimits"]

# US customary units (exact SI conversions) for forms published in them
FT = 0.3048  # m
SLUG = 14.593902937  # kg
BTU_FT2_S = 1055.05585262 / FT ** 2  # W/m^2 per BTU/ft^2/s (international-table BTU)


@dataclass(frozen=True)
class HeatFlux:
    """Heat flux q_dot = q_a(alpha) * coefficient * rho^density_exponent * V^velocity_exponent.

    Attributes:
      coefficient: K in SI units such that q_dot is in W/m^2.
      density_exponent: n (0.5 for every form in the papers).
      velocity_exponent: m (3 or 3.15).
      form: a label saying which published form produced the constants.
      alpha_factor: coefficients c_0, c_1, ... of q_a = sum c_i alpha^i (empty: q_a = 1).
      alpha_unit: 'deg' or 'rad', the unit of alpha in q_a.
    """

    coefficient: float
    density_exponent: float = 0.5
    velocity_exponent: float = 3.15
    form: str = "custom"
    alpha_factor: tuple = ()
    alpha_unit: str = "deg"

    def __post_init__(self):
        if not self.coefficient > 0:
            raise ScenarioError(f"HeatFlux.coefficient must be > 0, got {self.coefficient}")
        if self.alpha_unit not in ("deg", "rad"):
            raise ScenarioError(f"HeatFlux.alpha_unit = '{self.alpha_unit}'; allowed: deg, rad")
        if not all(np.isfinite(c) for c in self.alpha_factor):
            raise ScenarioError(f"HeatFlux.alpha_factor = {list(self.alpha_factor)} must be finite numbers")
        object.__setattr__(self, "alpha_factor", tuple(float(c) for c in self.alpha_factor))

    def __call__(self, rho, V, alpha=None):
        """q_dot [W/m^2] at density rho [kg/m^3], speed V [m/s] and, for a form with an
        angle-of-attack factor, alpha [rad]."""
        q = self.coefficient * rho**self.density_exponent * V**self.velocity_exponent
        if not self.alpha_factor:
            return q
        if alpha is None:
            raise ScenarioError(f"heat-flux form '{self.form}' has an angle-of-attack factor: this caller "
                                f"gives no alpha (use it where alpha is known, e.g. the NLP path)")
        a = alpha * (180.0 / np.pi) if self.alpha_unit == "deg" else alpha
        factor = 0.0
        for c in reversed(self.alpha_factor):  # Horner
            factor = factor * a + c
        return factor * q

    def factor(self, alpha):
        """q_a(alpha) [-] (1 without an angle-of-attack factor); alpha [rad]."""
        return self(1.0, 1.0, alpha) / self.coefficient

    @staticmethod
    def betts_shuttle() -> "HeatFlux":
        """Space Shuttle wing leading edge (Betts, Practical Methods for Optimal Control,
        2nd ed., 2010, Sec. 6.1): q = q_a q_r [BTU/ft^2/s] with q_r = 17 700 sqrt(rho)
        (1e-4 V)^3.07 (rho slug/ft^3, V ft/s) and q_a = 1.0672181 - 0.19213774e-1 a
        + 0.21286289e-3 a^2 - 0.10117249e-5 a^3 (a in deg); converted to SI exactly."""
        k = 17700.0 * (FT ** 3 / SLUG) ** 0.5 * (1e-4 / FT) ** 3.07 * BTU_FT2_S
        return HeatFlux(k, 0.5, 3.07, "betts_shuttle",
                        (1.0672181, -0.19213774e-1, 0.21286289e-3, -0.10117249e-5), "deg")

    @staticmethod
    def chapman(nose_radius: float, C1: float = 5.28137e-5, m: float = 3.15) -> "HeatFlux":
        """q = C1/sqrt(R_N) sqrt(rho) V^m (paper 000 eq. 34)."""
        _check_nose(nose_radius)
        return HeatFlux(C1 / np.sqrt(nose_radius), 0.5, m, "chapman")

    @staticmethod
    def sutton_graves(nose_radius: float, k: float = 1.7415e-4) -> "HeatFlux":
        """q = k sqrt(rho / R_N) V^3 (Sutton & Graves 1971, Earth)."""
        _check_nose(nose_radius)
        return HeatFlux(k / np.sqrt(nose_radius), 0.5, 3.0, "sutton_graves")

    @staticmethod
    def normalised(nose_radius: float, c_star: float = 1.1097e8, n: float = 0.5, m: float = 3.15,
                   rho0: float = 1.225, v_circular: float = 7905.0) -> "HeatFlux":
        """q = c*/R_N^n (rho/rho0)^(1-n) (V/V_c)^m (paper 001 eq. 9)."""
        _check_nose(nose_radius)
        return HeatFlux(c_star / nose_radius**n / rho0 ** (1 - n) / v_circular**m, 1 - n, m, "normalised")

    @staticmethod
    def lumped(k: float, m: float) -> "HeatFlux":
        """q = k sqrt(rho) V^m with the nose radius folded into k
        (paper 003 eq. 3: k = 1.2444e-3, m = 3; paper 004 eq. 13: k = 9.4369e-5, m = 3.15)."""
        return HeatFlux(k, 0.5, m, "lumped")


def _check_nose(r):
    if not r > 0:
        raise ScenarioError(f"nose_radius must be > 0 m, got {r}")


def make_heat_flux(form: str, *, nose_radius: float, coefficient: float | None = None,
                   velocity_exponent: float | None = None, circular_speed: float | None = None,
                   alpha_factor=(), alpha_unit: str = "deg") -> HeatFlux:
    """Heat-flux model by form name: 'chapman', 'sutton_graves', 'normalised', 'lumped' or
    'betts_shuttle' (``circular_speed`` [m/s] is the normalised form's V_c); ``alpha_factor``
    (c_0, c_1, ... in ``alpha_unit``) multiplies any form by q_a(alpha)."""
    hf = _heat_flux_form(form, nose_radius, coefficient, velocity_exponent, circular_speed)
    if alpha_factor:
        if hf.alpha_factor:
            raise ScenarioError(f"heat_flux form '{form}' has its own angle-of-attack factor; give no alpha_factor")
        hf = replace(hf, alpha_factor=tuple(alpha_factor), alpha_unit=alpha_unit)
    return hf


def _heat_flux_form(form, nose_radius, coefficient, velocity_exponent, circular_speed) -> HeatFlux:
    if coefficient is not None and not 0 < coefficient < math.inf:
        raise ScenarioError(f"heat_flux.coefficient = {coefficient} is out of range; allowed: a finite number > 0 "
                            f"(empty: the form's published constant)")
    if velocity_exponent is not None:
        if form == "sutton_graves":
            raise ScenarioError(f"heat_flux.velocity_exponent applies to forms chapman, normalised and lumped; form "
                                f"'{form}' has its own (give none)")
        if not 0 < velocity_exponent <= 10:
            raise ScenarioError(f"heat_flux.velocity_exponent = {velocity_exponent} is out of range; allowed: (0, 10] "
                                f"(Chapman 3.15, Sutton-Graves 3)")
    if circular_speed is not None and (form != "normalised" or not 0 < circular_speed < 1e5):
        raise ScenarioError(f"heat_flux.circular_speed_m_s = {circular_speed} applies to form 'normalised' only "
                            f"and must be in (0, 1e5) m/s")
    if form == "chapman":
        kw = {} if coefficient is None else {"C1": coefficient}
        if velocity_exponent is not None:
            kw["m"] = velocity_exponent
        return HeatFlux.chapman(nose_radius, **kw)
    if form == "sutton_graves":
        return HeatFlux.sutton_graves(nose_radius, **({} if coefficient is None else {"k": coefficient}))
    if form == "normalised":
        kw = {} if coefficient is None else {"c_star": coefficient}
        if velocity_exponent is not None:
            kw["m"] = velocity_exponent
        if circular_speed is not None:
            kw["v_circular"] = circular_speed
        return HeatFlux.normalised(nose_radius, **kw)
    if form == "lumped":
        if coefficient is None or velocity_exponent is None:
            raise ScenarioError("heat_flux form 'lumped' needs coefficient and velocity_exponent")
        return HeatFlux.lumped(coefficient, velocity_exponent)
    if form == "betts_shuttle":
        if coefficient is not None or velocity_exponent is not None:
            raise ScenarioError("heat_flux form 'betts_shuttle' takes no coefficient or velocity_exponent")
        return HeatFlux.betts_shuttle()
    raise ScenarioError(f"heat_flux.form '{form}' is unknown; allowed: chapman, sutton_graves, normalised, lumped, "
                        f"betts_shuttle")


def dynamic_pressure(rho, V):
    """q = rho V^2 / 2 [Pa] (paper 000 eq. 36)."""
    return 0.5 * rho * V * V


def signed_normal_load_factor(lift_acc, drag_acc, alpha, g0: float):
    """(L cos(alpha) + D sin(alpha)) / g0 (paper 000 eq. 35 before its absolute value), L, D in
    m/s^2: positive in flight, and smooth where a planner differentiates it."""
    return (lift_acc * np.cos(alpha) + drag_acc * np.sin(alpha)) / g0


def normal_load_factor(lift_acc, drag_acc, alpha, g0: float):
    """n_z = |L cos(alpha) + D sin(alpha)| / g0 (paper 000 eq. 35), L, D in m/s^2."""
    return abs(signed_normal_load_factor(lift_acc, drag_acc, alpha, g0))


def total_load_factor(lift_acc, drag_acc, g0: float):
    """n = sqrt(L^2 + D^2) / g0 (paper 001 eq. 10, paper 002 eq. 7 in g)."""
    return np.sqrt(lift_acc * lift_acc + drag_acc * drag_acc) / g0


def equilibrium_glide_lift(V, r, g):
    """Vertical lift acceleration L cos(sigma) [m/s^2] that holds gamma' = 0 on a
    non-rotating planet: g - V^2 / r (paper 004 eq. 16, dimensional)."""
    return g - V * V / r


@dataclass(frozen=True)
class PathLimits:
    """Upper limits on heat flux [W/m^2], dynamic pressure [Pa], normal and total load factor [g]."""

    heat_flux_max: float = np.inf
    dynamic_pressure_max: float = np.inf
    normal_load_max: float = np.inf
    total_load_max: float = np.inf

    def __post_init__(self):
        for name in ("heat_flux_max", "dynamic_pressure_max", "normal_load_max", "total_load_max"):
            if not getattr(self, name) > 0:
                raise ScenarioError(f"PathLimits.{name} must be > 0, got {getattr(self, name)}")

    def planned_load(self) -> tuple[str, float]:
        """The load a plan bounds and its limit [g]: ('total', limit) where the vehicle limits the
        total load (paper 001 eq. 10), else ('normal', limit) (paper 000 eq. 35)."""
        if math.isfinite(self.total_load_max):
            return "total", self.total_load_max
        return "normal", self.normal_load_max

    @property
    def load_bound_max(self) -> float:
        """The lower of the normal and total load limits [g]: what a law holding one load must
        hold it under (the total load bounds the normal)."""
        return min(self.normal_load_max, self.total_load_max)

    def margins(self, *, heat_flux, dynamic_pressure, normal_load, total_load) -> dict:
        """Relative margins 1 - value/limit (negative means violated)."""
        return {
            "heat_flux": 1.0 - heat_flux / self.heat_flux_max,
            "dynamic_pressure": 1.0 - dynamic_pressure / self.dynamic_pressure_max,
            "normal_load": 1.0 - normal_load / self.normal_load_max,
            "total_load": 1.0 - total_load / self.total_load_max,
        }
