"""Fly an SCvx plan's real bank and alpha with the Drake Simulator through the closed loop's
actuators (paper 001 Table 3: the propagated miss) and compare the flown DRS point with the
plan and the site; the path limits are checked at every log sample and integrator step.

    TrajectorySource(sigma(t + lead)) --> BankActuator (sampled every period) --bank--> EntryVehicle
    TrajectorySource(alpha(t + lead)) or ScheduleSource(alpha(V)) --> AlphaActuator --alpha--> EntryVehicle

The bank (atan2(u2, u1) of the lossless plan, the bank state of the direct ones) is the plan's
segment polynomial sampled densely into a C2 spline; |u| < 1 in a relaxed plan means the flown
lift is larger than planned there (the lossless gap shows up here as a position error).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drake_entry.diagrams.common import add_step_loggers, collect_trajectory
from drake_entry.guidance.scvx.planner import (
    PROPAGATION_TOLERANCE_M,
    FlightCheck,
    ScvxPlan,
    drs_point,
    plan_path_limits,
    terminal_distance,
)
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle
from drake_entry.models.verdict import breaches_text, check_limits
from drake_entry.systems.actuators import AlphaActuator, BankActuator
from drake_entry.systems.schedule import ScheduleSource
from drake_entry.systems.vehicle import EntryVehicle

#: acceptance of a flown plan: DRS point within this of the plan and of the site [m]
PLAN_TOLERANCE_M = PROPAGATION_TOLERANCE_M
SITE_TOLERANCE_M = 15e3


@dc.dataclass
class PlanFlight:
    """The plan flown open loop.

    Attributes:
      time [s], states (n, 6): the flown trajectory, logged.
      from_plan_m: flown minus planned position at t_f [m] (great circle and altitude, root sum square).
      from_site_m: flown DRS point to the site [m].
      drs: flown geodetic altitude [m], Mach and vertical speed [m/s] at t_f; drs_ok: all in the DRS box
        (altitude window, Mach, vertical speed; miss within SITE_TOLERANCE_M).
      peaks: flown max heat flux [W/m^2] and total load [g] (log samples and integrator steps).
      ok: from_plan_m <= PLAN_TOLERANCE_M, the DRS box met and every path limit held.
      checks: the path limits (vehicle q, n, bank; the mission's gamma bounds) on the flight.
      trajectory: the flown Trajectory (with its integrator steps).
    """

    time: np.ndarray
    states: np.ndarray
    from_plan_m: float
    from_site_m: float
    drs: dict
    drs_ok: bool
    peaks: dict
    ok: bool
    checks: list = dc.field(default_factory=list)
    trajectory: object = None

    def violations_text(self) -> str:
        return breaches_text(self.checks)


def fly_plan(plan: ScvxPlan, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, *,
             accuracy: float = 1e-9, samples_per_segment: int = 32, log_points: int = 2000,
             flight: FlightCheck | None = None) -> PlanFlight:
    """Fly ``plan``'s bank and alpha from its entry state to its t_f with the Drake Simulator
    (RK5 at ``accuracy``) as the closed loop flies them (``flight``, default the plan's own
    FlightCheck): the commands, read ``lead_s`` ahead on the plan, sampled every ``period_s``
    (the guidance period) into the shared BankActuator (the vehicle's bank limits) and
    AlphaActuator (the mission's alpha bounds and rate limit); ``period_s=None`` feeds the
    plan's bank and alpha to the vehicle directly (no actuator)."""
    problem, tf = plan.problem, plan.final_time
    mission = problem.mission
    flight = flight or plan.flight or FlightCheck()
    period_s = flight.period_s
    lead_s = flight.lead_s if period_s is not None else 0.0
    tt, bank, planned_alpha = plan.control_samples(samples_per_segment)

    def spline(values):
        return TrajectorySource(PiecewisePolynomial.CubicWithContinuousSecondDerivatives(
            tt - lead_s, np.reshape(values, (1, -1)), periodic_end_condition=False))

    scheduled_alpha = planned_alpha is None
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("vehicle", EntryVehicle(vehicle, planet, atmosphere,
                                                           initial_state=plan.states[0, :6]))
    bank_source = builder.AddNamedSystem("bank_plan", spline(bank)).get_output_port()
    if scheduled_alpha:
        schedule = builder.AddNamedSystem("alpha_plan", ScheduleSource(problem.alpha, planet))
        builder.Connect(plant.GetOutputPort("state"), schedule.GetInputPort("state"))
        alpha_source = schedule.get_output_port()
    else:
        alpha_source = builder.AddNamedSystem("alpha_plan", spline(planned_alpha)).get_output_port()
    if period_s is None:
        bank_out, alpha_out = bank_source, alpha_source
    else:
        lo, hi = np.radians(mission.alpha_bounds_deg)
        bank_act = builder.AddNamedSystem("bank_actuator", BankActuator(
            bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit,
            initial_bank=float(plan.bank[0]), period=period_s))
        alpha_act = builder.AddNamedSystem("alpha_actuator", AlphaActuator(
            alpha_min=float(lo), alpha_max=float(hi), rate_limit=math.radians(mission.alpha_rate_limit_deg_s),
            accel_limit=math.radians(flight.alpha_acceleration_deg_s2), initial_alpha=float(plan.alpha[0]),
            period=period_s))
        builder.Connect(bank_source, bank_act.get_input_port())
        builder.Connect(alpha_source, alpha_act.get_input_port())
        bank_out, alpha_out = bank_act.GetOutputPort("bank"), alpha_act.GetOutputPort("alpha")
    builder.Connect(bank_out, plant.GetInputPort("bank"))
    builder.Connect(alpha_out, plant.GetInputPort("alpha"))
    signals = {"state": plant.GetOutputPort("state"), "conditions": plant.GetOutputPort("flight_conditions"),
               "bank": bank_out, "alpha": alpha_out}
    loggers = {name: LogVectorOutput(port, builder, tf / log_points) for name, port in signals.items()}
    sources = {name: (port.get_system().get_name(), port.get_name()) for name, port in signals.items()}
    step_loggers = add_step_loggers(builder, signals)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", 10.0)
    integrator.set_target_accuracy(accuracy)
    simulator.get_mutable_context().SetAccuracy(accuracy)
    simulator.Initialize()
    simulator.AdvanceTo(tf)
    tr = collect_trajectory(diagram, loggers, simulator.get_context(), sources=sources, reason="t_f", wall_time=0.0,
                            step_loggers=step_loggers)
    xf = tr.state[-1]
    point, drs_ok = drs_point(mission, planet, xf, float(tr.column("mach")[-1]), SITE_TOLERANCE_M)
    from_site = point.pop("site_miss_m")
    drs = point
    checks = check_limits(tr.flown_time(), tr.flown, plan_path_limits(plan))
    peaks = {"heat_flux_W_m2": float(tr.flown("heat_flux").max()), "total_load_g": float(tr.flown("total_load").max())}
    from_plan = terminal_distance(planet, xf, plan.states[-1])
    within = all(c.held for c in checks)
    return PlanFlight(tr.time, tr.state, from_plan, float(from_site), drs, bool(drs_ok), peaks,
                      bool(from_plan <= PLAN_TOLERANCE_M and drs_ok and within), checks, tr)
