"""Piecewise-linear command schedules (angle of attack, bank) over time, energy or Mach.

The HORUS-2B angle-of-attack law (paper 000 Sec. IV.A: 40 deg, then linear down to 15 deg
between about 960 s and 1250 s, then held) is ``Schedule.ramp``; ``smooth=True`` replaces
the corners by a quintic blend, which keeps gamma smooth under a smooth drag profile
(docs/methods/drag-energy.md).
"""
from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models.scalar import is_autodiff, lift, value_of

__all__ = ["VARIABLES", "Schedule", "linear_bank"]

VARIABLES = ("time", "energy", "mach", "velocity")


@dataclass(frozen=True)
class Schedule:
    """value(s) by linear interpolation in ``breakpoints`` (held constant outside).

    Attributes:
      breakpoints: increasing values of the scheduling variable (s, J/kg, -, or m/s).
      values: command values at the breakpoints, SI (rad for angles).
      variable: 'time', 'energy', 'mach' or 'velocity'.
      smooth: quintic smoothstep between breakpoints instead of straight lines (C2).
    """

    breakpoints: tuple
    values: tuple
    variable: str = "time"
    smooth: bool = False

    def __post_init__(self):
        bp = np.asarray(self.breakpoints, float)
        if self.variable not in VARIABLES:
            raise ScenarioError(f"Schedule.variable must be one of {VARIABLES}, got '{self.variable}'")
        if bp.size == 0 or bp.size != len(self.values):
            raise ScenarioError(f"Schedule needs as many values as breakpoints (got {bp.size} and {len(self.values)})")
        if np.any(np.diff(bp) <= 0):
            raise ScenarioError("Schedule.breakpoints must be strictly increasing")

    def _scalar(self, s: float) -> float:
        bp, v = self.breakpoints, self.values
        if s <= bp[0]:
            return float(v[0])
        if s >= bp[-1]:
            return float(v[-1])
        i = bisect.bisect_right(bp, s) - 1
        t = (s - bp[i]) / (bp[i + 1] - bp[i])
        if self.smooth:
            t = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
        return float(v[i] + (v[i + 1] - v[i]) * t)

    @staticmethod
    def constant(value: float) -> "Schedule":
        return Schedule((0.0,), (float(value),))

    @staticmethod
    def ramp(start: float, end: float, value_start: float, value_end: float, *, variable: str = "time",
             smooth: bool = False) -> "Schedule":
        """value_start until ``start``, linear to value_end at ``end``, then held."""
        return Schedule((float(start), float(end)), (float(value_start), float(value_end)), variable, smooth)

    def derivatives(self, s: float) -> tuple[float, float, float]:
        """(value, d/ds, d2/ds2) at a scalar s (zero slope outside the breakpoints; the
        second derivative of a non-smooth schedule is zero between its corners)."""
        bp, v = self.breakpoints, self.values
        s = float(s)
        if len(bp) == 1 or s <= bp[0] or s >= bp[-1]:
            return self._scalar(s), 0.0, 0.0
        i = min(max(bisect.bisect_right(bp, s) - 1, 0), len(bp) - 2)
        width = float(bp[i + 1] - bp[i])
        dv = float(v[i + 1] - v[i])
        if not self.smooth:
            return self._scalar(s), dv / width, 0.0
        t = (s - bp[i]) / width
        d1 = 30.0 * t * t * (1.0 - t) ** 2
        d2 = 60.0 * t * (1.0 - t) * (1.0 - 2.0 * t)
        return self._scalar(s), dv * d1 / width, dv * d2 / width**2

    def __call__(self, s):
        """Value at s (float or ndarray)."""
        if isinstance(s, float):
            return self._scalar(s)
        bp = np.asarray(self.breakpoints, float)
        v = np.asarray(self.values, float)
        if not self.smooth or bp.size == 1:
            return np.interp(s, bp, v) if np.ndim(s) else float(np.interp(s, bp, v))
        s_arr = np.asarray(s, float)
        i = np.clip(np.searchsorted(bp, s_arr, side="right") - 1, 0, bp.size - 2)
        t = np.clip((s_arr - bp[i]) / (bp[i + 1] - bp[i]), 0.0, 1.0)
        blend = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
        out = v[i] + (v[i + 1] - v[i]) * blend
        return out if np.ndim(s) else float(out)

    def slope(self, s):
        """d value / d s at s (float or ndarray; zero outside the breakpoints, the right-hand
        slope at a corner)."""
        bp = np.asarray(self.breakpoints, float)
        v = np.asarray(self.values, float)
        s_arr = np.asarray(s, float)
        if bp.size == 1:
            return np.zeros_like(s_arr) if np.ndim(s) else 0.0
        i = np.clip(np.searchsorted(bp, s_arr, side="right") - 1, 0, bp.size - 2)
        width = bp[i + 1] - bp[i]
        t = (s_arr - bp[i]) / width
        inside = (s_arr >= bp[0]) & (s_arr < bp[-1])
        d = (v[i + 1] - v[i]) / width * (30.0 * t * t * (1.0 - t) ** 2 if self.smooth else 1.0)
        out = np.where(inside, d, 0.0)
        return out if np.ndim(s) else float(out)

    def at(self, s):
        """Value at s of any scalar type the models take: float, ndarray of floats, or
        AutoDiffXd (the chain rule through ``slope``)."""
        if is_autodiff(s):
            x = value_of(s)
            return lift([s], self(float(x)), [self.slope(float(x))])
        if isinstance(s, np.ndarray) and s.dtype == object:
            return np.array([self.at(e) for e in s.ravel()], dtype=object).reshape(s.shape)
        return self(float(s) if np.ndim(s) == 0 else s)


def linear_bank(e, e0, ef: float, sigma0, sigmaf):
    """|sigma| [rad] linear in the energy-like variable e = mu/r - V^2/2 [J/kg] (increasing along
    the flight): sigma0 at e0, sigmaf at ef (paper 004 eq. 17; Lu 2014's baseline profile). Any
    scalar type or numpy arrays."""
    return sigma0 + (e - e0) / (ef - e0) * (sigmaf - sigma0)
