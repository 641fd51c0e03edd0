"""TerminationMonitor: stops a simulation exactly when the vehicle reaches the terminal
interface (witness functions, located by Drake's event isolation).

Conditions (each optional): altitude below ``altitude`` [m], Mach below ``mach``,
specific energy below ``energy`` [J/kg], speed below ``velocity`` [m/s]. Whichever
triggers first ends the run; ``reason`` names it.

Ports:
  input "state"     [6]  vehicle state
  input "air_data"  [2]  density, speed of sound (AtmosphereSystem output): Mach = V / a
                         reuses the air data the vehicle already evaluated at that state
"""
from __future__ import annotations

from pydrake.systems.framework import EventStatus, LeafSystem, PublishEvent, WitnessFunctionDirection

from drake_entry.dynamics import specific_energy
from drake_entry.errors import ScenarioError
from drake_entry.planet import Earth


class TerminationMonitor(LeafSystem):
    def __init__(self, *, altitude: float | None = None, mach: float | None = None,
                 energy: float | None = None, velocity: float | None = None, planet: Earth | None = None):
        """Targets in SI: altitude [m], Mach, energy [J/kg] (with ``planet``), velocity [m/s]."""
        super().__init__()
        self.planet = planet or Earth()
        self.state_port = self.DeclareVectorInputPort("state", 6)
        self.air_port = self.DeclareVectorInputPort("air_data", 2)
        self.reason = None
        self.targets = {k: v for k, v in (("altitude", altitude), ("mach", mach), ("energy", energy),
                                          ("velocity", velocity)) if v is not None}
        if not self.targets:
            raise ScenarioError("TerminationMonitor needs at least one of altitude, mach, energy, velocity")
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
        if name == "mach":
            return lambda c: self.state_port.Eval(c)[3] / self.air_port.Eval(c)[1] - target
        return lambda c: specific_energy(self.state_port.Eval(c), self.planet) - target

    def _make_handler(self, name):
        def handler(context, event):
            self.reason = name
            return EventStatus.ReachedTermination(self, f"reached {name} = {self.targets[name]:g}")
        return handler

    def DoGetWitnessFunctions(self, context):
        return self._witnesses
