"""BankReversalLogic: the sign of the bank from a heading-error corridor (paper 000 Sec. VI.D;
Harpold & Graves 1979).

Heading error dpsi = psi - bearing to the target (wrapped to [-pi, pi]); the corridor
half-width grows linearly with speed between two (V, dpsi_max) points. When dpsi leaves
the corridor the bank sign is set to turn back (positive bank turns right, i.e. increases
psi), so reversals happen at the corridor edges.

Ports:
  - input  "estimated_state"  [6]
  - input  "bank_magnitude"   [1]  |sigma| [rad]
  - output "bank_command"     [1]  sign * |sigma| [rad]
  - output "reversals"        [1]  number of reversals so far
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.errors import ScenarioError
from drake_entry.models.bank_reversal import corridor_half_width, reversal_sign, wrap_angle
from drake_entry.models.geodesy import bearing
from drake_entry.systems.lifetime import weak_element, weak_method

__all__ = ["BankReversalLogic"]


class BankReversalLogic(LeafSystem):
    def __init__(self, *, target_lon: float, target_lat: float, corridor_deg=(5.0, 15.0),
                 corridor_velocity=(1000.0, 6000.0), period: float = 1.0, initial_sign: float = 1.0):
        super().__init__()
        if corridor_velocity[1] <= corridor_velocity[0]:
            raise ScenarioError("BankReversalLogic corridor_velocity must be increasing")
        if min(corridor_deg) <= 0:
            raise ScenarioError("BankReversalLogic corridor_deg must be > 0")
        self.target = (target_lon, target_lat)
        self.corridor = (np.radians(corridor_deg), np.asarray(corridor_velocity, float))
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.mag_port = self.DeclareVectorInputPort("bank_magnitude", 1)
        self._state = self.DeclareDiscreteState(BasicVector([1.0 if initial_sign >= 0 else -1.0, 0.0]))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._update))
        self.DeclareVectorOutputPort("bank_command", 1, weak_method(self._bank_command),
                                     prerequisites_of_calc={self.xd_ticket(), self.mag_port.ticket()})
        self.DeclareVectorOutputPort("reversals", 1, weak_element(self._sign_and_count, 1),
                                     prerequisites_of_calc={self.xd_ticket()})

    def _sign_and_count(self, context) -> np.ndarray:
        """[bank sign (+1 or -1), reversals so far]."""
        return context.get_discrete_state(self._state).get_value()

    def _bank_command(self, context, output):
        """The bank command [rad]: the sign times the commanded magnitude."""
        output.SetAtIndex(0, self._sign_and_count(context)[0] * self.mag_port.Eval(context)[0])

    def heading_error(self, x) -> float:
        return wrap_angle(x[5] - bearing(x[1], x[2], *self.target))

    def limit(self, V: float) -> float:
        return float(corridor_half_width(V, *self.corridor))

    def new_sign(self, x, sign: float) -> float:
        return float(reversal_sign(self.heading_error(x), self.limit(x[3]), sign))

    def _update(self, context, discrete_state):
        sign, count = context.get_discrete_state(self._state).get_value()
        new = self.new_sign(self.est_port.Eval(context), sign)
        discrete_state.get_mutable_vector(self._state).SetFromVector([new, count + (new != sign)])
