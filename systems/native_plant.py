"""The plant evaluated natively: the vehicle's equations of motion, its flight conditions and
the atmosphere's air data as Drake ``SymbolicVectorSystem``s, built from the same model code
(drake_entry.models: dynamics, atmosphere, aerodynamics, heat flux) called with symbolic
scalars. Drake then evaluates every derivative and every output in C++: no Python callback
per integrator stage. The Python systems (``EntryVehicle``, ``AtmosphereSystem``) stay the
reference; tests hold the two to each other (derivatives, conditions, a flight's end).

NativeEntryVehicle (a Diagram named like the vehicle it replaces, the same ports):
  - input  "bank" [1] and "alpha" [1] in rad, "air_data" [2] (density kg/m^3, speed of sound m/s),
    "wind" [2] (only with winds=True: east, north wind m/s)
  - output "state"             [6]  [h m, lon rad, lat rad, V m/s, gamma rad, psi rad]
  - output "flight_conditions" [9]  drake_entry.models.dynamics.FlightConditions
  inside: "equations_of_motion", a SymbolicVectorSystem whose continuous state is the
  deviation from the entry state (a SymbolicVectorSystem's default state is zero, and
  Drake's RandomSimulation resets every context to its defaults), and "flight_conditions",
  an algebraic one fed by state, alpha and air data (``stateless``).
NativeAtmosphere: input "state" [6] -> output "air_data" [2] (and "wind" [2] when the atmosphere
has a wind), as AtmosphereSystem.

``add_plant`` builds either realisation into a diagram; the scenario's
``simulation.plant`` chooses ("auto" by default: native when every model has a symbolic form,
which every packaged vehicle and atmosphere has; "python" for the reference).
"""
from __future__ import annotations

import numpy as np
from pydrake.symbolic import Expression, Variable
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Multiplexer, SymbolicVectorSystem

from drake_entry.errors import ModelRangeError, NonFiniteStateError, ScenarioError, UnsupportedScalarError
from drake_entry.models import dynamics
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.symbolic_system import expression, stateless
from drake_entry.models.vehicles import Vehicle
from drake_entry.scenario import PLANTS
from drake_entry.systems.atmosphere import AtmosphereSystem
from drake_entry.systems.vehicle import N_STATE, EntryVehicle

__all__ = ["STATE", "DEVIATION", "BANK", "ALPHA", "RHO", "SPEED_OF_SOUND", "WIND", "AIR_VELOCITY", "NativeAtmosphere", "NativeEntryVehicle",
           "SYMBOLIC_DOMAIN_ERROR", "as_flight_error", "flight_stop", "add_plant", "PlantProbe"]

#: the symbols of every native plant (shared, so each nominal model's expression trees are
#: built once per process and reused by every dispersed copy: Atmosphere.symbolic_profile)
STATE = [Variable(name) for name in dynamics.STATE_NAMES]
DEVIATION = [Variable(f"d{name}") for name in dynamics.STATE_NAMES]
BANK, ALPHA, RHO, SPEED_OF_SOUND = (Variable(n) for n in ("bank", "alpha", "rho", "speed_of_sound"))
WIND = [Variable("wind_east"), Variable("wind_north")]
AIR_VELOCITY = [Variable(n) for n in ("air_east", "air_north", "air_up", "air_horizontal", "airspeed")]



class NativeAtmosphere(Diagram):
    """Air data of ``atmosphere`` along the state, evaluated natively (module docstring)."""

    def __init__(self, atmosphere: Atmosphere, planet: Earth):
        Diagram.__init__(self)
        x = [Expression(v) for v in STATE]
        with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
            rho, a = dynamics.air_data(x, planet, atmosphere)
        builder = DiagramBuilder()
        leaf = builder.AddNamedSystem("air_data", stateless(STATE, [rho, a]))
        builder.ExportInput(leaf.get_input_port(), "state")
        builder.ExportOutput(leaf.get_output_port(), "air_data")
        if atmosphere.has_wind:
            with np.errstate(all="ignore"):
                wind = dynamics.wind_at(x, planet, atmosphere)
            moving = builder.AddNamedSystem("wind", stateless(STATE, list(wind)))
            builder.ConnectInput("state", moving.get_input_port())
            builder.ExportOutput(moving.get_output_port(), "wind")
        builder.BuildInto(self)


class NativeEntryVehicle(Diagram):
    """The 3-DOF entry plant of ``vehicle`` on ``planet``, evaluated natively (module
    docstring); air data come in on "air_data" (a NativeAtmosphere or AtmosphereSystem).

    Args: vehicle, planet; initial_state [6] SI (the default state, what a context reset keeps);
    winds: take the wind on input "wind" (the air-relative velocity sets the aerodynamics).
    """

    def __init__(self, vehicle: Vehicle, planet: Earth, *, initial_state=None, winds: bool = False):
        Diagram.__init__(self)
        self.x0 = np.zeros(N_STATE) if initial_state is None else np.asarray(initial_state, float).copy()
        x = [Expression(d) + float(x0) for d, x0 in zip(DEVIATION, self.x0)]
        bank, alpha, rho, a = (Expression(v) for v in (BANK, ALPHA, RHO, SPEED_OF_SOUND))
        state = [Expression(v) for v in STATE]
        # in a wind the air-relative velocity is an input (computed once by "air_velocity" from the
        # state and the wind), since Drake evaluates an expression tree without sharing repeated parts
        wind = [Expression(v) for v in WIND] if winds else None
        velocity = [Expression(v) for v in AIR_VELOCITY] if winds else None
        speed = velocity[4] if winds else None
        relative = (velocity[:3], velocity[3], velocity[4]) if winds else None
        air = [RHO, SPEED_OF_SOUND, *(WIND + AIR_VELOCITY if winds else [])]
        with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
            _, L, D = dynamics.aero_accelerations(x, alpha, rho, a, vehicle, wind, speed)
            xdot = dynamics.equations_of_motion(x, bank, L, D, planet, wind, relative)
            conditions = dynamics.conditions_from(state, alpha, rho,
                                                  *dynamics.aero_accelerations(state, alpha, rho, a, vehicle, wind, speed),
                                                  vehicle, planet, speed)
            if winds:
                (ve, vn, vu), vh, va = dynamics.air_relative_velocity(state, [Expression(v) for v in WIND])
        builder = DiagramBuilder()
        motion = builder.AddNamedSystem("equations_of_motion", SymbolicVectorSystem(
            state=DEVIATION, input=[BANK, ALPHA, *air], dynamics=list(xdot), output=x))
        cond = builder.AddNamedSystem("flight_conditions", stateless([*STATE, ALPHA, *air],
                                                                     [expression(c) for c in conditions]))
        inputs = [("alpha", 1), ("air_data", 2)] + ([("wind", 2)] if winds else [])
        sizes = [n for _, n in inputs] + ([len(AIR_VELOCITY)] if winds else [])
        controls = builder.AddNamedSystem("controls", Multiplexer([1] + sizes))
        flight = builder.AddNamedSystem("state_alpha_air", Multiplexer([N_STATE] + sizes))
        builder.Connect(controls.get_output_port(), motion.get_input_port())
        builder.Connect(motion.get_output_port(), flight.get_input_port(0))
        builder.Connect(flight.get_output_port(), cond.get_input_port())
        builder.ExportInput(controls.get_input_port(0), "bank")
        for k, (name, _) in enumerate(inputs, start=1):  # each input feeds both systems
            builder.ExportInput(controls.get_input_port(k), name)
            builder.ConnectInput(name, flight.get_input_port(k))
        if winds:  # the air-relative velocity of the state in the wind, into both systems
            speed_of = builder.AddNamedSystem("air_velocity", stateless([*STATE, *WIND], [ve, vn, vu, vh, va]))
            state_wind = builder.AddNamedSystem("state_wind", Multiplexer([N_STATE, 2]))
            builder.Connect(motion.get_output_port(), state_wind.get_input_port(0))
            builder.ConnectInput("wind", state_wind.get_input_port(1))
            builder.Connect(state_wind.get_output_port(), speed_of.get_input_port())
            builder.Connect(speed_of.get_output_port(), controls.get_input_port(len(inputs) + 1))
            builder.Connect(speed_of.get_output_port(), flight.get_input_port(len(inputs) + 1))
        builder.ExportOutput(motion.get_output_port(), "state")
        builder.ExportOutput(cond.get_output_port(), "flight_conditions")
        builder.BuildInto(self)
        self._motion = motion

    def state_derivatives(self, context) -> np.ndarray:
        """dx/dt [6] (SI per s) at this plant's ``context``: the equations of motion alone."""
        return self._motion.EvalTimeDerivatives(self.GetSubsystemContext(self._motion, context)).CopyToVector()

    def set_initial_state(self, context, x0):
        """Set the state [h, lon, lat, V, gamma, psi] (SI) in this plant's ``context``."""
        self.GetMutableSubsystemContext(self._motion, context).SetContinuousState(np.asarray(x0, float) - self.x0)


#: what Drake's symbolic evaluation says when a NaN (or a negative number) reaches a sqrt or log
SYMBOLIC_DOMAIN_ERROR = "numerical argument out of domain"


def as_flight_error(error: BaseException) -> BaseException:
    """The error a flight stops on for ``error`` raised inside a simulation: a ValueError from
    Drake's symbolic evaluation of the native plant (a NaN state reaching the atmosphere's sqrt
    or log, often inside an integrator stage, before a witness sees it) becomes the
    NonFiniteStateError the Python plant raises; any other error is returned as it is."""
    if isinstance(error, ValueError) and SYMBOLIC_DOMAIN_ERROR in str(error):
        return NonFiniteStateError(f"non-finite vehicle state in the native plant ({str(error).splitlines()[0]})")
    return error


def flight_stop(error: BaseException) -> BaseException | None:
    """The error a flight stops on (``as_flight_error``), or None when ``error`` is a bug to
    re-raise: a ValueError that is neither the native plant's NaN nor a ModelRangeError (a state
    the models do not cover, e.g. below the atmosphere model: a stop, not a bug)."""
    e = as_flight_error(error)
    if isinstance(e, ValueError) and not isinstance(e, ModelRangeError):
        return None
    return e


def add_plant(builder, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, *, initial_state,
              plant: str = "auto"):
    """Add the vehicle (named "vehicle") and its atmosphere ("atmosphere") to ``builder``, the
    air data wired in; returns (vehicle system, atmosphere system, the realisation used:
    "native" or "python").

    ``plant``: "native" (the SymbolicVectorSystems; a model with no symbolic form, such as an
    aerodynamic table or a user function written with ``math``, is a ScenarioError naming it),
    "python" (EntryVehicle and AtmosphereSystem, the reference), or "auto" (native when every
    model has a symbolic form, else python)."""
    if plant not in PLANTS:
        raise ScenarioError(f"simulation.plant = '{plant}'; allowed: {', '.join(PLANTS)}")
    systems, used = None, "python"
    if plant != "python":
        try:
            systems = (NativeEntryVehicle(vehicle, planet, initial_state=initial_state, winds=atmosphere.has_wind),
                       NativeAtmosphere(atmosphere, planet))
            used = "native"
        except (UnsupportedScalarError, TypeError) as e:
            if plant == "native":
                raise ScenarioError(f"simulation.plant = 'native' needs models with a symbolic form: {e} "
                                    f"(use plant 'auto' or 'python')") from None
    if systems is None:
        systems = (EntryVehicle(vehicle, planet, atmosphere, initial_state=initial_state, air_data_input=True,
                                wind_input=atmosphere.has_wind),
                   AtmosphereSystem(atmosphere, planet))
    body = builder.AddNamedSystem("vehicle", systems[0])
    air = builder.AddNamedSystem("atmosphere", systems[1])
    builder.Connect(body.GetOutputPort("state"), air.GetInputPort("state"))
    builder.Connect(air.GetOutputPort("air_data"), body.GetInputPort("air_data"))
    if atmosphere.has_wind:
        builder.Connect(air.GetOutputPort("wind"), body.GetInputPort("wind"))
    return body, air, used


class PlantProbe:
    """One plant (``add_plant``) alone, its controls as inputs: ``probe(x, bank, alpha)`` gives its
    state derivatives [6] and flight conditions [9] (SI) at any state and controls, to compare
    realisations (tests, example 13). ``plant`` is the realisation built ("native" or "python")."""

    def __init__(self, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, plant: str = "auto"):
        builder = DiagramBuilder()
        self.system, _, self.plant = add_plant(builder, vehicle, planet, atmosphere, initial_state=None, plant=plant)
        builder.ExportInput(self.system.GetInputPort("bank"), "bank")
        builder.ExportInput(self.system.GetInputPort("alpha"), "alpha")
        self.diagram = builder.Build()

    def __call__(self, x, bank: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        ctx = self.diagram.CreateDefaultContext()
        self.diagram.GetInputPort("bank").FixValue(ctx, [bank])
        self.diagram.GetInputPort("alpha").FixValue(ctx, [alpha])
        sub = self.system.GetMyMutableContextFromRoot(ctx)
        self.system.set_initial_state(sub, x)
        return self.system.state_derivatives(sub), self.system.GetOutputPort("flight_conditions").Eval(sub).copy()

