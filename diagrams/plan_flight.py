"""Fly an SCvx plan's real bank with the Drake Simulator (paper 001 Table 3: the propagated
miss) and compare the flown DRS point with the plan and the site.

    TrajectorySource(sigma(t)) --bank--> EntryVehicle --state--> VectorLogSink
    ScheduleSource(alpha(V)) <--state-- EntryVehicle;  alpha --> EntryVehicle
    (or TrajectorySource(alpha(t)) --alpha--> EntryVehicle where the plan planned alpha)

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

from drake_entry.atmosphere import Atmosphere
from drake_entry.dynamics import flight_conditions
from drake_entry.planet import Earth
from drake_entry.planning.scvx.planner import PROPAGATION_TOLERANCE_M, ScvxPlan, terminal_distance
from drake_entry.systems.schedule import ScheduleSource
from drake_entry.systems.vehicle import EntryVehicle
from drake_entry.vehicles import Vehicle

#: acceptance of a flown plan (issue 13): DRS point within this of the plan and of the site [m]
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
      peaks: flown max heat flux [W/m^2] and total load [g].
      ok: from_plan_m <= PLAN_TOLERANCE_M and the DRS box met.
    """

    time: np.ndarray
    states: np.ndarray
    from_plan_m: float
    from_site_m: float
    drs: dict
    drs_ok: bool
    peaks: dict
    ok: bool


def fly_plan(plan: ScvxPlan, vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, *,
             accuracy: float = 1e-9, samples_per_segment: int = 32, log_points: int = 2000) -> PlanFlight:
    """Fly ``plan``'s bank from its entry state to its t_f with the Drake Simulator (RK5)."""
    problem, tf = plan.problem, plan.final_time
    mission = problem.mission
    tt, bank, planned_alpha = plan.control_samples(samples_per_segment)

    def spline(values):
        return TrajectorySource(PiecewisePolynomial.CubicWithContinuousSecondDerivatives(
            tt, np.reshape(values, (1, -1)), periodic_end_condition=False))

    scheduled_alpha = planned_alpha is None
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("vehicle", EntryVehicle(vehicle, planet, atmosphere,
                                                           initial_state=plan.states[0, :6]))
    source = builder.AddNamedSystem("bank", spline(bank))
    builder.Connect(source.get_output_port(), plant.GetInputPort("bank"))
    if scheduled_alpha:
        alpha = builder.AddNamedSystem("alpha", ScheduleSource(problem.alpha, planet))
        builder.Connect(plant.GetOutputPort("state"), alpha.GetInputPort("state"))
    else:
        alpha = builder.AddNamedSystem("alpha", spline(planned_alpha))
    builder.Connect(alpha.get_output_port(), plant.GetInputPort("alpha"))
    logger = LogVectorOutput(plant.GetOutputPort("state"), builder, tf / log_points)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    integrator = ResetIntegratorFromFlags(simulator, "runge_kutta5", 10.0)
    integrator.set_target_accuracy(accuracy)
    simulator.get_mutable_context().SetAccuracy(accuracy)
    simulator.Initialize()
    simulator.AdvanceTo(tf)
    log = logger.FindLog(simulator.get_context())
    T, X = log.sample_times(), log.data().T
    xf = diagram.GetSubsystemByName("vehicle").GetOutputPort("state").Eval(
        diagram.GetSubsystemContext(diagram.GetSubsystemByName("vehicle"), simulator.get_context()))
    site = mission.site(planet)
    from_site = planet.great_circle_distance(xf[1], xf[2], *site)
    alphas = ([float(problem.alpha(float(x[3]))) for x in X] if scheduled_alpha
              else list(np.interp(T, tt, planned_alpha)))
    a_f = float(problem.alpha(float(xf[3]))) if scheduled_alpha else float(planned_alpha[-1])
    cf = flight_conditions(xf, 0.0, a_f, vehicle, planet, atmosphere)
    h_geo = float(planet.atmospheric_altitude(xf[0], xf[2]))
    drs = {"altitude_m": h_geo, "mach": float(cf.mach), "vertical_speed_m_s": float(xf[3] * math.sin(xf[4]))}
    drs_ok = (mission.final_altitude_m[0] <= h_geo <= mission.final_altitude_m[1]
              and cf.mach <= mission.final_mach_max and drs["vertical_speed_m_s"] >= mission.final_vertical_speed_min_m_s
              and from_site <= SITE_TOLERANCE_M)
    conds = [flight_conditions(x, 0.0, a, vehicle, planet, atmosphere) for x, a in zip(X, alphas)]
    peaks = {"heat_flux_W_m2": float(max(c.heat_flux for c in conds)),
             "total_load_g": float(max(c.total_load for c in conds))}
    from_plan = terminal_distance(planet, xf, plan.states[-1])
    return PlanFlight(T, X, from_plan, float(from_site), drs, bool(drs_ok), peaks,
                      bool(from_plan <= PLAN_TOLERANCE_M and drs_ok))
