"""ScheduleSource: an open-loop command (bank or angle of attack) from a ``Schedule``.

Ports:
  - input  "state"              [6]  (energy- or velocity-scheduled, or Mach from air data) vehicle state
  - input  "flight_conditions"  [9]  (Mach-scheduled, mach_from 'flight_conditions') EntryVehicle flight conditions
  - input  "air_data"           [2]  (Mach-scheduled, mach_from 'air_data') density, speed of sound: Mach = V / a
  - output "command"            [1]  the scheduled value (rad for angles)

A continuous alpha schedule in Mach reads Mach from the state and the air data (as the
termination monitor does): the flight conditions depend on alpha, so reading them would close an
algebraic loop; a sampled source (``period``) may read them.
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
from drake_entry.systems.lifetime import weak_method

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
    return ScheduleSource(schedule, planet, mach_from="air_data")


class ScheduleSource(LeafSystem):
    """Args: schedule; planet (for energy schedules); period [s]: if given, the command is
    sampled every period and held (a guidance command, cheap for the integrator),
    starting from ``initial_value``; otherwise it is evaluated continuously."""

    def __init__(self, schedule: Schedule, planet: Earth | None = None, period: float | None = None,
                 initial_value: float = 0.0, mach_from: str = "flight_conditions"):
        super().__init__()
        self.schedule = schedule
        self.planet = planet or Earth()
        var = schedule.variable
        if mach_from not in ("flight_conditions", "air_data"):
            raise ScenarioError(f"ScheduleSource.mach_from = {mach_from!r}; allowed: 'flight_conditions', 'air_data'")
        air = var == "mach" and mach_from == "air_data"
        self.state_port = self.DeclareVectorInputPort("state", 6) if var in ("energy", "velocity") or air else None
        self.conditions_port = (self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
                                if var == "mach" and not air else None)
        self.air_port = self.DeclareVectorInputPort("air_data", 2) if air else None
        if period is not None:
            if not period > 0:
                raise ScenarioError(f"ScheduleSource.period must be > 0 s, got {period}")
            self._held = self.DeclareDiscreteState([initial_value])
            self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, weak_method(self._sample))
            self.DeclareForcedDiscreteUpdateEvent(weak_method(self._sample))
            self.DeclareStateOutputPort("command", self._held)
            return
        prereq = {self.time_ticket()} if var == "time" else {self.all_input_ports_ticket()}
        self.DeclareVectorOutputPort("command", 1, weak_method(self._calc), prerequisites_of_calc=prereq)

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
        elif self.air_port is not None:
            s = self.state_port.Eval(context)[3] / self.air_port.Eval(context)[1]
        else:
            s = self.conditions_port.Eval(context)[FLIGHT_CONDITION_NAMES.index("mach")]
        return self.schedule(float(s))
