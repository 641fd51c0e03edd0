"""Closed-loop drag-energy entry (paper 000 Secs. IV.A and VI.D) as a Drake diagram.

  EntryVehicle --state--> Navigation --estimate--> DragEnergyGuidance --reference-->
  DragTrackingController --|sigma|--> BankReversalLogic --sigma_cmd--> BankActuator --> EntryVehicle
  AtmosphereSystem(state) --air_data--> EntryVehicle, TerminationMonitor
  alpha(E) ScheduleSource(estimate) --alpha--> EntryVehicle

The run stops exactly at the guidance terminal energy E_f (witness function), or on an
altitude floor (a crash guard) or max_time_s. ``fly`` returns the trajectory, the
reference, and the terminal errors in the form of paper 000 Table 3.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from drake_entry.diagrams.common import Trajectory, run
from drake_entry.aerodynamics import ScaledAero
from drake_entry.atmosphere import DispersedAtmosphere
from drake_entry.dispersions import Draw
from drake_entry.planning.drag_energy import DragEnergyPlanner, DragEnergyReference, bearing
from drake_entry.scenario import Scenario
from drake_entry.systems.actuators import BankActuator
from drake_entry.systems.atmosphere import AtmosphereSystem
from drake_entry.systems.bank_reversal import BankReversalLogic
from drake_entry.systems.drag_tracking import DragTrackingController
from drake_entry.systems.guidance import DragEnergyGuidance
from drake_entry.systems.monitors import TerminationMonitor
from drake_entry.systems.navigation import Navigation
from drake_entry.systems.schedule import ScheduleSource
from drake_entry.systems.vehicle import EntryVehicle

ALTITUDE_FLOOR_M = 5000.0


@dc.dataclass
class ClosedLoopResult:
    """One closed-loop flight.

    Attributes:
      trajectory: the flown Trajectory (extra['reference'] = [D_ref, D'_ref, D''_ref, engaged]).
      reference: the last successful plan (None if guidance never engaged).
      errors: terminal errors (Table 3 form): altitude_m, longitude_deg, latitude_deg,
        velocity_m_s, range_to_go_m (along the heading, + short of the target),
        crossrange_m (+ target to the right), distance_m.
      engaged_at: guidance engagement time [s]; plans: successful plans; reversals: count.
      first_reference, engaged_state: the plan made at engagement and the estimate it used.
      planning_failures: list of (time, message). planning_wall_s: wall time spent planning [s].
      success: reached the terminal energy with guidance engaged.
      message: human summary.
    """

    trajectory: Trajectory
    reference: DragEnergyReference | None
    errors: dict
    engaged_at: float | None
    plans: int
    reversals: int
    planning_failures: list
    success: bool
    message: str
    first_reference: DragEnergyReference | None = None
    engaged_state: np.ndarray | None = None
    planning_wall_s: float = 0.0


def build_closed_loop(scenario: Scenario, planner: DragEnergyPlanner | None = None, *, nav_seed: int = 0,
                      nav_bias=None, nav_noise=None, initial_state=None, draw: Draw | None = None):
    """Diagram, loggers and the planner (built from the scenario unless given).

    ``initial_state`` becomes the vehicle's default state (what SetRandomContext keeps).
    ``draw`` (a Monte-Carlo sample) disperses the plant: entry state, density, aerodynamic
    scale factors, mass and navigation errors; the guidance keeps the nominal models.
    """
    planner = planner or DragEnergyPlanner.from_scenario(scenario)
    g = scenario.guidance
    vehicle, planet, atmosphere = planner.vehicle, scenario.make_planet(), planner.atmosphere
    if draw is not None:
        vehicle = dc.replace(vehicle, mass=vehicle.mass * draw.mass_scale,
                             aero=ScaledAero(vehicle.aero, draw.lift_scale, draw.drag_scale))
        atmosphere = DispersedAtmosphere(atmosphere, scale=draw.density_scale, amplitude=draw.density_wave_amplitude,
                                         wavelength=draw.density_wave_length, phase=draw.density_wave_phase)
        initial_state = scenario.initial_state() + draw.entry_delta
        nav_bias, nav_noise, nav_seed = draw.nav_bias, draw.nav_noise_sigma, draw.nav_seed
    builder = DiagramBuilder()
    x0 = scenario.initial_state() if initial_state is None else np.asarray(initial_state, float)
    plant = builder.AddNamedSystem("vehicle", EntryVehicle(vehicle, planet, atmosphere, initial_state=x0,
                                                           air_data_input=True))
    air = builder.AddNamedSystem("atmosphere", AtmosphereSystem(atmosphere, planet))
    nav = builder.AddNamedSystem("navigation", Navigation(bias=nav_bias, noise_sigma=nav_noise,
                                                          period=g.period_s, seed=nav_seed))
    guidance = builder.AddNamedSystem("guidance", DragEnergyGuidance(
        planner, period=g.period_s, pre_guidance_min_s=g.pre_guidance_min_s, replan_period_s=g.replan_period_s,
        replan_until_e=g.replan_until_e))
    pre_bank = math.radians(g.pre_guidance_bank_deg)
    controller = builder.AddNamedSystem("drag_tracking", DragTrackingController(
        planner, zeta=g.zeta, omega=g.omega_per_J, integral_ratio=g.integral_ratio, period=g.period_s,
        pre_guidance_bank=abs(pre_bank), bandwidth=g.bandwidth_rad_s))
    reversal = builder.AddNamedSystem("bank_reversal", BankReversalLogic(
        target_lon=planner.target[0], target_lat=planner.target[1], corridor_deg=tuple(g.reversal_heading_deg),
        corridor_velocity=tuple(g.reversal_velocity_m_s), period=g.period_s,
        initial_sign=1.0 if pre_bank >= 0 else -1.0))
    actuator = builder.AddNamedSystem("bank_actuator", BankActuator(
        bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit, accel_limit=vehicle.bank_accel_limit,
        initial_bank=pre_bank, period=g.period_s))
    alpha = builder.AddNamedSystem("alpha_schedule", ScheduleSource(
        planner.alpha, planner.planet, period=g.period_s, initial_value=planner.alpha(scenario.entry_energy())))
    monitor = builder.AddNamedSystem("termination", TerminationMonitor(
        energy=planner.E_final, altitude=ALTITUDE_FLOOR_M, planet=planner.planet))

    state = plant.GetOutputPort("state")
    estimate = nav.GetOutputPort("estimated_state")
    builder.Connect(state, air.get_input_port())
    builder.Connect(air.GetOutputPort("air_data"), plant.GetInputPort("air_data"))
    builder.Connect(state, nav.GetInputPort("true_state"))
    builder.Connect(estimate, guidance.GetInputPort("estimated_state"))
    builder.Connect(estimate, controller.GetInputPort("estimated_state"))
    builder.Connect(guidance.GetOutputPort("reference"), controller.GetInputPort("reference"))
    # the accelerometer's drag: guidance and feedback act on the drag actually felt
    builder.Connect(plant.GetOutputPort("flight_conditions"), guidance.GetInputPort("flight_conditions"))
    builder.Connect(plant.GetOutputPort("flight_conditions"), controller.GetInputPort("flight_conditions"))
    builder.Connect(estimate, reversal.GetInputPort("estimated_state"))
    builder.Connect(controller.GetOutputPort("bank_magnitude"), reversal.GetInputPort("bank_magnitude"))
    builder.Connect(reversal.GetOutputPort("bank_command"), actuator.get_input_port())
    builder.Connect(actuator.GetOutputPort("bank"), plant.GetInputPort("bank"))
    builder.Connect(estimate, alpha.GetInputPort("state"))
    builder.Connect(alpha.get_output_port(), plant.GetInputPort("alpha"))
    builder.Connect(state, monitor.GetInputPort("state"))
    builder.Connect(air.GetOutputPort("air_data"), monitor.GetInputPort("air_data"))
    period = scenario.simulation.log_period_s
    loggers = {
        "state": LogVectorOutput(state, builder, period),
        "conditions": LogVectorOutput(plant.GetOutputPort("flight_conditions"), builder, period),
        "bank": LogVectorOutput(actuator.GetOutputPort("bank"), builder, period),
        "alpha": LogVectorOutput(alpha.get_output_port(), builder, period),
        "reference": LogVectorOutput(guidance.GetOutputPort("reference"), builder, period),
        "bank_command": LogVectorOutput(reversal.GetOutputPort("bank_command"), builder, period),
    }
    diagram = builder.Build()
    diagram.set_name(f"closed_loop_{scenario.name}")
    return diagram, loggers, planner


SOURCES = {"state": ("vehicle", "state"), "conditions": ("vehicle", "flight_conditions"),
           "bank": ("bank_actuator", "bank"), "alpha": ("alpha_schedule", "command"),
           "reference": ("guidance", "reference"), "bank_command": ("bank_reversal", "bank_command")}


def terminal_errors(x, scenario: Scenario, planner: DragEnergyPlanner) -> dict:
    """Final errors against the guidance terminal interface and the target (Table 3 form)."""
    h_f, V_f, _ = scenario.guidance_terminal_state()
    tlon, tlat = planner.target
    dist = float(planner.planet.great_circle_distance(x[1], x[2], tlon, tlat))
    # range to go along the velocity heading (+ short of the target), and cross-range
    rel = bearing(x[1], x[2], tlon, tlat) - x[5]
    return {"altitude_m": float(x[0] - h_f), "longitude_deg": math.degrees(x[1] - tlon),
            "latitude_deg": math.degrees(x[2] - tlat), "velocity_m_s": float(x[3] - V_f),
            "range_to_go_m": dist * math.cos(rel), "crossrange_m": dist * math.sin(rel), "distance_m": dist}


def fly(scenario: Scenario, planner: DragEnergyPlanner | None = None, *, initial_state=None,
        nav_seed: int = 0, nav_bias=None, nav_noise=None, draw: Draw | None = None) -> ClosedLoopResult:
    """Fly the closed loop once (the nominal entry state unless ``initial_state`` or a
    Monte-Carlo ``draw`` is given)."""
    diagram, loggers, planner = build_closed_loop(scenario, planner, nav_seed=nav_seed, nav_bias=nav_bias,
                                                  nav_noise=nav_noise, initial_state=initial_state, draw=draw)
    tr, simulator = run(diagram, loggers, scenario, sources=SOURCES, closed_loop=True)
    return summarise(diagram, simulator.get_context(), tr, scenario, planner)


def summarise(diagram, ctx, tr: Trajectory, scenario: Scenario, planner: DragEnergyPlanner) -> ClosedLoopResult:
    """ClosedLoopResult of a finished closed-loop simulation."""
    guidance = diagram.GetSubsystemByName("guidance")
    mem = guidance.memory(guidance.GetMyContextFromRoot(ctx))
    reversal = diagram.GetSubsystemByName("bank_reversal")
    n_rev = int(reversal.GetOutputPort("reversals").Eval(reversal.GetMyContextFromRoot(ctx))[0])
    x = tr.state[-1]
    errors = terminal_errors(x, scenario, planner)
    reached = "energy" in tr.reason
    ok = reached and mem.engaged_at is not None
    if ok:
        msg = f"reached E_f at t = {tr.time[-1]:.1f} s, {errors['distance_m'] / 1e3:.3f} km from the target"
    elif mem.engaged_at is None:
        last = mem.failures[-1][1] if mem.failures else "engagement condition never met"
        msg = f"guidance never engaged: {last}"
    else:
        msg = f"stopped before E_f: {tr.reason}"
    return ClosedLoopResult(tr, mem.reference, errors, mem.engaged_at, mem.plans, n_rev, mem.failures, ok, msg,
                            mem.first_reference, mem.engaged_state, mem.planning_wall_s)



def propagate_extracted_bank(scenario: Scenario, reference: DragEnergyReference, x0) -> Trajectory:
    """Open-loop flight from x0 with the extracted bank magnitude sigma(E) and alpha(E)
    (paper 000 Fig. 5: extracted states against open-loop propagation)."""
    from drake_entry.diagrams.open_loop import simulate

    sc = dc.replace(scenario)
    x = reference.extraction
    E = reference.energy[::-1]  # increasing
    sc.bank = dc.replace(scenario.bank, variable="energy", breakpoints=list(E),
                         values_deg=list(np.degrees(x.sigma[::-1])), smooth=False)
    sc.alpha = dc.replace(scenario.alpha, variable="energy", breakpoints=list(reference.problem.alpha.breakpoints),
                          values_deg=list(np.degrees(reference.problem.alpha.values)),
                          smooth=reference.problem.alpha.smooth)
    sc.terminal = dc.replace(scenario.terminal, altitude_km=None, mach=None, velocity_m_s=None,
                             energy_MJ_kg=reference.problem.Ef / 1e6)
    sc.simulation = dc.replace(scenario.simulation, integrator="runge_kutta5", accuracy=1e-8)
    return simulate(sc, initial_state=x0)
