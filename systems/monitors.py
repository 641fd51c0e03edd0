"""TerminationMonitor: stops a simulation exactly when the vehicle reaches the terminal
interface (witness functions, located by Drake's event isolation).

Conditions: Mach below ``mach``, specific energy below ``energy`` [J/kg], speed below
``velocity`` [m/s] (each optional), and always an altitude band: below ``altitude`` [m]
(the terminal altitude or a crash floor; the surface, 0 m, when not given; the state
altitude, or with ``geodetic=True`` the altitude above the ellipsoid) or above
``ceiling`` [m] (skipped out: the vehicle left the atmosphere model). The band is one
witness, min(h - floor, ceiling - h), so the ceiling costs nothing per step. Whichever
triggers first ends the run; ``reason`` names it ("reached energy", "reached the surface",
"skipped out above the atmosphere", ...) and the termination message adds the value.

Ports:
  - input "state"     [6]  vehicle state
  - input "air_data"  [2]  density, speed of sound (AtmosphereSystem output): Mach = V / a
                         reuses the air data the vehicle already evaluated at that state
"""
from __future__ import annotations

from pydrake.systems.framework import EventStatus, LeafSystem, PublishEvent, WitnessFunctionDirection

from drake_entry.errors import ModelRangeError, NonFiniteStateError, ScenarioError
from drake_entry.models.atmosphere import US76_H_MAX
from drake_entry.models.dynamics import specific_energy
from drake_entry.models.planet import Earth
from drake_entry.systems.lifetime import weak_method

__all__ = ["CEILING_M", "require_finite", "TerminationMonitor", "PlantGuard"]

#: default ceiling [m]: 100 km under the top of the US76 model (1000 km), so that an
#: integrator's trial stages (10 s steps at several km/s) stay inside the model
CEILING_M = US76_H_MAX - 100e3


def require_finite(x, context):
    """``x``, the vehicle state [6]; NonFiniteStateError (with the time) when any entry is NaN or
    infinite: how the witnesses below stop a native-plant flight, which cannot raise itself."""
    total = float(x.sum())
    if total - total != 0.0:
        raise NonFiniteStateError(f"non-finite vehicle state at t = {context.get_time():.3f} s: {x.tolist()}")
    return x


class TerminationMonitor(LeafSystem):
    def __init__(self, *, altitude: float | None = None, mach: float | None = None,
                 energy: float | None = None, velocity: float | None = None, planet: Earth | None = None,
                 ceiling: float = CEILING_M, geodetic: bool = False):
        """Targets in SI: altitude [m] (floor; default the surface), Mach, energy [J/kg]
        (with ``planet``), velocity [m/s]; ceiling [m] above which the vehicle skipped out;
        geodetic: the floor is a geodetic altitude (planet.atmospheric_altitude)."""
        super().__init__()
        self.planet = planet or Earth()
        self.geodetic = bool(geodetic)
        self.state_port = self.DeclareVectorInputPort("state", 6)
        self.air_port = self.DeclareVectorInputPort("air_data", 2)
        self.reason = None
        floor = 0.0 if altitude is None else float(altitude)
        if not floor < ceiling:
            raise ScenarioError(f"TerminationMonitor.altitude = {floor:g} m must be below the ceiling {ceiling:g} m")
        self.floor, self.ceiling = floor, float(ceiling)
        self.targets = {k: v for k, v in (("altitude", altitude), ("mach", mach), ("energy", energy),
                                          ("velocity", velocity)) if v is not None}
        self._witnesses = []
        for name in ("altitude", "mach", "energy", "velocity"):
            if name != "altitude" and name not in self.targets:
                continue
            event = PublishEvent(weak_method(self._reached, name))
            self._witnesses.append(self.MakeWitnessFunction(
                f"reached {name}", WitnessFunctionDirection.kPositiveThenNonPositive,
                weak_method(self._distance, name), event))

    def _altitude(self, context) -> float:
        """The altitude the band bounds [m]: the state altitude, or the geodetic one. A
        non-finite state stops the run here with NonFiniteStateError (the native plant, unlike
        the Python one, cannot raise from its derivatives; this witness runs every step)."""
        x = require_finite(self.state_port.Eval(context), context)
        return self.planet.atmospheric_altitude(x[0], x[2]) if self.geodetic else x[0]

    def _distance(self, context, name: str) -> float:
        """The witness value of target ``name``, positive before it is reached: the altitude's
        distance to the band [floor, ceiling] [m], or the velocity [m/s], Mach or energy [J/kg]
        above its target."""
        if name == "altitude":
            h = self._altitude(context)
            return min(h - self.floor, self.ceiling - h)
        x = self.state_port.Eval(context)
        if name == "velocity":
            return x[3] - self.targets[name]
        if name == "mach":
            return x[3] / self.air_port.Eval(context)[1] - self.targets[name]
        return specific_energy(x, self.planet) - self.targets[name]

    def _reached(self, context, event, name: str):
        """Ends the flight at target ``name`` with its reason (``self.reason``)."""
        if name != "altitude":
            self.reason, detail = f"reached {name}", f" = {self.targets[name]:g}"
        elif self._altitude(context) > 0.5 * (self.floor + self.ceiling):
            self.reason, detail = "skipped out above the atmosphere", f" (h = {self.ceiling / 1e3:g} km)"
        elif "altitude" in self.targets:
            self.reason, detail = "reached altitude", f" = {self.floor:g}"
        else:
            self.reason, detail = "reached the surface", " (h = 0 m)"
        return EventStatus.ReachedTermination(self, self.reason + detail)

    def DoGetWitnessFunctions(self, context):
        return self._witnesses


class PlantGuard(LeafSystem):
    """Stops a flight whose state leaves what the models cover, as the Python plant does from
    inside its derivatives: a non-finite state raises NonFiniteStateError, an altitude outside
    [h_min, h_max] of the atmosphere model ModelRangeError, each at the end of the integrator
    step where it happens (one witness evaluation per step, never triggered otherwise). The
    native plant (systems/native_plant.py) computes in C++ and cannot raise; diagrams without a
    TerminationMonitor (the plan verifier's flights) add this guard.

    Ports:
      - input "state" [6]  vehicle state
    """

    def __init__(self, *, h_min: float, h_max: float, model: str, planet: Earth | None = None):
        """Args: h_min, h_max [m] the atmosphere model's range; model: its name for the message;
        planet: whose planet.atmospheric_altitude the atmosphere sees."""
        super().__init__()
        self.h_min, self.h_max, self.model = float(h_min), float(h_max), model
        self.planet = planet or Earth()
        self.state_port = self.DeclareVectorInputPort("state", 6)
        self._witness = [self.MakeWitnessFunction("plant guard", WitnessFunctionDirection.kNone,
                                                  weak_method(self._check))]

    def _check(self, context) -> float:
        x = require_finite(self.state_port.Eval(context), context)
        h = self.planet.atmospheric_altitude(x[0], x[2])
        if not self.h_min <= h <= self.h_max:
            raise ModelRangeError(f"altitude h = {h:.6g} m is outside the {self.model} range "
                                  f"[{self.h_min:.6g}, {self.h_max:.6g}] m")
        return 1.0

    def DoGetWitnessFunctions(self, context):
        return self._witness
