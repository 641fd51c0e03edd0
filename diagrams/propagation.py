"""Propagate an NLP solution's controls with the Drake Simulator (paper 002 'Results':
the optimal controls flown open loop, compared with the NLP states at t_f).

  TrajectorySource(u(t)) --u--> OptimalControlPlant (SI) --> VectorLogSink

u(t) is the transcription's own control representation (the LGL Lagrange interpolant,
sampled densely into a C2 cubic spline; first-order hold for DirectCollocation). The
sampling matters: on the 125-node MARV solution 16 samples per node interval leave 41 m of
terminal miss, 64 leave 1.5 m, 256 (the default) 0.04 m.
"""
from __future__ import annotations

import dataclasses as dc

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.errors import ModelRangeError, NonFiniteStateError
from drake_entry.models.geodesy import downtrack_crosstrack
from drake_entry.planning.ocp import OptimalControlProblem
from drake_entry.systems.ocp_plant import OptimalControlPlant


@dc.dataclass
class PropagationCheck:
    """Open-loop flight of the NLP controls.

    Attributes:
      time [s], states (n, n_states) SI: the propagated trajectory.
      terminal_error: propagated minus NLP at t_f: downtrack_m, crosstrack_m, position_m
        (their root sum square, paper 002's 18.16 m), altitude_m, velocity_m_s,
        flight_path_deg (entry problems), or state_max for other problems; {'failed': reason}
        when the integration could not reach t_f.
    """

    time: np.ndarray
    states: np.ndarray
    terminal_error: dict


def propagate(problem, result, *, accuracy: float = 1e-11, samples_per_interval: int = 256,
              log_points: int = 2000) -> PropagationCheck:
    """Fly ``result.controls`` from ``result.states[0]`` over [0, t_f] (RK5, ``accuracy``)."""
    t_nodes, tf = result.time, result.final_time
    if result.transcription == "lgl":
        tt = np.unique(np.concatenate([np.linspace(0.0, tf, samples_per_interval * len(t_nodes)), t_nodes]))
        u = result.control_function()(tt)
        traj = PiecewisePolynomial.CubicWithContinuousSecondDerivatives(tt, u.T, periodic_end_condition=False)
    else:
        traj = PiecewisePolynomial.FirstOrderHold(t_nodes, result.controls.T)
    builder = DiagramBuilder()
    source = builder.AddSystem(TrajectorySource(traj))
    plant = builder.AddNamedSystem("plant", OptimalControlPlant(problem))
    builder.Connect(source.get_output_port(), plant.get_input_port())
    logger = LogVectorOutput(plant.get_output_port(), builder, tf / log_points)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    ctx = simulator.get_mutable_context()
    plant.GetMyMutableContextFromRoot(ctx).SetContinuousState(result.states[0])
    integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", tf / 200)
    integrator.set_target_accuracy(accuracy)
    simulator.Initialize()
    failure = None
    try:
        simulator.AdvanceTo(tf)
    except (RuntimeError, ModelRangeError, NonFiniteStateError) as e:  # e.g. gamma reaching -90 deg, h below the
        # atmosphere model
        failure = f"propagation stopped at t = {ctx.get_time():.2f} s of {tf:.2f} s: {first_sentence(str(e))}"
    log = logger.FindLog(ctx)
    t_end = ctx.get_time()
    x_end = plant.GetMyContextFromRoot(ctx).get_continuous_state_vector().CopyToVector()
    keep = log.sample_times() < t_end - 1e-9
    t = np.append(log.sample_times()[keep], t_end)
    X = np.vstack([log.data()[:, keep].T, x_end])
    err = {"failed": failure} if failure else terminal_error(problem, result, x_end)
    return PropagationCheck(time=t, states=X, terminal_error=err)


def first_sentence(text: str) -> str:
    """The first sentence of a (Drake or model) error message, whole: never cut mid-word."""
    line = text.strip().splitlines()[0] if text.strip() else ""
    end = line.find(". ")
    return line if end < 0 else line[:end + 1]


def terminal_error(problem, result, x_end) -> dict:
    """Propagated minus NLP final state (paper 002 appendix eqs. 24-30 for the position)."""
    xf = result.states[-1]
    if not isinstance(problem, OptimalControlProblem):
        return {"state_max": float(np.max(np.abs(x_end - xf)))}
    x0 = result.states[0]
    R = problem.planet.reference_radius
    d, c = downtrack_crosstrack(np.array([x_end[1], xf[1]]), np.array([x_end[2], xf[2]]), x0[1], x0[2],
                                xf[1], xf[2], R)
    dd, dcr = float(d[0] - d[1]), float(c[0] - c[1])
    return {"downtrack_m": dd, "crosstrack_m": dcr, "position_m": float(np.hypot(dd, dcr)),
            "altitude_m": float(x_end[0] - xf[0]), "velocity_m_s": float(x_end[3] - xf[3]),
            "flight_path_deg": float(np.degrees(x_end[4] - xf[4]))}
