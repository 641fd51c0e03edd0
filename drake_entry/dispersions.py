"""Entry-interface dispersions: seeded draws of the initial-state error.

``EntryDispersion.paper000_table2()`` is paper 000 Table 2 (uniform). A draw depends only
on (seed, sample index), so any Monte-Carlo sample can be re-run alone.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EntryDispersion:
    """Half-widths (uniform) or standard deviations (gaussian) of [h, lon, lat, V, gamma, psi]
    in SI / rad."""

    scale: tuple = (0.0,) * 6
    distribution: str = "uniform"

    def __post_init__(self):
        if len(self.scale) != 6 or any(s < 0 for s in self.scale):
            raise ValueError("EntryDispersion.scale needs 6 non-negative entries [h, lon, lat, V, gamma, psi]")
        if self.distribution not in ("uniform", "gaussian"):
            raise ValueError(f"EntryDispersion.distribution must be 'uniform' or 'gaussian', got '{self.distribution}'")

    @staticmethod
    def paper000_table2() -> "EntryDispersion":
        """+-250 m, +-0.1 deg lon/lat, +-15 m/s, +-0.01 deg gamma/psi (paper 000 Table 2)."""
        d = np.radians
        return EntryDispersion((250.0, d(0.1), d(0.1), 15.0, d(0.01), d(0.01)), "uniform")

    def sample(self, seed: int, index: int = 0) -> np.ndarray:
        """Deviation of sample ``index`` of the campaign seeded with ``seed``."""
        return self.draw(np.random.default_rng([int(seed), int(index)]))

    def draw(self, rng: np.random.Generator) -> np.ndarray:
        """Deviation drawn from ``rng``."""
        s = np.asarray(self.scale, float)
        if self.distribution == "uniform":
            return rng.uniform(-1.0, 1.0, 6) * s
        return rng.standard_normal(6) * s

    def apply(self, x0, seed: int, index: int = 0) -> np.ndarray:
        """Dispersed entry state x0 + sample."""
        return np.asarray(x0, float) + self.sample(seed, index)
