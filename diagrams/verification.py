"""The plan verifier: a plan's controls flown by the Drake Simulator, the one path by which
every planner's ``success`` is judged (the contract is drake_entry.planning.verification;
planners receive ``fly_controls`` as their ``verifier``).

Entry controls (SCvx plans), as the closed loop flies them:

    bank(t + lead) --> BankActuator (sampled every period) --bank--> EntryVehicle
    alpha(t + lead) or ScheduleSource(alpha(V)) --> AlphaActuator --alpha--> EntryVehicle
    (with ``tracking``: ReplanningGuidance without re-plans, its feedback fed the flown state,
     --bank_command, alpha_command--> the actuators, as the closed loop flies a plan)
    AtmosphereSystem(state) --air_data--> EntryVehicle; PlantGuard(state) (native plant)

A command known in advance (the plan's spline) is flown as its actuator's response, computed
before the flight by the actuator's own law and segments (``LimitedActuator.response``: the
segments its periodic update would make, joined into a cubic Hermite TrajectorySource), so the
flight makes no Python call per integrator stage; ``actuator_systems=True`` flies the sampled
actuator systems themselves (tests hold the two to each other). alpha(V), a law of the state,
always goes through the AlphaActuator system.

Without ``actuation`` the C2 splines feed the vehicle directly. Optimal-control controls (NLP
solutions):

    TrajectorySource(u(t)) --u--> the problem's dynamics (SI); PlantGuard(h, lon, lat, V, gamma, psi)

the dynamics as a SymbolicVectorSystem evaluated in C++ (planning.ocp_system.native_ocp_plant;
the guard stops the flight where the Python plant's models would raise) when every model of the
problem has a symbolic form, else OptimalControlPlant (Python, the reference; tests hold the
two to each other).

Integration. Through the sampled actuators (whose path has a kink at every 0.02-s sub-step)
the flight takes fixed RK5 steps of ``period / ENTRY_STEPS_PER_PERIOD``; on the nominal
SPHYNX plan of paper 001 (1-s period) this ends 0.3 m from an error-controlled RK5 flight at
accuracy 1e-9 in 0.98 s, where the error-controlled flight takes 2.5 s (1e-9) or 1.3 s (1e-7,
1.6 m). Splines without actuators: error-controlled RK5 at ``ENTRY_ACCURACY``. OCP controls:
RK5 at ``OCP_ACCURACY`` (on the 125-node MaRV solution 256 samples per node interval leave
0.04 m of terminal miss, 64 leave 1.5 m, 16 leave 41 m: the sampling is the caller's).
"""
from __future__ import annotations

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer, LogVectorOutput, TrajectorySource, ZeroOrderHold
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.diagrams.common import add_step_loggers, collect_trajectory
from drake_entry.errors import ModelRangeError, NonFiniteStateError, ScenarioError
from drake_entry.models.dynamics import STATE_NAMES
from drake_entry.planning.ocp_system import OptimalControlPlant, native_ocp_plant
from drake_entry.planning.verification import Actuation, EntryControls, FlownControls, OcpControls
from drake_entry.scenario import PLANTS
from drake_entry.systems.actuators import AlphaActuator, BankActuator
from drake_entry.systems.lifetime import release_system
from drake_entry.systems.monitors import PlantGuard
from drake_entry.systems.native_plant import add_plant, flight_stop
from drake_entry.systems.replanning_guidance import ReplanningGuidance
from drake_entry.systems.schedule import ScheduleSource

__all__ = ["ENTRY_STEPS_PER_PERIOD", "ENTRY_ACCURACY", "OCP_ACCURACY", "LOG_POINTS", "FLIGHT_ERRORS", "fly_controls",
           "first_sentence"]

#: fixed RK5 steps per actuator period (see the module docstring for the measured error)
ENTRY_STEPS_PER_PERIOD = 2
#: error-controlled RK5 accuracy of an entry flight without actuators, and of an OCP flight
ENTRY_ACCURACY = 1e-9
OCP_ACCURACY = 1e-11
#: samples logged over a flight (the integrator's own steps are logged as well for entries)
LOG_POINTS = 2000
#: what stops a flight early: a model outside its range, a NaN, Drake's own step-size failure
FLIGHT_ERRORS = (RuntimeError, ModelRangeError, NonFiniteStateError, OverflowError, ValueError)


def fly_controls(controls: EntryControls | OcpControls, *, accuracy: float | None = None,
                 log_points: int = LOG_POINTS, plant: str = "auto", actuator_systems: bool = False) -> FlownControls:
    """Fly ``controls`` from their initial state to their final time with the Drake Simulator
    (the verifier of drake_entry.planning.verification).

    Args:
      accuracy: error-controlled RK5 at this accuracy instead of the defaults of the module
        docstring (a reference flight to hold the default to, or a looser study).
      log_points: samples logged over the flight.
      plant: the entry plant: "auto", "native" (systems/native_plant.py, with a PlantGuard) or
        "python" (systems/native_plant.add_plant); for OcpControls the problem's dynamics:
        "auto" (native when every model has a symbolic form), "native" or "python" (_ocp_plant).
      actuator_systems: fly a command known in advance through the sampled actuator systems
        (a Python call per integrator stage) instead of their precomputed response (the same
        law and segments; the reference the tests hold the default to).
    """
    if isinstance(controls, EntryControls):
        return _fly_entry(controls, accuracy, log_points, plant, actuator_systems)
    if isinstance(controls, OcpControls):
        return _fly_ocp(controls, accuracy or OCP_ACCURACY, log_points, plant)
    raise ScenarioError(f"fly_controls flies EntryControls or OcpControls, got {type(controls).__name__}")


def _spline(time, values) -> PiecewisePolynomial:
    """The C2 cubic spline through the samples; through two samples, the straight line (Drake's
    spline needs three; a C2 interpolant of two points is the line)."""
    t, v = np.asarray(time, float), np.atleast_2d(np.asarray(values, float))
    if t.size < 3:
        return PiecewisePolynomial.FirstOrderHold(t, v)
    return PiecewisePolynomial.CubicWithContinuousSecondDerivatives(t, v, periodic_end_condition=False)


def _fly_entry(c: EntryControls, accuracy: float | None, log_points: int, plant_kind: str,
               actuator_systems: bool) -> FlownControls:
    act: Actuation | None = c.actuation
    lead = act.lead_s if act is not None else 0.0
    t = np.asarray(c.time, float) - lead
    builder = DiagramBuilder()
    plant, _, used = add_plant(builder, c.vehicle, c.planet, c.atmosphere, initial_state=np.asarray(c.initial_state, float),
                         plant=plant_kind)
    if used == "native":  # the native plant cannot raise: the guard stops the flight as it would
        guard = builder.AddNamedSystem("plant_guard", PlantGuard(
            h_min=c.atmosphere.h_min, h_max=c.atmosphere.h_max, model=c.atmosphere.name, planet=c.planet))
        builder.Connect(plant.GetOutputPort("state"), guard.get_input_port())
    tf = float(c.final_time)
    bank_plan = _spline(t, np.reshape(c.bank, (1, -1)))
    alpha_plan = None if c.alpha is None else _spline(t, np.reshape(c.alpha, (1, -1)))
    if act is None:
        bank_act = alpha_act = None
    else:
        lo, hi = act.alpha_bounds
        bank_act = BankActuator(bank_limit=act.bank_limit, rate_limit=act.bank_rate_limit,
                                accel_limit=act.bank_accel_limit, initial_bank=act.initial_bank, period=act.period_s)
        alpha_act = AlphaActuator(alpha_min=lo, alpha_max=hi, rate_limit=act.alpha_rate_limit,
                                  accel_limit=act.alpha_accel_limit, initial_alpha=act.initial_alpha,
                                  period=act.period_s)
    if c.tracking is not None:  # the plan and its feedback as the closed loop flies them
        bank_out, alpha_out = _tracked(builder, c, plant.GetOutputPort("state"), bank_act, alpha_act, tf)
    elif alpha_plan is None:  # the alpha(V) law, fed back from the state
        bank_out = _actuated(builder, "bank", bank_plan, bank_act, tf, actuator_systems)
        schedule = builder.AddNamedSystem("alpha_plan", ScheduleSource(c.alpha_law, c.planet))
        builder.Connect(plant.GetOutputPort("state"), schedule.GetInputPort("state"))
        alpha_out = _actuated(builder, "alpha", schedule.get_output_port(), alpha_act, tf, actuator_systems)
    else:
        bank_out = _actuated(builder, "bank", bank_plan, bank_act, tf, actuator_systems)
        alpha_out = _actuated(builder, "alpha", alpha_plan, alpha_act, tf, actuator_systems)
    builder.Connect(bank_out, plant.GetInputPort("bank"))
    builder.Connect(alpha_out, plant.GetInputPort("alpha"))
    signals = {"state": plant.GetOutputPort("state"), "conditions": plant.GetOutputPort("flight_conditions"),
               "bank": bank_out, "alpha": alpha_out}
    loggers = {name: LogVectorOutput(port, builder, tf / log_points) for name, port in signals.items()}
    sources = {name: (port.get_system().get_name(), port.get_name()) for name, port in signals.items()}
    step_loggers = add_step_loggers(builder, signals)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    if act is not None and accuracy is None:
        integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", act.period_s / ENTRY_STEPS_PER_PERIOD)
        integrator.set_fixed_step_mode(True)
    else:
        integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", 10.0)
        integrator.set_target_accuracy(accuracy or ENTRY_ACCURACY)
    simulator.get_mutable_context().SetAccuracy(accuracy or ENTRY_ACCURACY)
    try:
        failure = _advance(simulator, tf)
        tr = collect_trajectory(diagram, loggers, simulator.get_context(), sources=sources,
                                reason=failure or "t_f", wall_time=0.0, step_loggers=step_loggers,
                                final_instant=not failure)
    finally:  # the actuators too: one whose response was flown instead is in no diagram
        for system in (diagram, bank_act, alpha_act):
            if system is not None:
                release_system(system)
    return FlownControls(tr.time, tr.state, tr, failure)


def _tracked(builder, c: EntryControls, state, bank_act, alpha_act, t_end: float):
    """The bank and alpha output ports of the plan flown with its feedback: the closed loop's
    ReplanningGuidance without re-plans (the plan's commands read ``lead_s`` ahead plus the
    offsets its tracking law builds up every period from the flown state) through the actuator
    systems."""
    act, tr = c.actuation, c.tracking
    guidance = builder.AddNamedSystem("tracking", ReplanningGuidance(
        tr.plan, period=act.period_s, lead=act.lead_s, feedback=tr.feedback, offset_limits=tr.offset_limits))
    builder.Connect(state, guidance.GetInputPort("estimated_state"))
    return (_actuated(builder, "bank", guidance.GetOutputPort("bank_command"), bank_act, t_end, True),
            _actuated(builder, "alpha", guidance.GetOutputPort("alpha_command"), alpha_act, t_end, True))


def _actuated(builder, name: str, command, actuator, t_end: float, as_system: bool):
    """The output port of ``name`` ("bank" or "alpha") as the plant receives it. ``command``: a
    PiecewisePolynomial known in advance (the plan's) or an output port (a law of the state);
    ``actuator``: a sampled LimitedActuator, or None for the command itself. A command known in
    advance goes through the actuator's ``response`` (its own law and segments, before the
    flight: a TrajectorySource, no Python call per integrator stage) unless ``as_system``; a
    port goes through the actuator system."""
    if isinstance(command, PiecewisePolynomial):
        if actuator is not None and not as_system:
            response = actuator.response(lambda t: command.value(t)[0, 0], t_end)
            out = builder.AddNamedSystem(f"{name}_actuator", TrajectorySource(response)).get_output_port()
            # the actuator system's periodic update ends an integrator step at every sample instant;
            # a ZeroOrderHold at the same period (C++, its output unused) keeps those step ends, so
            # both realisations take the same steps
            instants = builder.AddNamedSystem(f"{name}_actuator_samples", ZeroOrderHold(actuator.period, 1))
            builder.Connect(out, instants.get_input_port())
            return out
        command = builder.AddNamedSystem(f"{name}_plan", TrajectorySource(command)).get_output_port()
    if actuator is None:
        return command
    builder.AddNamedSystem(f"{name}_actuator", actuator)
    builder.Connect(command, actuator.get_input_port())
    return actuator.GetOutputPort(name)


def _ocp_plant(problem, plant: str):
    """The problem's dynamics as a system (module docstring): ``plant`` "python" the Python
    OptimalControlPlant, "native" the SymbolicVectorSystem (ScenarioError when a model has no
    symbolic form), "auto" native where it can be built."""
    if plant not in PLANTS:
        raise ScenarioError(f"plant = '{plant}'; allowed: {', '.join(PLANTS)}")
    native = native_ocp_plant(problem) if plant != "python" else None
    if native is None and plant == "native":
        raise ScenarioError("plant = 'native' needs the problem's models in a symbolic form (an aerodynamic table or "
                            "a user function written with math has none): use 'auto' or 'python'")
    return OptimalControlPlant(problem) if native is None else native


def _guard_entry_states(builder, problem, plant) -> None:
    """A PlantGuard on a native plant's vehicle states when the problem flies an atmosphere
    (the range and finiteness checks the Python plant makes inside its derivatives)."""
    atmosphere = getattr(problem, "atmosphere", None)
    if isinstance(plant, OptimalControlPlant) or atmosphere is None \
            or tuple(problem.state_names[:6]) != STATE_NAMES:
        return
    guard = builder.AddNamedSystem("plant_guard", PlantGuard(h_min=atmosphere.h_min, h_max=atmosphere.h_max,
                                                             model=atmosphere.name, planet=problem.planet))
    state = plant.get_output_port()
    if problem.n_states > 6:
        split = builder.AddSystem(Demultiplexer([6, problem.n_states - 6]))
        builder.Connect(state, split.get_input_port())
        state = split.get_output_port(0)
    builder.Connect(state, guard.get_input_port())


def _fly_ocp(c: OcpControls, accuracy: float, log_points: int, plant_kind: str = "auto") -> FlownControls:
    tf = float(c.final_time)
    u = np.asarray(c.controls, float).T
    traj = (_spline(c.time, u) if c.interpolation == "cubic"
            else PiecewisePolynomial.FirstOrderHold(np.asarray(c.time, float), u))
    builder = DiagramBuilder()
    source = builder.AddSystem(TrajectorySource(traj))
    plant = builder.AddNamedSystem("plant", _ocp_plant(c.problem, plant_kind))
    builder.Connect(source.get_output_port(), plant.get_input_port())
    _guard_entry_states(builder, c.problem, plant)
    logger = LogVectorOutput(plant.get_output_port(), builder, tf / log_points)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    ctx = simulator.get_mutable_context()
    plant.GetMyMutableContextFromRoot(ctx).SetContinuousState(np.asarray(c.initial_state, float))
    integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", tf / 200)
    integrator.set_target_accuracy(accuracy)
    try:
        failure = _advance(simulator, tf)
        log = logger.FindLog(ctx)
        t_end = ctx.get_time()
        x_end = plant.GetMyContextFromRoot(ctx).get_continuous_state_vector().CopyToVector()
        keep = log.sample_times() < t_end - 1e-9
        times, states = np.append(log.sample_times()[keep], t_end), np.vstack([log.data()[:, keep].T, x_end])
    finally:
        release_system(diagram)
    return FlownControls(times, states, None, failure)


def _advance(simulator: Simulator, tf: float) -> str:
    """Advance to ``tf``: '' when reached, else the reason the flight stopped, with its time."""
    simulator.Initialize()
    try:
        simulator.AdvanceTo(tf)
    except FLIGHT_ERRORS as raised:  # gamma reaching -90 deg, h below the atmosphere model, a NaN
        e = flight_stop(raised)
        if e is None:  # a ValueError that is neither the native plant's NaN nor a ModelRangeError: a bug
            raise
        t = simulator.get_context().get_time()
        return f"the flight stopped at t = {t:.2f} s of {tf:.2f} s: {first_sentence(str(e))}"
    return ""


def first_sentence(text: str) -> str:
    """The first sentence of a (Drake or model) error message, whole: never cut mid-word."""
    line = text.strip().splitlines()[0] if text.strip() else ""
    end = line.find(". ")
    return line if end < 0 else line[:end + 1]

