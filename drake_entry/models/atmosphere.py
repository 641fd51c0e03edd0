"""Atmosphere models: exponential (paper 000 eq. 29) and U.S. Standard Atmosphere 1976.

Every model gives density, temperature and speed of sound, and the first and second
altitude derivatives of density and temperature that the drag dynamics need (paper 000
eqs. 42-46, 59). Inputs are geometric altitude h [m]; outputs SI. Methods accept a
float, an ndarray (vectorised) or a pydrake AutoDiffXd (derivatives by the chain rule);
``properties`` and ``air_data`` also take a symbolic Expression, for which the layers and
the splines become piecewise expressions (``piecewise``: a balanced tree of
``if_then_else`` over the same breakpoints, each piece the float path's own formula), so a
Drake ``SymbolicVectorSystem`` evaluates the same model in C++ (systems/native_plant.py).

US76 below 86 km is evaluated from the standard's own layer formulas (hydrostatic
equation with piecewise-linear molecular-scale temperature in geopotential altitude), so
it reproduces the standard's tables to their printed precision. Derivatives are exact
within a layer and jump at layer boundaries where the standard's temperature has kinks.
From 86 to 1000 km the standard integrates species diffusion; we ship its tabulation
(``data/us76_upper.csv``, made with the PyPI package ``ussa1976``; regenerate with
``python -m drake_entry.models.atmosphere --write-upper-table``) and interpolate ln(rho) and T
with C2 cubic splines.
"""
from __future__ import annotations

import argparse
import bisect
import math
from dataclasses import dataclass
from importlib import resources
from typing import NamedTuple

import numpy as np
from pydrake.symbolic import Expression, if_then_else
from scipy.interpolate import CubicSpline

from drake_entry.errors import ModelRangeError, ScenarioError, UnsupportedScalarError
from drake_entry.models.data_tables import read_csv_rows
from drake_entry.models.scalar import clamp, is_autodiff, is_symbolic, lift, promote, value_of

__all__ = ["G0_US76", "R_STAR", "M0_AIR", "R_AIR", "R0_GEOPOTENTIAL", "GAMMA_AIR", "P0_SEA_LEVEL", "US76_H_MIN",
           "US76_H_MAX", "US76_LOWER_TOP", "AtmosphereProperties", "Derivatives", "piecewise", "held_linear",
           "held_linear_expression", "Atmosphere",
           "US76Atmosphere", "ExponentialAtmosphere", "TableAtmosphere", "DENSITY_WAVE_AMPLITUDE_BOUND",
           "DispersedAtmosphere", "make_atmosphere", "write_upper_table", "PerturbedAtmosphere"]

# U.S. Standard Atmosphere 1976 constants (NASA-TM-X-74335).
G0_US76 = 9.80665  # m/s^2
R_STAR = 8314.32  # J/(kmol K)
M0_AIR = 28.9644  # kg/kmol
R_AIR = R_STAR / M0_AIR  # 287.0531 J/(kg K)
R0_GEOPOTENTIAL = 6356766.0  # m
GAMMA_AIR = 1.4
P0_SEA_LEVEL = 101325.0  # Pa

US76_H_MIN = -5000.0  # m, lower end of the standard
US76_H_MAX = 1000000.0  # m
US76_LOWER_TOP = 86000.0  # m geometric


class AtmosphereProperties(NamedTuple):
    """Density [kg/m^3], temperature [K] and speed of sound [m/s]."""

    rho: object
    T: object
    a: object


class Derivatives(NamedTuple):
    """A quantity and its first and second altitude derivatives (per m, per m^2)."""

    value: object
    d_h: object
    d_hh: object


def piecewise(x, breaks, piece):
    """A symbolic Expression equal to ``piece(i)`` where breaks[i] <= x < breaks[i + 1], for the
    len(breaks) - 1 intervals; below breaks[1] the first piece, from breaks[-2] on the last (the
    index rule of the float paths, bisect_right clamped). Built as a balanced tree of
    ``if_then_else``, so an evaluation compares about log2(intervals) times and evaluates one
    piece (Drake evaluates only the branch taken)."""

    def build(lo: int, hi: int):
        if hi - lo == 1:
            return piece(lo)
        mid = (lo + hi) // 2
        return if_then_else(x < breaks[mid], build(lo, mid), build(mid, hi))

    return build(0, len(breaks) - 1)


def held_linear(h, nodes: np.ndarray, values: np.ndarray):
    """(value, slope per m) of the profile linear between ``nodes`` (increasing) through
    ``values`` and held beyond its ends (slope 0 there), at a float or ndarray h."""
    hv = np.asarray(h, float)
    k = np.clip(np.searchsorted(nodes, hv, side="right") - 1, 0, nodes.size - 2)
    inside = (hv >= nodes[0]) & (hv <= nodes[-1])
    slope = (values[k + 1] - values[k]) / (nodes[k + 1] - nodes[k])
    return np.interp(hv, nodes, values), np.where(inside, slope, 0.0)


def held_linear_expression(h, nodes: np.ndarray, values: np.ndarray, offset: float = 0.0):
    """``offset`` plus that profile (``held_linear``) as a symbolic Expression of the altitude
    Expression h: one linear piece per interval (``piecewise``), the end values beyond the ends."""
    def piece(i):
        s = (values[i + 1] - values[i]) / (nodes[i + 1] - nodes[i])
        return offset + values[i] + s * (h - nodes[i])

    inner = piecewise(h, list(nodes), piece)
    return if_then_else(h < nodes[0], Expression(offset + values[0]),
                        if_then_else(h > nodes[-1], Expression(offset + values[-1]), inner))


def _check_range(name: str, h, lo: float, hi: float):
    if is_symbolic(h):  # symbolic work has no numbers to check
        return
    hv = np.asarray(value_of(h), dtype=float)
    outside = ~((hv >= lo) & (hv <= hi))  # NaN is outside
    if outside.any():
        bad = hv[outside].flat[0]
        raise ModelRangeError(f"altitude h = {bad:.6g} m is outside the {name} range [{lo:.6g}, {hi:.6g}] m")


class Atmosphere:
    """Common interface. Subclasses implement ``density_derivatives`` and
    ``temperature_derivatives`` for float / ndarray input."""

    name = "atmosphere"
    h_min = -np.inf
    h_max = np.inf
    gas_constant = R_AIR
    gamma = GAMMA_AIR

    # -- to implement ----------------------------------------------------------------
    def density_derivatives(self, h) -> Derivatives:  # pragma: no cover - interface
        raise NotImplementedError

    def temperature_derivatives(self, h) -> Derivatives:  # pragma: no cover - interface
        raise NotImplementedError

    # -- generic ---------------------------------------------------------------------
    def wind(self, h):
        """(east, north) horizontal wind [m/s] at altitude h [m], or None in still air (every
        model here; models.winds.WindyAtmosphere adds a wind)."""
        return None

    @property
    def has_wind(self) -> bool:
        """True when ``wind`` gives a wind (the plant then takes a wind input)."""
        return False

    def check(self, h):
        _check_range(self.name, h, self.h_min, self.h_max)

    def density(self, h):
        """Density rho(h) [kg/m^3]."""
        if is_symbolic(h):
            return self.symbolic_profile(h)[0]
        if is_autodiff(h):
            d = self.density_derivatives(h.value())
            return lift([h], d.value, [d.d_h])
        return self.density_derivatives(value_of(h)).value

    def temperature(self, h):
        """Temperature T(h) [K]."""
        if is_symbolic(h):
            return self.symbolic_profile(h)[1]
        if is_autodiff(h):
            d = self.temperature_derivatives(h.value())
            return lift([h], d.value, [d.d_h])
        return self.temperature_derivatives(value_of(h)).value

    def speed_of_sound(self, h):
        """Speed of sound a = sqrt(gamma R T) [m/s] (paper 000 eq. 31, corrected)."""
        return np.sqrt(self.gamma * self.gas_constant * self.temperature(h))

    def derivatives(self, h) -> tuple[Derivatives, Derivatives]:
        """Density and temperature with their altitude derivatives (float / ndarray)."""
        return self.density_derivatives(h), self.temperature_derivatives(h)

    def air_data(self, h):
        """(density [kg/m^3], speed of sound [m/s]) at altitude h [m], any scalar type. A float
        (the simulation's once-per-derivative call) takes a path without the altitude
        derivatives, equal to ``properties`` to the last bit."""
        if isinstance(h, float):
            return self._air_data_float(h)
        rho, _, a = self.properties(h)
        return rho, a

    def _air_data_float(self, h: float) -> tuple[float, float]:
        d, t = self.derivatives(h)
        return float(d.value), math.sqrt(self.gamma * self.gas_constant * float(t.value))

    def symbolic_profile(self, h) -> tuple:
        """(density, temperature) as symbolic Expressions of the altitude Expression ``h``: the
        float model's own formulas, pieces selected by ``if_then_else``. Outside the model's
        range the end pieces extend (no range check: a symbolic plant is stopped by the
        termination monitor's altitude band, inside the range). Kept per altitude expression
        on the instance, so the dispersed copies of one nominal model share its tree."""
        h = promote(h)
        key = (h.to_string(), tuple(sorted(v.get_id() for v in h.GetVariables())))
        cache = self.__dict__.setdefault("_symbolic_profiles", {})
        if key not in cache:
            with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
                cache[key] = self._symbolic_profile(h)
        return cache[key]

    def _symbolic_profile(self, h) -> tuple:
        raise UnsupportedScalarError(f"{type(self).__name__} has no symbolic form; use US76, exponential, "
                                     f"table or a dispersed one of these")

    def properties(self, h) -> AtmosphereProperties:
        """(rho, T, a) at altitude h [m]; one model evaluation for float / AutoDiff input."""
        if is_symbolic(h):
            rho, T = self.symbolic_profile(h)
            with np.errstate(all="ignore"):
                return AtmosphereProperties(rho, T, np.sqrt(self.gamma * self.gas_constant * T))
        d, t = self.derivatives(value_of(h))
        rho = lift([h], d.value, [d.d_h]) if is_autodiff(h) else d.value
        T = lift([h], t.value, [t.d_h]) if is_autodiff(h) else t.value
        return AtmosphereProperties(rho, T, np.sqrt(self.gamma * self.gas_constant * T))


# ---------------------------------------------------------------------------------------
# U.S. Standard Atmosphere 1976
# ---------------------------------------------------------------------------------------
# Base geopotential altitudes [m'] and lapse rates [K/m'] of the seven layers below 86 km.
_H_BASE = np.array([0.0, 11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0])
_LAPSE = np.array([-6.5, 0.0, 1.0, 2.8, 0.0, -2.8, -2.0]) * 1e-3
_GMR = G0_US76 * M0_AIR / R_STAR  # K/m'


def _layer_bases():
    """Base temperature and pressure of each layer, propagated from sea level."""
    T = [288.15]
    P = [P0_SEA_LEVEL]
    for i in range(len(_H_BASE) - 1):
        dH = _H_BASE[i + 1] - _H_BASE[i]
        L = _LAPSE[i]
        Tn = T[i] + L * dH
        if L == 0.0:
            Pn = P[i] * np.exp(-_GMR * dH / T[i])
        else:
            Pn = P[i] * (T[i] / Tn) ** (_GMR / L)
        T.append(Tn)
        P.append(Pn)
    return np.array(T), np.array(P)


_T_BASE, _P_BASE = _layer_bases()


def _lower_layers(z: float):
    """ln rho, d/dz, d2/dz2, T, dT/dz, d2T/dz2 at geometric altitude z <= 86 km [m]."""
    r0 = R0_GEOPOTENTIAL
    H = r0 * z / (r0 + z)
    Hz = (r0 / (r0 + z)) ** 2
    Hzz = -2.0 * r0 * r0 / (r0 + z) ** 3
    i = max(bisect.bisect_right(_H_BASE_LIST, H) - 1, 0)
    L = _LAPSE_LIST[i]
    Tb = _T_BASE_LIST[i]
    dH = H - _H_BASE_LIST[i]
    T = Tb + L * dH
    if L == 0.0:
        lnP = _LN_P_BASE_LIST[i] - _GMR * dH / Tb
    else:
        lnP = _LN_P_BASE_LIST[i] + (_GMR / L) * math.log(Tb / T)
    ln_rho = lnP - math.log(R_AIR * T)
    # hydrostatic equilibrium + ideal gas with T linear in H:
    f_H = -(_GMR + L) / T  # d ln rho / dH
    f_HH = (_GMR + L) * L / (T * T)
    return ln_rho, f_H * Hz, f_HH * Hz * Hz + f_H * Hzz, T, L * Hz, L * Hzz


_H_BASE_LIST = _H_BASE.tolist()
_LAPSE_LIST = _LAPSE.tolist()
_T_BASE_LIST = _T_BASE.tolist()
_LN_P_BASE = np.log(_P_BASE)
_LN_P_BASE_LIST = _LN_P_BASE.tolist()


class _ScalarCubic:
    """Fast scalar evaluation of a scipy CubicSpline with its first two derivatives."""

    def __init__(self, spline: CubicSpline):
        self.x = spline.x.tolist()
        self.c = spline.c.T.tolist()  # per interval: [c3, c2, c1, c0]
        self._x, self._c = np.asarray(spline.x, float), np.asarray(spline.c.T, float)

    def __call__(self, x: float):
        i = min(max(bisect.bisect_right(self.x, x) - 1, 0), len(self.c) - 1)
        c3, c2, c1, c0 = self.c[i]
        t = x - self.x[i]
        return ((c3 * t + c2) * t + c1) * t + c0, (3.0 * c3 * t + 2.0 * c2) * t + c1, 6.0 * c3 * t + 2.0 * c2

    def symbolic(self, x):
        """The spline's value as a piecewise symbolic Expression of ``x`` (the same cubics)."""

        def piece(i):
            c3, c2, c1, c0 = self.c[i]
            t = x - self.x[i]
            return ((c3 * t + c2) * t + c1) * t + c0

        return piecewise(x, self.x, piece)

    def evaluate(self, x: np.ndarray):
        """(value, first, second derivative) arrays at an array of x (the same cubics)."""
        i = np.clip(np.searchsorted(self._x, x, side="right") - 1, 0, len(self.c) - 1)
        c3, c2, c1, c0 = self._c[i].T
        t = x - self._x[i]
        return ((c3 * t + c2) * t + c1) * t + c0, (3.0 * c3 * t + 2.0 * c2) * t + c1, 6.0 * c3 * t + 2.0 * c2


class _SplineProfile:
    """C2 cubic splines of ln rho(z) and T(z) through tabulated altitudes z [m]: the six
    quantities (ln rho, its two derivatives, T, its two derivatives) at a float or an array.
    Used by US76 above 86 km and by TableAtmosphere."""

    def __init__(self, z, rho, T):
        self.ln_rho = _ScalarCubic(CubicSpline(z, np.log(rho)))
        self.T = _ScalarCubic(CubicSpline(z, T))

    def __call__(self, z: float):
        return self.ln_rho(z) + self.T(z)

    def evaluate(self, z: np.ndarray):
        return np.array(self.ln_rho.evaluate(z) + self.T.evaluate(z))

    def symbolic(self, z):
        """(ln rho, T) as piecewise symbolic Expressions of the altitude ``z``."""
        return self.ln_rho.symbolic(z), self.T.symbolic(z)


def _load_upper_table() -> _SplineProfile:
    """US76 from 86 to 1000 km (shipped tabulation)."""
    with resources.files("drake_entry").joinpath("data/us76_upper.csv").open() as f:
        data = np.loadtxt(f, delimiter=",", comments="#")
    return _SplineProfile(data[:, 0], data[:, 1], data[:, 2])


_UPPER = None


def _upper_table() -> _SplineProfile:
    global _UPPER
    if _UPPER is None:
        _UPPER = _load_upper_table()
    return _UPPER


def _lower_layers_array(z: np.ndarray, derivatives: bool = True):
    """``_lower_layers`` for an array of altitudes <= 86 km (the same formulas with numpy);
    without ``derivatives`` only (ln rho, T)."""
    r0 = R0_GEOPOTENTIAL
    H = r0 * z / (r0 + z)
    i = np.maximum(np.searchsorted(_H_BASE, H, side="right") - 1, 0)
    L, Tb, dH = _LAPSE[i], _T_BASE[i], H - _H_BASE[i]
    T = Tb + L * dH
    isothermal = L == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        lnP = _LN_P_BASE[i] + np.where(isothermal, -_GMR * dH / Tb, (_GMR / np.where(isothermal, 1.0, L)) * np.log(Tb / T))
    ln_rho = lnP - np.log(R_AIR * T)
    if not derivatives:
        return ln_rho, T
    Hz = (r0 / (r0 + z)) ** 2
    Hzz = -2.0 * r0 * r0 / (r0 + z) ** 3
    f_H = -(_GMR + L) / T
    f_HH = (_GMR + L) * L / (T * T)
    return ln_rho, f_H * Hz, f_HH * Hz * Hz + f_H * Hzz, T, L * Hz, L * Hzz


def _lower_layers_symbolic(z):
    """(ln rho, T) of ``_lower_layers`` as piecewise symbolic Expressions of z (the same
    formulas, the layer chosen by geopotential altitude as there)."""
    r0 = R0_GEOPOTENTIAL
    H = r0 * z / (r0 + z)
    breaks = _H_BASE_LIST + [math.inf]

    def temperature(i):
        return _T_BASE_LIST[i] + _LAPSE_LIST[i] * (H - _H_BASE_LIST[i])

    def ln_rho(i):
        L, Tb, dH = _LAPSE_LIST[i], _T_BASE_LIST[i], H - _H_BASE_LIST[i]
        T = Tb + L * dH
        lnP = _LN_P_BASE_LIST[i] - _GMR * dH / Tb if L == 0.0 else _LN_P_BASE_LIST[i] + (_GMR / L) * np.log(Tb / T)
        return lnP - np.log(R_AIR * T)

    return piecewise(H, breaks, ln_rho), piecewise(H, breaks, temperature)


def _us76_array(z: np.ndarray):
    """The six US76 quantities for an array of altitudes, vectorised by layer; equal to the
    scalar path to rounding (tests)."""
    out = np.empty((6,) + z.shape)
    lower = z <= US76_LOWER_TOP
    if lower.all():
        return list(_lower_layers_array(z))
    if lower.any():
        out[:, lower] = _lower_layers_array(z[lower])
    upper = ~lower
    table = _upper_table()
    out[:, upper] = table.evaluate(z[upper])
    return list(out)


def _us76_scalar(z: float):
    return _lower_layers(z) if z <= US76_LOWER_TOP else _upper_table()(z)


class US76Atmosphere(Atmosphere):
    """U.S. Standard Atmosphere 1976, -5 to 1000 km geometric altitude.

    Example:
      >>> rho, T, a = US76Atmosphere().properties(11019.0)
    """

    name = "us76"
    h_min = US76_H_MIN
    h_max = US76_H_MAX

    def _evaluate(self, h):
        """The six US76 quantities for a float or an ndarray of altitudes."""
        if isinstance(h, (float, int)) or np.ndim(h) == 0:
            z = float(h)
            if not US76_H_MIN <= z <= US76_H_MAX:
                self.check(z)
            return _us76_scalar(z)
        self.check(h)
        return _us76_array(np.asarray(h, dtype=float))

    def _air_data_float(self, h: float) -> tuple[float, float]:
        ln_rho, _, _, T, _, _ = self._evaluate(float(h))
        return math.exp(ln_rho), math.sqrt(GAMMA_AIR * R_AIR * T)

    def air_data(self, h):
        """(density, speed of sound); a float array below 86 km skips the altitude derivatives
        (the paper-004 population evaluator's path; equal to ``properties``, tested)."""
        if (isinstance(h, np.ndarray) and h.dtype.kind == "f" and h.size and h.max() <= US76_LOWER_TOP
                and h.min() >= US76_H_MIN):  # NaN fails both: the general path names it
            ln_rho, T = _lower_layers_array(h, derivatives=False)
            return np.exp(ln_rho), np.sqrt(GAMMA_AIR * R_AIR * T)
        return super().air_data(h)

    def _symbolic_profile(self, h):
        """(rho, T) Expressions: the seven layers below 86 km, the upper table's splines above."""
        lower_ln_rho, lower_T = _lower_layers_symbolic(h)
        upper_ln_rho, upper_T = _upper_table().symbolic(h)
        below = h <= US76_LOWER_TOP
        return np.exp(if_then_else(below, lower_ln_rho, upper_ln_rho)), if_then_else(below, lower_T, upper_T)

    def density_derivatives(self, h) -> Derivatives:
        return self.derivatives(h)[0]

    def temperature_derivatives(self, h) -> Derivatives:
        *_, T, T1, T2 = self._evaluate(h)
        return Derivatives(T, T1, T2)

    def derivatives(self, h):
        ln_rho, l1, l2, T, T1, T2 = self._evaluate(h)
        rho = np.exp(ln_rho) if isinstance(ln_rho, np.ndarray) else math.exp(ln_rho)
        return Derivatives(rho, rho * l1, rho * (l2 + l1 * l1)), Derivatives(T, T1, T2)


@dataclass(frozen=True)
class ExponentialAtmosphere(Atmosphere):
    """rho = rho0 exp(-h / h_s) (paper 000 eq. 29).

    Temperature (for the Mach number, paper 000 eqs. 30-31) comes from US76's
    piecewise-linear profile unless a constant ``temperature_K`` is given.

    Attributes:
      rho0: sea-level density [kg/m^3] (paper 000: 1.2256).
      scale_height: h_s [m] (paper 000: 7200).
      temperature_K: constant temperature [K], or None for the US76 profile.
    """

    rho0: float = 1.2256
    scale_height: float = 7200.0
    temperature_K: float | None = None
    name = "exponential"

    def __post_init__(self):
        if not 0 < self.rho0 <= 1e3:
            raise ScenarioError(f"ExponentialAtmosphere.rho0 = {self.rho0} kg/m^3 is out of range; allowed (0, 1000]")
        if not 100.0 <= self.scale_height <= 1e6:
            raise ScenarioError(f"ExponentialAtmosphere.scale_height = {self.scale_height} m is out of range; "
                                f"allowed [100, 1e6]")
        if self.temperature_K is not None and not 0 < self.temperature_K <= 1e4:
            raise ScenarioError(f"ExponentialAtmosphere.temperature_K = {self.temperature_K} is out of range; "
                                f"allowed (0, 1e4]")

    H_MAX = 1e7  # [m]: the formula holds at any height; this only catches nonsense (and NaN)
    h_min, h_max = US76_H_MIN, H_MAX  # the range density() accepts (a native plant's PlantGuard reads it)

    def density(self, h):
        _check_range(self.name, h, US76_H_MIN, self.H_MAX)
        return self.rho0 * np.exp(-h / self.scale_height)

    def density_derivatives(self, h) -> Derivatives:
        _check_range(self.name, h, US76_H_MIN, self.H_MAX)
        rho = self.rho0 * np.exp(-np.asarray(h, dtype=float) / self.scale_height)
        return Derivatives(rho, -rho / self.scale_height, rho / self.scale_height**2)

    def _symbolic_profile(self, h):
        return self.density(h), self.temperature(h)

    def temperature(self, h):
        """US76 temperature (held at its range ends: the exponential density model has no
        altitude limit, and optimisers may step outside) or the constant temperature [K]."""
        if self.temperature_K is None:
            _check_range(self.name, h, US76_H_MIN, self.H_MAX)
            return US76Atmosphere().temperature(clamp(h, US76_H_MIN, US76_H_MAX))
        return self.temperature_K + 0.0 * h  # keeps the scalar type of h

    def temperature_derivatives(self, h) -> Derivatives:
        if self.temperature_K is not None:
            z = np.zeros(np.shape(h))
            return Derivatives(z + self.temperature_K, z, z)
        inside = (np.asarray(h) >= US76_H_MIN) & (np.asarray(h) <= US76_H_MAX)
        d = US76Atmosphere().temperature_derivatives(np.clip(h, US76_H_MIN, US76_H_MAX))
        return Derivatives(d.value, np.where(inside, d.d_h, 0.0) if np.ndim(h) else (d.d_h if inside else 0.0),
                           np.where(inside, d.d_hh, 0.0) if np.ndim(h) else (d.d_hh if inside else 0.0))


class TableAtmosphere(Atmosphere):
    """A tabulated atmosphere (for example a GRAM or NRLMSIS profile, or another planet's):
    C2 cubic splines of ln rho and T through the table, so density and temperature have the
    continuous first and second altitude derivatives the drag dynamics need. Defined on the
    table's altitude range only (outside it a ModelRangeError names the range).

    Args: altitude_m (increasing, at least 4 rows), density_kg_m3 (> 0), temperature_K (> 0),
    source (where the numbers come from). ``TableAtmosphere.from_csv(path)`` reads a CSV with
    the columns altitude_m, density_kg_m3, temperature_K (``#`` comment lines allowed).
    """

    name = "table"

    def __init__(self, altitude_m, density_kg_m3, temperature_K, *, source: str = ""):
        h, rho, T = (np.asarray(v, float) for v in (altitude_m, density_kg_m3, temperature_K))
        if not (h.ndim == 1 and h.size >= 4 and rho.shape == h.shape and T.shape == h.shape):
            raise ScenarioError(f"TableAtmosphere needs at least 4 rows of altitude_m, density_kg_m3, temperature_K "
                                f"of one length, got {h.size}, {rho.size}, {T.size}")
        for name, v, lo in (("altitude_m", h, -1e7), ("density_kg_m3", rho, 0.0), ("temperature_K", T, 0.0)):
            bad = ~np.isfinite(v) | (v <= lo)
            if bad.any():
                raise ScenarioError(f"TableAtmosphere.{name} = {v[bad][0]} in row {int(np.flatnonzero(bad)[0]) + 1} is "
                                    f"out of range; allowed: finite and > {lo:g}")
        if np.any(np.diff(h) <= 0):
            i = int(np.flatnonzero(np.diff(h) <= 0)[0])
            raise ScenarioError(f"TableAtmosphere.altitude_m must increase: row {i + 2} ({h[i + 1]:g} m) follows "
                                f"{h[i]:g} m")
        self.h_min, self.h_max, self.source = float(h[0]), float(h[-1]), source
        self._profile = _SplineProfile(h, rho, T)

    @classmethod
    def from_csv(cls, path_or_file, *, source: str = "") -> "TableAtmosphere":
        name = getattr(path_or_file, "name", path_or_file)
        expected = ["altitude_m", "density_kg_m3", "temperature_K"]
        try:
            rows = [[c.strip() for c in r] for r in read_csv_rows(path_or_file)]
            if not rows or rows[0] != expected:
                raise ValueError(f"header {rows[0] if rows else 'missing'}; expected {','.join(expected)}")
            values = np.array([[float(c) for c in r] for r in rows[1:]]).reshape(-1, 3)
        except (ValueError, OSError, UnicodeDecodeError) as e:
            raise ScenarioError(f"atmosphere table {name}: {e}") from None
        return cls(values[:, 0], values[:, 1], values[:, 2], source=source or str(name))

    def _symbolic_profile(self, h):
        ln_rho, T = self._profile.symbolic(h)
        return np.exp(ln_rho), T

    def _evaluate(self, h):
        self.check(h)
        if isinstance(h, (float, int)) or np.ndim(h) == 0:
            return self._profile(float(h))
        return self._profile.evaluate(np.asarray(h, float))

    def density_derivatives(self, h) -> Derivatives:
        ln_rho, l1, l2, *_ = self._evaluate(h)
        rho = np.exp(ln_rho) if isinstance(ln_rho, np.ndarray) else math.exp(ln_rho)
        return Derivatives(rho, rho * l1, rho * (l2 + l1 * l1))

    def temperature_derivatives(self, h) -> Derivatives:
        *_, T, T1, T2 = self._evaluate(h)
        return Derivatives(T, T1, T2)


#: |A| < DENSITY_WAVE_AMPLITUDE_BOUND keeps a dispersed density positive (DispersedAtmosphere; the
#: scenario's dispersions are checked against the same bound)
DENSITY_WAVE_AMPLITUDE_BOUND = 1.0


class DispersedAtmosphere(Atmosphere):
    """A Monte-Carlo sample's true atmosphere: rho = rho_nominal * scale * (1 + A sin(2 pi h /
    wavelength + phase)) (bias plus an altitude-correlated perturbation); temperature nominal.

    Args: base atmosphere, scale (> 0), amplitude A with |A| < 1 (a negative A is the same wave
    half a wavelength along), wavelength [m] (> 0), phase [rad].
    """

    def __init__(self, base: Atmosphere, *, scale: float = 1.0, amplitude: float = 0.0,
                 wavelength: float = 8000.0, phase: float = 0.0):
        if not scale > 0 or not abs(amplitude) < DENSITY_WAVE_AMPLITUDE_BOUND or not wavelength > 0:
            raise ScenarioError(f"DispersedAtmosphere needs scale > 0, |amplitude| < {DENSITY_WAVE_AMPLITUDE_BOUND:g}, "
                                f"wavelength > 0 (got {scale}, {amplitude}, {wavelength})")
        self.base, self.scale, self.amplitude = base, scale, amplitude
        self.k, self.phase = 2.0 * math.pi / wavelength, phase
        self.name = f"dispersed {base.name}"
        self.h_min, self.h_max = base.h_min, base.h_max
        self.gas_constant, self.gamma = base.gas_constant, base.gamma

    def _factor(self, h):
        """f, f', f'' of the multiplicative perturbation."""
        a = self.amplitude
        if isinstance(h, float):  # the simulation's scalar path, without numpy overhead
            arg = self.k * h + self.phase
            s, c = math.sin(arg), math.cos(arg)
            return self.scale * (1.0 + a * s), self.scale * a * self.k * c, -self.scale * a * self.k**2 * s
        arg = self.k * np.asarray(h, float) + self.phase
        return (self.scale * (1.0 + a * np.sin(arg)), self.scale * a * self.k * np.cos(arg),
                -self.scale * a * self.k**2 * np.sin(arg))

    def _air_data_float(self, h: float) -> tuple[float, float]:
        rho, a = self.base.air_data(h)
        return rho * self._factor(float(h))[0], a

    def _symbolic_profile(self, h):
        rho, T = self.base.symbolic_profile(h)
        return rho * (self.scale * (1.0 + self.amplitude * np.sin(self.k * h + self.phase))), T

    def density_derivatives(self, h) -> Derivatives:
        return self.derivatives(h)[0]

    def temperature_derivatives(self, h) -> Derivatives:
        return self.base.temperature_derivatives(h)

    def derivatives(self, h):
        """Product rule on rho_nominal * f(h)."""
        d, t = self.base.derivatives(h)
        f, f1, f2 = self._factor(h)
        if np.ndim(h) == 0:
            f, f1, f2 = float(f), float(f1), float(f2)
        return Derivatives(d.value * f, d.d_h * f + d.value * f1, d.d_hh * f + 2 * d.d_h * f1 + d.value * f2), t


class PerturbedAtmosphere(Atmosphere):
    """A Monte-Carlo sample's atmosphere with its density and temperature perturbation profiles:
    rho = rho_base(h) (1 + d_rho(h)), T = T_base(h) (1 + d_T(h)) (so the speed of sound and the
    Mach number change with T), d_rho and d_T linear between the nodes of ``altitude_m`` and held
    beyond its ends (models.atmosphere_perturbations draws them). Float, ndarray, AutoDiffXd and
    symbolic altitude (the native plant flies it).

    Args: base atmosphere; altitude_m (increasing nodes [m]); density_perturbation and
    temperature_perturbation (fractions at the nodes, each > -1).
    """

    def __init__(self, base: Atmosphere, altitude_m, density_perturbation, temperature_perturbation):
        h, dr, dt = (np.asarray(v, float) for v in (altitude_m, density_perturbation, temperature_perturbation))
        if not (h.ndim == 1 and h.size >= 2 and dr.shape == h.shape and dt.shape == h.shape
                and np.all(np.diff(h) > 0) and np.all(np.isfinite(dr)) and np.all(np.isfinite(dt))
                and np.all(dr > -1.0) and np.all(dt > -1.0)):
            raise ScenarioError("PerturbedAtmosphere needs increasing altitude nodes and finite perturbations > -1 at "
                                "each of them")
        self.base, self.nodes, self.d_rho, self.d_T = base, h, dr, dt
        self.name = f"perturbed {base.name}"
        self.h_min, self.h_max = base.h_min, base.h_max
        self.gas_constant, self.gamma = base.gas_constant, base.gamma

    def factors(self, h):
        """((1 + d_rho, slope), (1 + d_T, slope)) at altitude h [m] (float or ndarray; slopes per m,
        zero beyond the nodes)."""
        out = []
        for d in (self.d_rho, self.d_T):
            value, slope = held_linear(h, self.nodes, d)
            out.append((1.0 + value, slope))
        if np.ndim(h) == 0:
            out = [(float(f), float(s)) for f, s in out]
        return out

    def _air_data_float(self, h: float) -> tuple[float, float]:
        rho, a = self.base.air_data(h)
        (fr, _), (ft, _) = self.factors(h)
        return rho * fr, a * math.sqrt(ft)

    def _symbolic_profile(self, h):
        rho, T = self.base.symbolic_profile(h)
        return (rho * held_linear_expression(h, self.nodes, self.d_rho, 1.0),
                T * held_linear_expression(h, self.nodes, self.d_T, 1.0))

    def density_derivatives(self, h) -> Derivatives:
        return self.derivatives(h)[0]

    def temperature_derivatives(self, h) -> Derivatives:
        return self.derivatives(h)[1]

    def derivatives(self, h):
        """Product rule on base x factor (the factor piecewise linear: no second derivative)."""
        d, t = self.base.derivatives(h)
        (fr, sr), (ft, st) = self.factors(value_of(h))
        return (Derivatives(d.value * fr, d.d_h * fr + d.value * sr, d.d_hh * fr + 2 * d.d_h * sr),
                Derivatives(t.value * ft, t.d_h * ft + t.value * st, t.d_hh * ft + 2 * t.d_h * st))


def make_atmosphere(name: str, **kwargs) -> Atmosphere:
    """Atmosphere by name: 'us76' or 'exponential' (keyword arguments go to the model)."""
    if name == "us76":
        return US76Atmosphere()
    if name == "exponential":
        return ExponentialAtmosphere(**kwargs)
    raise ScenarioError(f"atmosphere model '{name}' is unknown; allowed: 'us76', 'exponential'")


def write_upper_table(path: str) -> None:
    """Tabulate US76 from 86 to 1000 km with the ``ussa1976`` package."""
    import ussa1976  # optional, test/dev extra

    z = np.unique(np.concatenate([np.arange(86e3, 200e3, 1e3), np.arange(200e3, 1000e3 + 1, 5e3)]))
    ds = ussa1976.compute(z=z, variables=["rho", "t"])
    header = (
        "U.S. Standard Atmosphere 1976 above 86 km, tabulated with ussa1976 "
        f"{getattr(ussa1976, '__version__', '')} (NASA-TM-X-74335).\n"
        "Regenerate: python -m drake_entry.models.atmosphere --write-upper-table PATH\n"
        "z_m, rho_kg_m3, T_K"
    )
    np.savetxt(path, np.column_stack([z, ds["rho"].values, ds["t"].values]), delimiter=",",
               header=header, fmt=["%.1f", "%.10e", "%.6f"])


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--write-upper-table", metavar="PATH", required=True)
    write_upper_table(parser.parse_args().write_upper_table)
