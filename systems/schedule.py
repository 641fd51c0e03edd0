"""ScheduleSource: an open-loop command (bank or angle of attack) from a ``Schedule``.

Ports:
  - input  "state"              [6]  (energy-, Mach- or velocity-scheduled only) vehicle state
  - input  "flight_conditions"  [9]  (Mach-scheduled only) EntryVehicle flight conditions
  - output "command"            [1]  the scheduled value (rad for angles)
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.errors import ScenarioError
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES, specific_energy
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule

__all__ = ["make_schedule_source", "ScheduleSource"]


def make_schedule_source(schedule: Schedule, planet: Earth | None = None):
    """The cheapest source for a schedule: a native TrajectorySource (first-order hold,
    held constant outside the breakpoints) for piecewise-linear time schedules, else a
    ScheduleSource. Both have the output port "command" at index 0."""
    if schedule.variable == "time" and not schedule.smooth:
        bp = np.asarray(schedule.breakpoints, float)
        v = np.asarray(schedule.values, float)
        far = 1e9
        times = np.concatenate([[min(bp[0], 0.0) - far], bp, [bp[-1] + far]])
        values = np.concatenate([[v[0]], v, [v[-1]]])
        return TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, values.reshape(1, -1)))
    return ScheduleSource(schedule, planet)


class ScheduleSource(LeafSystem):
    """Args: schedule; planet (for energy schedules); period [s]: if given, the command is
    sampled every period and held (a guidance command, cheap for the integrator),
    starting from ``initial_value``; otherwise it is evaluated continuously."""

    def __init__(self, schedule: Schedule, planet: Earth | None = None, period: float | None = None,
                 initial_value: float = 0.0):
        super().__init__()
        self.schedule = schedule
        self.planet = planet or Earth()
        var = schedule.variable
        self.state_port = self.DeclareVectorInputPort("state", 6) if var in ("energy", "velocity") else None
        self.conditions_port = (
            self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES)) if var == "mach" else None
        )
        if period is not None:
            if not period > 0:
                raise ScenarioError(f"ScheduleSource.period must be > 0 s, got {period}")
            self._held = self.DeclareDiscreteState([initial_value])
            self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._sample)
            self.DeclareForcedDiscreteUpdateEvent(self._sample)
            self.DeclareStateOutputPort("command", self._held)
            return
        prereq = {self.time_ticket()} if var == "time" else {self.all_input_ports_ticket()}
        self.DeclareVectorOutputPort("command", 1, self._calc, prerequisites_of_calc=prereq)

    def _sample(self, context, discrete_state):
        discrete_state.get_mutable_vector(self._held).SetAtIndex(0, self.value(context))

    def _calc(self, context, output):
        output.SetAtIndex(0, self.value(context))

    def value(self, context) -> float:
        var = self.schedule.variable
        if var == "time":
            s = context.get_time()
        elif var == "energy":
            s = specific_energy(self.state_port.Eval(context), self.planet)
        elif var == "velocity":
            s = self.state_port.Eval(context)[3]
        else:
            s = self.conditions_port.Eval(context)[FLIGHT_CONDITION_NAMES.index("mach")]
        return self.schedule(float(s))
