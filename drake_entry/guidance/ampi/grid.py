"""The parameter space of the trajectory database (paper 003 Sec. IV.A, eqs. 4-6).

The parameters are offsets of the entry state: each dimension has increasing levels (SI /
rad), and the database holds one optimal trajectory per combination. Paper 003 eq. 5: three
levels {-, 0, +} in each of h (250 m), lon, lat (0.5 deg), V (70 m/s), gamma, psi (0.5 deg),
3^6 = 729 cases.

Cases are numbered in C order of their multi-indices (the last dimension fastest).
Continuation (the database build) solves them in waves of growing grid distance from the
nominal (the centre): each case is warm-started from its ``parent``, the neighbour one step
closer to the centre.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["PARAMETERS", "DISPLAY_UNITS", "ParameterGrid"]

#: the entry-state components a parameter may offset (the canonical state order)
PARAMETERS = ("h", "lon", "lat", "V", "gamma", "psi")
#: the unit each parameter's levels are given in by ``ParameterGrid.from_steps`` / YAML
DISPLAY_UNITS = {"h": ("m", 1.0), "lon": ("deg", math.pi / 180), "lat": ("deg", math.pi / 180),
                 "V": ("m/s", 1.0), "gamma": ("deg", math.pi / 180), "psi": ("deg", math.pi / 180)}


@dc.dataclass(frozen=True)
class ParameterGrid:
    """A tensor grid of entry-state offsets.

    Attributes:
      names: the offset states, a subset of PARAMETERS in any order.
      levels: per name, the increasing offsets [SI / rad] (at least 2).
    """

    names: tuple
    levels: tuple

    def __post_init__(self):
        if len(self.names) != len(self.levels) or not self.names:
            raise ScenarioError(f"ParameterGrid needs one level list per name, got {len(self.names)} names and "
                                f"{len(self.levels)} level lists")
        for name, lv in zip(self.names, self.levels):
            if name not in PARAMETERS:
                raise ScenarioError(f"ParameterGrid: '{name}' is not an entry state; allowed: {', '.join(PARAMETERS)}")
            lv = np.asarray(lv, float)
            if lv.ndim != 1 or lv.size < 2 or not np.all(np.isfinite(lv)) or np.any(np.diff(lv) <= 0):
                raise ScenarioError(f"ParameterGrid.levels['{name}'] = {lv.tolist()}: needs >= 2 finite, strictly "
                                    f"increasing offsets")
        if len(set(self.names)) != len(self.names):
            raise ScenarioError(f"ParameterGrid: a name appears twice in {self.names}")
        object.__setattr__(self, "levels", tuple(tuple(float(v) for v in lv) for lv in self.levels))

    @staticmethod
    def from_steps(steps: dict, n_levels: int = 3) -> "ParameterGrid":
        """Symmetric levels about 0: {name: step in its display unit (m, deg, m/s)}; n_levels odd."""
        if n_levels < 3 or n_levels % 2 == 0:
            raise ScenarioError(f"n_levels = {n_levels}: allowed an odd integer >= 3 (the nominal in the middle)")
        half = n_levels // 2
        names, levels = [], []
        for name, step in steps.items():
            if name not in DISPLAY_UNITS:
                raise ScenarioError(f"ParameterGrid: '{name}' is not an entry state; allowed: {', '.join(PARAMETERS)}")
            if not 0 < step < math.inf:
                raise ScenarioError(f"ParameterGrid step for '{name}' = {step}: must be finite and > 0")
            names.append(name)
            levels.append(tuple(k * step * DISPLAY_UNITS[name][1] for k in range(-half, half + 1)))
        return ParameterGrid(tuple(names), tuple(levels))

    @staticmethod
    def paper_003() -> "ParameterGrid":
        """Eq. 5: h +-250 m, lon, lat +-0.5 deg, V +-70 m/s, gamma, psi +-0.5 deg (3^6 cases)."""
        return ParameterGrid.from_steps({"h": 250.0, "lon": 0.5, "lat": 0.5, "V": 70.0, "gamma": 0.5, "psi": 0.5})

    # -- layout -----------------------------------------------------------------------
    @property
    def shape(self) -> tuple:
        return tuple(len(lv) for lv in self.levels)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    @property
    def centre(self) -> tuple:
        """Multi-index of the nominal (the middle level of each dimension)."""
        return tuple(n // 2 for n in self.shape)

    def index(self, multi) -> int:
        return int(np.ravel_multi_index(tuple(multi), self.shape))

    def multi_index(self, index: int) -> tuple:
        return tuple(int(i) for i in np.unravel_index(int(index), self.shape))

    def offsets(self, index: int) -> dict:
        """{state name: offset [SI / rad]} of case ``index``."""
        return {n: self.levels[d][i] for d, (n, i) in enumerate(zip(self.names, self.multi_index(index)))}

    def point(self, index: int) -> np.ndarray:
        """The case's offsets as a vector in ``names`` order."""
        return np.array([self.levels[d][i] for d, i in enumerate(self.multi_index(index))])

    def distance(self, index: int) -> int:
        """Grid steps from the nominal (the continuation wave of the case)."""
        return int(sum(abs(i - c) for i, c in zip(self.multi_index(index), self.centre)))

    def parent(self, index: int) -> int | None:
        """The neighbour one step closer to the nominal along the first offset dimension
        (None for the nominal): where continuation warm-starts the case from."""
        multi = list(self.multi_index(index))
        for d, c in enumerate(self.centre):
            if multi[d] != c:
                multi[d] += 1 if multi[d] < c else -1
                return self.index(multi)
        return None

    def neighbours(self, index: int) -> list:
        """Indices one step away along each dimension."""
        multi = self.multi_index(index)
        out = []
        for d, n in enumerate(self.shape):
            for step in (-1, 1):
                j = multi[d] + step
                if 0 <= j < n:
                    out.append(self.index(multi[:d] + (j,) + multi[d + 1:]))
        return out

    def waves(self) -> list:
        """Case indices grouped by distance from the nominal (continuation order)."""
        by = {}
        for i in range(self.size):
            by.setdefault(self.distance(i), []).append(i)
        return [by[k] for k in sorted(by)]

    def as_dict(self) -> dict:
        """JSON-able form (a campaign's identity)."""
        return {"names": list(self.names), "levels": [list(lv) for lv in self.levels]}

    @staticmethod
    def from_dict(d: dict) -> "ParameterGrid":
        return ParameterGrid(tuple(d["names"]), tuple(tuple(lv) for lv in d["levels"]))
