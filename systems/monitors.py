"""TerminationMonitor: stops a simulation exactly when the vehicle reaches the terminal
interface (witness functions, located by Drake's event isolation).

Conditions (each optional): altitude below ``altitude`` [m], Mach below ``mach``,
specific energy below ``energy`` [J/kg], speed below ``velocity`` [m/s]. Whichever
triggers first ends the run; ``reason`` names it.

Ports:
  input "state"              [6]
  input "flight_conditions"  [9]  (EntryVehicle output)
"""
from __future__ import annotations

from pydrake.systems.framework import EventStatus, LeafSystem, PublishEvent, WitnessFunctionDirection

from drake_entry.dynamics import FLIGHT_CONDITION_NAMES

_MACH = FLIGHT_CONDITION_NAMES.index("mach")
_ENERGY = FLIGHT_CONDITION_NAMES.index("energy")


class TerminationMonitor(LeafSystem):
    def __init__(self, *, altitude: float | None = None, mach: float | None = None,
                 energy: float | None = None, velocity: float | None = None):
        super().__init__()
        self.state_port = self.DeclareVectorInputPort("state", 6)
        self.conditions_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.reason = None
        self.targets = {k: v for k, v in (("altitude", altitude), ("mach", mach), ("energy", energy),
                                          ("velocity", velocity)) if v is not None}
        if not self.targets:
            raise ValueError("TerminationMonitor needs at least one of altitude, mach, energy, velocity")
        self._witnesses = []
        for name, target in self.targets.items():
            calc = self._make_calc(name, target)
            event = PublishEvent(self._make_handler(name))
            self._witnesses.append(self.MakeWitnessFunction(
                f"reached {name}", WitnessFunctionDirection.kPositiveThenNonPositive, calc, event))

    def _make_calc(self, name, target):
        if name == "altitude":
            return lambda c: self.state_port.Eval(c)[0] - target
        if name == "velocity":
            return lambda c: self.state_port.Eval(c)[3] - target
        index = _MACH if name == "mach" else _ENERGY
        return lambda c: self.conditions_port.Eval(c)[index] - target

    def _make_handler(self, name):
        def handler(context, event):
            self.reason = name
            return EventStatus.ReachedTermination(self, f"reached {name} = {self.targets[name]:g}")
        return handler

    def DoGetWitnessFunctions(self, context):
        return self._witnesses
