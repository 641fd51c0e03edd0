"""AccelerationRatioFilter: the low-passed ratios of the sensed lift and drag to the nominal
models' at the navigation estimate (drake_entry.models.acceleration_ratios), for a guidance that
predicts with its models scaled by what the flight has shown.

Ports:
  - input  "estimated_state"    [6]  navigation estimate [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "flight_conditions"  [9]  sensed flight conditions (lift and drag accelerations used)
  - input  "alpha_command"      [1]  angle of attack commanded [rad] (the models' alpha)
  - output "ratios"             [2]  k_L, k_D (1, 1 until the first update)
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.models.acceleration_ratios import filtered_ratios
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.lifetime import weak_method

__all__ = ["AccelerationRatioFilter"]

_LIFT, _DRAG = FLIGHT_CONDITION_NAMES.index("lift"), FLIGHT_CONDITION_NAMES.index("drag")


class AccelerationRatioFilter(LeafSystem):
    def __init__(self, vehicle, planet, atmosphere, *, period: float = 1.0):
        """Args: the nominal models (vehicle, planet, atmosphere); period [s] of the update."""
        super().__init__()
        self.models, self.period = (vehicle, planet, atmosphere), float(period)
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.fc_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.alpha_port = self.DeclareVectorInputPort("alpha_command", 1)
        self._ratios = self.DeclareDiscreteState(BasicVector([1.0, 1.0]))
        self.DeclarePeriodicDiscreteUpdateEvent(self.period, 0.0, weak_method(self._update))
        self.DeclareStateOutputPort("ratios", self._ratios)

    def _update(self, context, discrete_state):
        x = np.asarray(self.est_port.Eval(context), float)
        fc = self.fc_port.Eval(context)
        k = filtered_ratios(context.get_discrete_state(self._ratios).get_value(), x, float(self.alpha_port.Eval(context)[0]),
                            float(fc[_LIFT]), float(fc[_DRAG]), *self.models, self.period)
        discrete_state.get_mutable_vector(self._ratios).SetFromVector(k)
