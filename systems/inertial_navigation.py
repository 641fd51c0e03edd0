"""InertialNavigation: the navigation a strapdown INS gives guidance, from the error model of
drake_entry.models.inertial_navigation (entry errors, accelerometer bias and scale factor, gyro
drift, gravity feedback), propagated at the guidance period.

Ports:
  - input  "true_state"         [6]  [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "flight_conditions"  [9]  the plant's (true drag and lift drive the error model)
  - input  "bank"               [1]  the flown bank [rad] (orients the lift)
  - output "estimated_state"    [6]  the INS state: true state with the position and velocity errors
  - output "sensed_conditions"  [9]  the flight conditions with the accelerometers' drag and lift
                                     (the other entries, loads included, stay the true ones)
  - output "navigation_error"   [2]  |position error| [m], |velocity error| [m/s]

The error state is discrete (updated every ``period`` from the inputs held over the step), so
the outputs change only at the updates and the flight's integrator steps are not slowed.
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_entry.errors import ScenarioError
from drake_entry.models import inertial_navigation as ins
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.models.planet import Earth
from drake_entry.systems.lifetime import weak_method

__all__ = ["InertialNavigation"]

_LIFT, _DRAG = FLIGHT_CONDITION_NAMES.index("lift"), FLIGHT_CONDITION_NAMES.index("drag")


class InertialNavigation(LeafSystem):
    def __init__(self, errors: ins.InertialErrors, planet: Earth, *, period: float):
        """Args: errors (one flight's draw), planet (radius and gravity), period [s]."""
        super().__init__()
        if not period > 0:
            raise ScenarioError(f"InertialNavigation.period must be > 0 s, got {period}")
        self.errors, self.planet, self.period = errors, planet, float(period)
        self.true_port = self.DeclareVectorInputPort("true_state", 6)
        self.conditions_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.bank_port = self.DeclareVectorInputPort("bank", 1)
        start = np.zeros(9)
        start[:6] = errors.initial if errors.enabled else 0.0
        self._error = self.DeclareDiscreteState(BasicVector(start))
        if errors.enabled:
            self.DeclarePeriodicDiscreteUpdateEvent(self.period, 0.0, weak_method(self._update))
        deps = {self.true_port.ticket(), self.discrete_state_ticket(self._error)}
        self.DeclareVectorOutputPort("estimated_state", 6, weak_method(self._calc_state), prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("sensed_conditions", len(FLIGHT_CONDITION_NAMES), weak_method(self._calc_sensed),
                                     prerequisites_of_calc={self.conditions_port.ticket()})
        self.DeclareVectorOutputPort("navigation_error", 2, weak_method(self._calc_error),
                                     prerequisites_of_calc={self.discrete_state_ticket(self._error)})

    def _update(self, context, discrete_state):
        x = self.true_port.Eval(context)
        c = self.conditions_port.Eval(context)
        r = float(self.planet.radius(x[0]))
        gravity = float(self.planet.gravity(r, x[2])[0])
        rotation = ins.stability_to_local_level(float(x[4]), float(x[5]), float(self.bank_port.Eval(context)[0]))
        e = context.get_discrete_state(self._error).get_value()
        discrete_state.get_mutable_vector(self._error).SetFromVector(
            ins.propagate(e, self.errors, rotation, float(c[_DRAG]), float(c[_LIFT]), gravity, r, self.period))

    def _calc_state(self, context, output):
        x = self.true_port.Eval(context)
        if not self.errors.enabled:
            output.SetFromVector(x)
            return
        e = context.get_discrete_state(self._error).get_value()
        output.SetFromVector(ins.navigated_state(x, e, float(self.planet.radius(x[0]))))

    def _calc_sensed(self, context, output):
        c = self.conditions_port.Eval(context).copy()
        if self.errors.enabled:
            c[_DRAG], c[_LIFT] = ins.sensed_drag_lift(self.errors, float(c[_DRAG]), float(c[_LIFT]))
        output.SetFromVector(c)

    def _calc_error(self, context, output):
        e = context.get_discrete_state(self._error).get_value()
        output.SetFromVector([np.linalg.norm(e[0:3]), np.linalg.norm(e[3:6])])
