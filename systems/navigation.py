"""Navigation: true state in, estimated state out (bias plus seeded white noise).

The noise is a zero-order hold updated every ``period`` seconds; sample k uses the
generator seeded with (seed, k), so any run is reproducible from its seed alone and
independent of integrator steps or context resets.

Ports:
  - input  "true_state"       [6]  [h m, lon, lat rad, V m/s, gamma, psi rad]
  - output "estimated_state"  [6]  true state + bias + noise
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.errors import ScenarioError
from drake_entry.systems.lifetime import weak_method

__all__ = ["Navigation"]


class Navigation(LeafSystem):
    def __init__(self, *, bias=None, noise_sigma=None, period: float = 1.0, seed: int = 0):
        """Args: bias [6] and noise_sigma [6] in state units, period [s], seed (int)."""
        super().__init__()
        self.bias = np.zeros(6) if bias is None else np.asarray(bias, float)
        self.sigma = np.zeros(6) if noise_sigma is None else np.asarray(noise_sigma, float)
        if self.bias.shape != (6,) or self.sigma.shape != (6,):
            raise ScenarioError("Navigation.bias and noise_sigma must have 6 entries (one per state)")
        if np.any(self.sigma < 0):
            raise ScenarioError("Navigation.noise_sigma must be >= 0")
        if not period > 0:
            raise ScenarioError(f"Navigation.period must be > 0 s, got {period}")
        self.seed = int(seed)
        self.period = float(period)
        self.true_port = self.DeclareVectorInputPort("true_state", 6)
        self._noise = self.DeclareDiscreteState(BasicVector(np.zeros(7)))  # [noise(6), k]
        if np.any(self.sigma > 0):
            self.DeclarePeriodicDiscreteUpdateEvent(self.period, 0.0, weak_method(self._update))
        self.DeclareVectorOutputPort("estimated_state", 6, weak_method(self._calc),
                                     prerequisites_of_calc={self.true_port.ticket(), self.all_state_ticket()})

    def noise_sample(self, k: int) -> np.ndarray:
        """Noise of update k (reproducible)."""
        return self.sigma * np.random.default_rng([self.seed, int(k)]).standard_normal(6)

    def _update(self, context, discrete_state):
        k = int(context.get_discrete_state(self._noise).get_value()[6])
        discrete_state.get_mutable_vector(self._noise).SetFromVector(np.append(self.noise_sample(k), k + 1))

    def _calc(self, context, output):
        noise = context.get_discrete_state(self._noise).get_value()[:6]
        output.SetFromVector(self.true_port.Eval(context) + self.bias + noise)
