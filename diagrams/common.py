"""Pieces every diagram runner shares: integrator set-up, collecting the loggers into a
``drake_entry.models.trajectory.Trajectory``, and a run loop that stops on the termination
monitor and appends the exact final instant."""
from __future__ import annotations

import time as _time

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.primitives import LogVectorOutput

from drake_entry.errors import ModelRangeError, NonFiniteStateError
from drake_entry.models.trajectory import Trajectory
from drake_entry.scenario import Scenario
from drake_entry.systems.native_plant import flight_stop

__all__ = ["configure_integrator", "collect_trajectory", "STEP_SIGNALS", "add_step_loggers", "make_simulator",
           "stop_reason", "run"]


def configure_integrator(simulator: Simulator, scenario: Scenario, *, closed_loop: bool = False):
    """Integrator, accuracy and maximum step from the scenario (RK5 by default; docs/architecture.md, "Integration");
    a closed loop takes fixed steps of ``simulation.closed_loop_step_s`` when that is > 0."""
    sim = scenario.simulation
    step = sim.closed_loop_step_s if closed_loop and sim.closed_loop_step_s > 0 else 0.0
    integrator = ResetIntegratorFromFlags(simulator, sim.integrator, step or sim.max_step_s)
    if step:
        integrator.set_fixed_step_mode(True)
    else:
        integrator.set_target_accuracy(sim.accuracy)
        integrator.set_maximum_step_size(sim.max_step_s)
    # witness functions need the context accuracy set explicitly (docs/architecture.md, "Integration")
    simulator.get_mutable_context().SetAccuracy(sim.accuracy)
    return integrator


def collect_trajectory(diagram, loggers: dict, context, *, sources: dict, reason: str, wall_time: float,
                       columns: dict | None = None, final_instant: bool = True,
                       step_loggers: dict | None = None) -> Trajectory:
    """Trajectory from the loggers, with every logged signal's value at the final instant
    appended (the witness-located stop).

    Args:
      loggers: name -> VectorLogSink; must include 'state', 'conditions', 'bank', 'alpha'.
      sources: name -> (system name, output port name or index) giving each logged signal.
      columns: name -> table column names of the extra signals (Trajectory.extra_columns).
      final_instant: append the signals at the context's time (False after a run stopped
        inside a step, whose state is not a solution).
      step_loggers: name -> per-step VectorLogSink of 'state', 'conditions', 'bank', 'alpha'
        (``add_step_loggers``): they become ``Trajectory.steps``.
    """
    t_end = context.get_time()
    data = {}
    times = loggers["state"].FindLog(context).sample_times()
    keep = times < t_end - 1e-9
    for name, logger in loggers.items():
        logged = logger.FindLog(context).data()[:, keep]
        if final_instant:
            system_name, port = sources[name]
            system = diagram.GetSubsystemByName(system_name)
            port = system.GetOutputPort(port) if isinstance(port, str) else system.get_output_port(port)
            logged = np.column_stack([logged, port.Eval(system.GetMyContextFromRoot(context))])
        data[name] = logged.T
    extra = {k: v for k, v in data.items() if k not in ("state", "conditions", "bank", "alpha")}
    time = np.append(times[keep], t_end) if final_instant else times[keep]
    steps = None
    if step_loggers:
        logs = {name: logger.FindLog(context) for name, logger in step_loggers.items()}
        t_steps = logs["state"].sample_times()
        upto = t_steps <= t_end + 1e-9
        steps = Trajectory(time=t_steps[upto], state=logs["state"].data()[:, upto].T,
                           conditions=logs["conditions"].data()[:, upto].T, bank=logs["bank"].data()[0, upto],
                           alpha=logs["alpha"].data()[0, upto], reason=reason, wall_time=wall_time)
    return Trajectory(time=time, state=data["state"], conditions=data["conditions"],
                      bank=data["bank"][:, 0], alpha=data["alpha"][:, 0], reason=reason, wall_time=wall_time,
                      extra=extra, extra_columns={k: v for k, v in (columns or {}).items() if k in extra},
                      steps=steps)


#: the signals logged at every integrator step for the verdict's path limits
STEP_SIGNALS = ("state", "conditions", "bank", "alpha")


def add_step_loggers(builder, signals: dict) -> dict:
    """Per-step VectorLogSinks (Drake logs at every simulator step when the publish period is 0)
    of ``signals[name]`` for each of STEP_SIGNALS: the flight at the integrator's own steps."""
    return {name: LogVectorOutput(signals[name], builder, 0.0) for name in STEP_SIGNALS}


def make_simulator(diagram, scenario: Scenario, *, initial_state=None, closed_loop: bool = False) -> Simulator:
    """Simulator with the scenario's integrator (``closed_loop``: see configure_integrator);
    optional entry state override."""
    simulator = Simulator(diagram)
    if initial_state is not None:
        plant = diagram.GetSubsystemByName("vehicle")
        plant.set_initial_state(plant.GetMyMutableContextFromRoot(simulator.get_mutable_context()), initial_state)
    configure_integrator(simulator, scenario, closed_loop=closed_loop)
    return simulator


def stop_reason(status) -> str:
    return status.message() if status.reason() != status.ReturnReason.kReachedBoundaryTime else "max_time"


def run(diagram, loggers: dict, scenario: Scenario, *, sources: dict, initial_state=None,
        closed_loop: bool = False, columns: dict | None = None,
        step_loggers: dict | None = None) -> tuple[Trajectory, Simulator]:
    """Simulate ``diagram`` to a terminal condition or max_time_s (see collect_trajectory)."""
    simulator = make_simulator(diagram, scenario, initial_state=initial_state, closed_loop=closed_loop)
    simulator.Initialize()
    t0 = _time.perf_counter()
    try:
        reason = stop_reason(simulator.AdvanceTo(scenario.simulation.max_time_s))
        final = True
    except (NonFiniteStateError, ModelRangeError, OverflowError, ValueError) as raised:  # a NaN, an overflow,
        # or a state the models do not cover: stop with the reason, keep the log
        e = flight_stop(raised)
        if e is None:  # a ValueError that is neither the native plant's NaN nor a ModelRangeError: a bug
            raise
        reason = f"stopped at t = {simulator.get_context().get_time():.3f} s: {e}"
        final = False
    wall = _time.perf_counter() - t0
    tr = collect_trajectory(diagram, loggers, simulator.get_context(), sources=sources, reason=reason,
                            wall_time=wall, columns=columns, final_instant=final, step_loggers=step_loggers)
    return tr, simulator
