"""The closed-loop entry diagram, shared by every guidance method.

  EntryVehicle --state--> Navigation --estimate--> [method's systems] --bank_command-->
      BankActuator --bank--> EntryVehicle
  alpha: the scenario's alpha schedule (sampled at the guidance period), or the method's
      alpha_command through the rate- and acceleration-limited AlphaActuator
  AtmosphereSystem(state) --air_data--> EntryVehicle, TerminationMonitor
  (vehicle and atmosphere: the native SymbolicVectorSystems or the Python reference systems,
  by the scenario's simulation.plant; systems/native_plant.py)

This module builds the shared parts (vehicle, atmosphere, navigation, actuators,
termination monitor, loggers) and asks the scenario's guidance method
(``drake_entry.guidance``) for the rest. The run stops exactly at the guidance terminal
energy E_f (witness function), or on an altitude floor (a crash guard) or max_time_s;
``fly`` returns the trajectory, the method's summary and the terminal errors in the form of
paper 000 Table 3.
"""
from __future__ import annotations

import dataclasses as dc
import math
import os

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, Multiplexer

from drake_entry.diagrams.common import add_step_loggers, run
from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.guidance import method_for
from drake_entry.guidance.interface import GuidanceMethod, GuidanceSummary, PlantPorts
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.dispersions import Draw
from drake_entry.models.geodesy import range_and_crossrange
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.models.trajectory import Trajectory
from drake_entry.models.vehicles import Vehicle
from drake_entry.models.verdict import ALTITUDE_FLOOR_M, Verdict, altitude_floor, box_text, failure_message, judge
from drake_entry.scenario import Scenario, load_scenario
from drake_entry.systems.actuators import AlphaActuator, BankActuator
from drake_entry.systems.inertial_navigation import InertialNavigation
from drake_entry.systems.lifetime import release_system
from drake_entry.systems.monitors import TerminationMonitor
from drake_entry.systems.native_plant import add_plant
from drake_entry.systems.navigation import Navigation
from drake_entry.systems.schedule import ScheduleSource

__all__ = ["ALTITUDE_FLOOR_M", "altitude_floor", "NAVIGATION_ERROR_COLUMNS", "ClosedLoopSetup", "ClosedLoopResult", "ClosedLoopDiagram", "build_closed_loop",
           "terminal_errors", "acceptance_box", "fly", "summarise"]

#: the logged columns of an INS flight's navigation error (InertialNavigation "navigation_error")
NAVIGATION_ERROR_COLUMNS = ("nav_position_error_m", "nav_velocity_error_m_s")


@dc.dataclass
class ClosedLoopSetup:
    """What every flight of one mission shares (built once per campaign worker).

    Attributes:
      scenario; method: its GuidanceMethod; planner: what ``method.make_planner`` built (given
        the Drake plan verifier, diagrams.verification.fly_controls).
      vehicle, planet, atmosphere: the nominal models (a Monte-Carlo draw disperses copies).
      alpha: the scenario's alpha schedule [rad]. entry_energy, terminal: E_0 [J/kg] and
        (h_f [m], V_f [m/s], E_f [J/kg]) of the guidance terminal interface (central gravity).
    """

    scenario: Scenario
    method: GuidanceMethod
    planner: object
    vehicle: Vehicle
    planet: Earth
    atmosphere: Atmosphere
    alpha: Schedule
    entry_energy: float
    terminal: tuple

    @staticmethod
    def from_scenario(scenario: Scenario, planner=None, method: GuidanceMethod | None = None) -> "ClosedLoopSetup":
        """The setup of a scenario; ``planner`` overrides the method's own (tests, studies);
        ``method`` flies a GuidanceMethod of your own instead of the registered one of the
        scenario's ``guidance:`` spec (which it may read; examples/02_custom_controller.py).
        ``scenario`` may also be a packaged name or a YAML path (read by load_scenario)."""
        if isinstance(scenario, (str, os.PathLike)):
            scenario = load_scenario(scenario)
        if not isinstance(scenario, Scenario):
            raise ScenarioError(f"ClosedLoopSetup.from_scenario needs a Scenario (load_scenario) or a scenario name "
                                f"or path; got {type(scenario).__name__}")
        method = method_for(scenario.guidance) if method is None else method
        return ClosedLoopSetup(
            scenario=scenario, method=method, planner=method.make_planner(scenario, fly_controls) if planner is None else planner,
            vehicle=scenario.make_vehicle(), planet=scenario.make_planet(), atmosphere=scenario.make_atmosphere(),
            alpha=scenario.schedule("alpha"), entry_energy=scenario.entry_energy(),
            terminal=scenario.guidance_terminal_state())

    @property
    def energy_planet(self) -> Earth:
        """The planet of energy-valued schedules and the terminal energy (central gravity)."""
        return self.planet.with_(j2=0.0)


@dc.dataclass
class ClosedLoopResult:
    """One closed-loop flight.

    Attributes:
      trajectory: the flown Trajectory (extra: the method's logged signals and 'bank_command').
      errors: terminal errors (Table 3 form): altitude_m, longitude_deg, latitude_deg,
        velocity_m_s, range_to_go_m (along the heading, + short of the target),
        crossrange_m (+ target to the right), distance_m.
      success: the verdict (drake_entry.models.verdict): reached the terminal interface with the
        guidance active and finite terminal errors, inside every criterion of the mission's
        acceptance box, and every path limit held at every log sample and integrator step.
      message: human summary (the criteria missed and the limits breached, when not a success).
      method: the guidance method's name.
      guidance: the method's GuidanceSummary (plans, planning time, its own fields and details).
      box: the acceptance box per criterion given (acceptance_box).
      reached: the flight stopped at the terminal interface (E_f, or h_f for a spec that
        stops at its altitude), inside the box or not.
      verdict: the Verdict: inside_box, within_limits, each path limit's check (peak, margin).
    """

    trajectory: Trajectory
    errors: dict
    success: bool
    message: str
    method: str
    guidance: GuidanceSummary
    box: dict = dc.field(default_factory=dict)
    reached: bool = False
    verdict: Verdict | None = None


@dc.dataclass
class ClosedLoopDiagram:
    """A built closed loop: the diagram, its loggers by name, the (system, port) each logger
    reads and the table columns of the extra signals (both for collect_trajectory), the
    per-step loggers of the verdict's path limits, and the plant flown ("native" or "python")."""

    diagram: object
    loggers: dict
    sources: dict
    columns: dict
    step_loggers: dict
    plant: str = "python"


def build_closed_loop(setup: ClosedLoopSetup, *, nav_seed: int = 0, nav_bias=None, nav_noise=None,
                      initial_state=None, draw: Draw | None = None) -> ClosedLoopDiagram:
    """The closed-loop diagram of ``setup``'s scenario and guidance method.

    ``initial_state`` becomes the vehicle's default state (what SetRandomContext keeps).
    ``draw`` (a Monte-Carlo sample) disperses the plant: entry state, density, aerodynamic
    scale factors and errors by Mach regime with the trim error, mass and navigation errors; the
    guidance keeps the nominal models.
    """
    scenario, g = setup.scenario, setup.scenario.guidance
    vehicle, atmosphere = setup.vehicle, setup.atmosphere
    if draw is not None:
        vehicle = dc.replace(vehicle, mass=vehicle.mass * draw.mass_scale, aero=draw.aerodynamics(vehicle.aero))
        atmosphere = draw.atmosphere(atmosphere)
        initial_state = scenario.initial_state() + draw.entry_delta
        nav_bias, nav_noise, nav_seed = draw.nav_bias, draw.nav_noise_sigma, draw.nav_seed
    builder = DiagramBuilder()
    x0 = scenario.initial_state() if initial_state is None else np.asarray(initial_state, float)
    plant, air, used = add_plant(builder, vehicle, setup.planet, atmosphere, initial_state=x0,
                           plant=scenario.simulation.plant)
    state, conditions = plant.GetOutputPort("state"), plant.GetOutputPort("flight_conditions")
    inertial = draw.inertial if draw is not None else None
    if inertial is None:
        nav = builder.AddNamedSystem("navigation", Navigation(bias=nav_bias, noise_sigma=nav_noise,
                                                              period=g.period_s, seed=nav_seed))
        sensed = conditions
    else:  # the INS: its state, and the accelerometers' drag and lift
        nav = builder.AddNamedSystem("navigation", InertialNavigation(inertial, setup.planet, period=g.period_s))
        builder.Connect(conditions, nav.GetInputPort("flight_conditions"))
        sensed = nav.GetOutputPort("sensed_conditions")
    builder.Connect(state, nav.GetInputPort("true_state"))
    estimate = nav.GetOutputPort("estimated_state")

    commands = setup.method.add_systems(builder, scenario, setup.planner, PlantPorts(estimate, sensed))

    bank = builder.AddNamedSystem("bank_actuator", BankActuator(
        bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit,
        initial_bank=commands.initial_bank, period=g.period_s))
    builder.Connect(commands.bank, bank.get_input_port())
    builder.Connect(bank.GetOutputPort("bank"), plant.GetInputPort("bank"))
    if commands.bank_sinks:  # the bank flown and its rate, one [2] signal
        flown = builder.AddNamedSystem("bank_flown", Multiplexer([1, 1]))
        builder.Connect(bank.GetOutputPort("bank"), flown.get_input_port(0))
        builder.Connect(bank.GetOutputPort("bank_rate"), flown.get_input_port(1))
        for sink in commands.bank_sinks:
            builder.Connect(flown.get_output_port(), sink)
    if inertial is not None:
        builder.Connect(bank.GetOutputPort("bank"), nav.GetInputPort("bank"))
    if commands.alpha is None:  # the scenario's alpha schedule, sampled at the guidance period
        alpha = builder.AddNamedSystem("alpha_schedule", ScheduleSource(
            setup.alpha, setup.energy_planet, period=g.period_s, initial_value=setup.alpha(setup.entry_energy)))
        for port, source in (("state", estimate), ("flight_conditions", sensed)):
            if alpha.HasInputPort(port):
                builder.Connect(source, alpha.GetInputPort(port))
        alpha_out = alpha.get_output_port()
    else:
        lim = commands.alpha_limits
        if lim is None:
            raise ScenarioError(f"guidance method '{setup.method.name}' commands alpha without alpha_limits")
        alpha = builder.AddNamedSystem("alpha_actuator", AlphaActuator(
            alpha_min=lim.lower, alpha_max=lim.upper, rate_limit=lim.rate, accel_limit=lim.acceleration,
            initial_alpha=commands.initial_alpha, period=g.period_s))
        builder.Connect(commands.alpha, alpha.get_input_port())
        alpha_out = alpha.GetOutputPort("alpha")
    builder.Connect(alpha_out, plant.GetInputPort("alpha"))
    for sink in commands.alpha_sinks:
        builder.Connect(alpha_out, sink)
    # altitudes of the stop and the floor are geodetic with altitude_datum 'ellipsoid'
    stop = ({"altitude": g.terminal_altitude_km * 1e3} if g.stops_at_altitude
            else {"energy": setup.terminal[2], "altitude": altitude_floor(g.terminal_altitude_km * 1e3)})
    monitor = builder.AddNamedSystem("termination", TerminationMonitor(
        **stop, planet=setup.energy_planet, geodetic=scenario.altitude_datum == "ellipsoid"))
    builder.Connect(state, monitor.GetInputPort("state"))
    builder.Connect(air.GetOutputPort("air_data"), monitor.GetInputPort("air_data"))

    signals = {"state": state, "conditions": conditions, "bank": bank.GetOutputPort("bank"), "alpha": alpha_out,
               "bank_command": commands.bank}
    signals.update({name: logged.port for name, logged in commands.logged.items()})
    if inertial is not None:
        signals["navigation_error"] = nav.GetOutputPort("navigation_error")
    period = scenario.simulation.log_period_s
    loggers = {name: LogVectorOutput(port, builder, period) for name, port in signals.items()}
    step_loggers = add_step_loggers(builder, signals)
    sources = {name: (port.get_system().get_name(), port.get_name()) for name, port in signals.items()}
    columns = {"bank_command": ("bank_command_rad",), **{n: s.columns for n, s in commands.logged.items()}}
    if inertial is not None:
        columns["navigation_error"] = NAVIGATION_ERROR_COLUMNS
    diagram = builder.Build()
    diagram.set_name(f"closed_loop_{scenario.name}_{setup.method.name}")
    return ClosedLoopDiagram(diagram, loggers, sources, columns, step_loggers, used)


def terminal_errors(x, setup: ClosedLoopSetup) -> dict:
    """Final errors against the guidance terminal interface and the target (Table 3 form)."""
    h_f, V_f, _ = setup.terminal
    tlon, tlat = math.radians(setup.scenario.target.longitude_deg), math.radians(setup.scenario.target.latitude_deg)
    rng, cross, dist = range_and_crossrange(x[1], x[2], x[5], tlon, tlat, setup.planet.reference_radius)
    return {"altitude_m": float(x[0] - h_f), "longitude_deg": math.degrees(x[1] - tlon),
            "latitude_deg": math.degrees(x[2] - tlat), "velocity_m_s": float(x[3] - V_f),
            "range_to_go_m": rng, "crossrange_m": cross, "distance_m": dist}


def acceptance_box(tr: Trajectory, setup: ClosedLoopSetup, distance_m: float) -> dict:
    """The mission's acceptance box (Scenario.acceptance_box) at the final state: the Mach number
    and angle of attack flown, the distance to the target ``distance_m`` (terminal_errors')."""
    return setup.scenario.acceptance_box(setup.planet, tr.state[-1], mach=float(tr.column("mach")[-1]),
                                         distance_m=distance_m, alpha_rad=float(tr.column("alpha")[-1]))


def fly(scenario: Scenario | ClosedLoopSetup, planner=None, *, initial_state=None, nav_seed: int = 0,
        nav_bias=None, nav_noise=None, draw: Draw | None = None) -> ClosedLoopResult:
    """Fly the closed loop once (the nominal entry state unless ``initial_state`` or a
    Monte-Carlo ``draw`` is given). Pass a ClosedLoopSetup to reuse its planner and models."""
    setup = scenario if isinstance(scenario, ClosedLoopSetup) else ClosedLoopSetup.from_scenario(scenario, planner)
    built = build_closed_loop(setup, nav_seed=nav_seed, nav_bias=nav_bias, nav_noise=nav_noise,
                              initial_state=initial_state, draw=draw)
    try:
        tr, simulator = run(built.diagram, built.loggers, setup.scenario, sources=built.sources, closed_loop=True,
                            columns=built.columns, step_loggers=built.step_loggers)
        return summarise(setup, built.diagram, simulator.get_context(), tr)
    finally:
        release_system(built.diagram)


def summarise(setup: ClosedLoopSetup, diagram, ctx, tr: Trajectory) -> ClosedLoopResult:
    """ClosedLoopResult of a finished closed-loop simulation, with its verdict."""
    guidance = setup.method.summarise(diagram, ctx, setup.planner)
    errors = terminal_errors(tr.state[-1], setup)
    box = acceptance_box(tr, setup, errors["distance_m"])
    missed = [f"{k} {box_text(k, b)}" for k, b in box.items() if not b["inside"]]
    by_altitude = setup.scenario.guidance.stops_at_altitude
    name = "h_f" if by_altitude else "E_f"
    reached = ("altitude" if by_altitude else "energy") in tr.reason
    finite = all(math.isfinite(v) for v in errors.values())
    verdict = judge(tr, setup.scenario.path_limits(setup.vehicle), reached=reached and guidance.active and finite,
                    inside_box=finite and not missed, tolerance=setup.scenario.terminal.path_limit_tolerance)
    if not reached:
        msg = f"stopped before {name}: {tr.reason}"
    elif not guidance.active:
        msg = guidance.message
    elif not finite:
        msg = f"reached {name} with non-finite terminal errors {errors}"
    else:
        where = f"reached {name} at t = {tr.time[-1]:.1f} s, {errors['distance_m'] / 1e3:.3f} km from the target"
        msg = failure_message(missed, verdict.violations_text(), where)
    return ClosedLoopResult(tr, errors, verdict.success, msg, setup.method.name, guidance, box, reached, verdict)
