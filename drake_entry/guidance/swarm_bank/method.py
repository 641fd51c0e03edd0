"""Paper 004's guidance as a GuidanceMethod.

  estimate, flight conditions --> SwarmBankGuidance --|sigma|--> BankReversalLogic --sigma_cmd-->
      (shared bank actuator);   SwarmBankGuidance --alpha_command--> (shared alpha actuator)

The planner searches sigma_0 before flight (PIO by default, guidance/swarm_bank/search.py) on the
evaluator that replicates this closed loop, and calls the optimum a success only when its
commands, flown by the plan verifier (the Drake Simulator through the closed loop's actuators),
end near the replica's TAEM point, inside the acceptance box and the path limits (eqs. 13-15).
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np

from drake_entry.guidance.interface import (
    ActuatorLimits,
    GuidanceCommands,
    GuidanceMethod,
    GuidanceSummary,
    LoggedSignal,
    PlantPorts,
)
from drake_entry.guidance.reversal_wiring import add_bank_reversal, reversal_count
from drake_entry.guidance.swarm_bank.evaluator import (
    CONTROL_COLUMNS,
    HISTORY_COLUMNS,
    Evaluation,
    SwarmProblem,
    evaluate,
)
from drake_entry.guidance.swarm_bank.search import SearchResult, problem_from_scenario, search
from drake_entry.models.verdict import box_text, breaches_text, check_limits, vehicle_path_limits
from drake_entry.planning.result import PlanResult
from drake_entry.planning.verification import Actuation, EntryControls, FlownControls, require_verifier
from drake_entry.systems.swarm_bank_guidance import SwarmBankGuidance

__all__ = ["GUIDANCE_SYSTEM", "FLOWN_TOLERANCE_M", "SwarmPlan", "plan_controls", "verify", "terminal_box", "plan",
           "SwarmBankMethod", "METHOD"]

GUIDANCE_SYSTEM = "swarm_bank_guidance"
#: the plan's commands flown by Drake must end this close to the replica's TAEM point [m]
#: (great circle and altitude; measured on paper 004's Case 1 optimum: see docs/methods/swarm-bank.md)
FLOWN_TOLERANCE_M = 2000.0

@dc.dataclass
class SwarmPlan(PlanResult):
    """sigma_0 [deg] of paper 004 eq. 17 for a mission, with the search that found it and the
    evaluation of its trajectory (``evaluation``, one member with its recorded history).

    success: the replica reaches the TAEM energy, and its commands flown by the Drake Simulator
    through the closed loop's actuators (``flown``, ``plan_controls``) end within
    FLOWN_TOLERANCE_M of the replica's TAEM point (``from_replica_m``), inside the scenario's
    acceptance box and within the path limits (heat rate, q, load, bank: the vehicle's, widened
    only by the scenario's ``terminal.path_limit_tolerance``, at every log sample and
    integrator step); otherwise ``message`` names what failed, the violated limits with their
    peaks and margins (``violations``).
    """

    variable = "time"

    problem: SwarmProblem | None = None
    sigma0_deg: float = math.nan
    sigma_f_deg: float = math.nan
    search: SearchResult | None = None
    evaluation: Evaluation | None = None
    violations: list = dc.field(default_factory=list)
    flown: FlownControls | None = dc.field(default=None, repr=False)
    from_replica_m: float = math.nan

    def evaluate(self, at) -> dict:
        """The planned trajectory's HISTORY_COLUMNS at times ``at`` [s]: the states, commands and
        flight conditions interpolated between the guidance steps, alpha and bank the actuators'
        own path at every sub-step (what the plan flew: flown open loop these controls reproduce
        the plan; the guidance-step samples interpolated linearly would not)."""
        h, u = self.evaluation.history[0], self.evaluation.controls[0]
        t = np.atleast_1d(np.asarray(at, float))
        out = {name: np.interp(t, h[:, 0], h[:, i]) for i, name in enumerate(HISTORY_COLUMNS)}
        out.update({name: np.interp(t, u[:, 0], u[:, i]) for i, name in enumerate(CONTROL_COLUMNS) if i})
        return out


def plan_controls(problem: SwarmProblem, ev: Evaluation) -> EntryControls:
    """The replica's bank and alpha commands (``ev``'s recorded member, one per guidance step)
    as the closed loop flies them: sampled every guidance step, no lead, into the shared bank
    and alpha actuators (the vehicle's bank limits, the problem's alpha bounds and limits), from
    the start state to the replica's TAEM time."""
    h = ev.history[0]
    t = h[:, 0]
    bank, alpha = h[:, HISTORY_COLUMNS.index("bank_command_rad")], h[:, HISTORY_COLUMNS.index("alpha_command_rad")]
    tf = float(ev.time_s[0])
    if tf > t[-1] + 1e-9:  # the TAEM energy is crossed inside the last step: its commands hold
        t, bank, alpha = np.append(t, tf), np.append(bank, bank[-1]), np.append(alpha, alpha[-1])
    v, p = problem.vehicle, problem
    actuation = Actuation(period_s=p.guidance_step_s, lead_s=0.0, bank_limit=v.bank_limit,
                          bank_rate_limit=v.bank_rate_limit, bank_accel_limit=v.bank_accel_limit,
                          alpha_bounds=(p.alpha_min, p.alpha_max), alpha_rate_limit=p.alpha_rate,
                          alpha_accel_limit=p.alpha_accel, initial_bank=p.initial_bank,
                          initial_alpha=p.entry_alpha)
    return EntryControls(v, p.planet, p.atmosphere, np.asarray(p.x0, float), tf, t, bank, alpha, None, actuation)


def verify(problem: SwarmProblem, flown: FlownControls, tolerance: float = 0.0) -> list:
    """The path limits (heat rate, q, load, bank: drake_entry.models.verdict, ``tolerance``
    relative) the Drake flight of the plan's commands breaches, at every log sample and
    integrator step."""
    v = problem.vehicle
    tr = flown.trajectory
    checks = check_limits(tr.flown_time(), tr.flown, vehicle_path_limits(v.limits, v.bank_limit), tolerance)
    return [c for c in checks if not c.held]


def terminal_box(scenario, problem: SwarmProblem, x) -> dict:
    """The scenario's acceptance box (Scenario.acceptance_box) at the replica's TAEM state ``x``
    [h, lon, lat, V, gamma, psi]: the Mach number there, the great-circle distance to the target."""
    pl = problem.planet
    a = float(problem.atmosphere.air_data(float(pl.atmospheric_altitude(x[0], x[2])))[1])
    return scenario.acceptance_box(pl, x, mach=float(x[3]) / a,
                                   distance_m=float(pl.great_circle_distance(x[1], x[2], *problem.target)))


def plan(scenario, verifier, problem: SwarmProblem | None = None) -> SwarmPlan:
    """Search sigma_0 (unless the spec gives it) on the replica, record the answer's flight,
    and verify it: its commands flown by ``verifier`` (the Drake Simulator through the closed
    loop's actuators, ``plan_controls``) must end inside the acceptance box, within every path
    limit and within FLOWN_TOLERANCE_M of the replica's TAEM point."""
    fly = require_verifier(verifier, "the swarm-bank planner")
    t0 = time.perf_counter()
    g = scenario.guidance
    problem = problem_from_scenario(scenario) if problem is None else problem
    found = None
    if g.bank_start_deg is None:
        bounds = [tuple(g.bank_start_bounds_deg)] + ([tuple(g.bank_end_bounds_deg)] if g.bank_end_bounds_deg else [])
        found = search(problem, g.optimizer, bounds, seed=g.seed, n=g.population,
                       k_max=g.iterations, k_c=g.landmark_iteration, R=g.map_compass_factor)
        sigma0 = float(found.x[0])
        if len(bounds) == 2:  # sigma_f searched too: the problem (and the guidance on board) flies it
            problem = dc.replace(problem, sigma_f=math.radians(float(found.x[1])))
    else:
        sigma0 = float(g.bank_start_deg)
    sigma_f = math.degrees(problem.sigma_f)
    build = time.perf_counter() - t0
    ev = evaluate(problem, np.radians([sigma0]), record=True)
    reached = bool(ev.reached[0])
    flown = fly(plan_controls(problem, ev))
    x = flown.states[-1]
    violations = verify(problem, flown, scenario.terminal.path_limit_tolerance)
    box = terminal_box(scenario, problem, x)
    missed = [f"{k} {box_text(k, b)}" for k, b in box.items() if not b["inside"]]
    xf = ev.final_state[0]
    from_replica = math.hypot(problem.planet.great_circle_distance(x[1], x[2], xf[1], xf[2]), x[0] - xf[0])
    searched_f = found is not None and len(found.x) == 2
    parts = [f"sigma_0 = {sigma0:.3f} deg" + (f", sigma_f = {sigma_f:.3f} deg" if searched_f else "")
             + (f" by {found.method} ({found.trajectories} trajectories)" if found else " (given)"),
             f"J = {ev.J[0]:.4f}: range error {ev.range_error_m[0] / 1e3:+.2f} km, altitude {ev.altitude_error_m[0]:+.0f} m, "
             f"speed {ev.velocity_error_m_s[0]:+.1f} m/s, crossrange {ev.crossrange_m[0] / 1e3:+.2f} km"]
    if not reached:
        parts.append("the trajectory does not reach the TAEM energy")
    parts.append(f"flown by Drake through the actuators: {from_replica:.0f} m from the replica's TAEM point"
                 + (f", stopped early: {flown.failure}" if flown.failure else ""))
    departs = bool(flown.failure) or not from_replica <= FLOWN_TOLERANCE_M
    if departs and not flown.failure:
        parts.append(f"the Drake flight departs from the replica (> {FLOWN_TOLERANCE_M:.0f} m)")
    if missed:
        parts.append("the flight ends outside the acceptance box: " + "; ".join(missed))
    if violations:
        parts.append("the flight breaches " + breaches_text(violations))
    if found is not None and found.message:
        parts.append(found.message)
    return SwarmPlan(success=reached and not departs and not missed and not violations, message="; ".join(parts),
                     iterations=len(found.swarm.history) - 1 if found is not None and found.swarm else 0,
                     build_time=build, solve_time=time.perf_counter() - t0 - build, objective=float(ev.J[0]),
                     problem=problem, sigma0_deg=sigma0, sigma_f_deg=sigma_f, search=found, evaluation=ev,
                     violations=violations,
                     flown=flown, from_replica_m=from_replica)


class SwarmBankMethod(GuidanceMethod):
    name = "swarm_bank"

    def make_planner(self, scenario, verifier) -> SwarmPlan:
        return plan(scenario, verifier)

    def add_systems(self, builder, scenario, planner: SwarmPlan, plant: PlantPorts) -> GuidanceCommands:
        g, p = scenario.guidance, planner.problem
        guidance = builder.AddNamedSystem(GUIDANCE_SYSTEM, SwarmBankGuidance(
            p, math.radians(planner.sigma0_deg), period=g.period_s, replan_period=g.replan_period_s,
            replan_until_e=g.replan_until_e, bounds_deg=tuple(g.bank_start_bounds_deg),
            acceleration_scaling=g.acceleration_scaling,
            end_bounds_deg=tuple(g.bank_end_bounds_deg) if g.resolve_bank_end else None, **g.latency()))
        builder.Connect(plant.estimated_state, guidance.GetInputPort("estimated_state"))
        builder.Connect(plant.flight_conditions, guidance.GetInputPort("flight_conditions"))
        reversal = add_bank_reversal(builder, scenario, plant, guidance.GetOutputPort("bank_magnitude"),
                                     initial_sign=p.initial_sign)
        builder.Connect(reversal.GetOutputPort("bank_command"), guidance.GetInputPort("bank_command"))
        return GuidanceCommands(
            bank=reversal.GetOutputPort("bank_command"), alpha=guidance.GetOutputPort("alpha_command"),
            alpha_limits=ActuatorLimits(p.alpha_min, p.alpha_max, p.alpha_rate, p.alpha_accel),
            initial_bank=p.initial_bank, initial_alpha=p.entry_alpha,
            logged={"alpha_command": LoggedSignal(guidance.GetOutputPort("alpha_command"), ("alpha_command_rad",)),
                    "sigma0": LoggedSignal(guidance.GetOutputPort("sigma0"), ("sigma0_rad",))},
            bank_sinks=(guidance.GetInputPort("bank_flown"),))

    def summarise(self, diagram, context, planner: SwarmPlan) -> GuidanceSummary:
        system = diagram.GetSubsystemByName(GUIDANCE_SYSTEM)
        mine = system.GetMyContextFromRoot(context)
        plans, failed, wall = system.GetOutputPort("plan_stats").Eval(mine)
        sigma0 = math.degrees(system.GetOutputPort("sigma0").Eval(mine)[0])
        sigma_f = math.degrees(system.GetOutputPort("sigma_f").Eval(mine)[0])
        unverified = "" if planner.success else f"the pre-flight plan is not verified: {planner.message}"
        return GuidanceSummary(planner.success, unverified, plans=int(plans), planning_wall_s=float(wall),
                               fields={"reversals": reversal_count(diagram, context),
                                       "sigma0_planned_deg": planner.sigma0_deg, "sigma0_final_deg": sigma0,
                                       "sigma_f_deg": planner.sigma_f_deg, "sigma_f_final_deg": sigma_f,
                                       "resolutions_unbracketed": int(failed)},
                               details=planner)


METHOD = SwarmBankMethod()
