"""Paper 001's guidance as a GuidanceMethod.

  estimate --> ReplanningGuidance (the plan's sigma(t), alpha(t) or alpha(V); re-plans) --bank_command-->
      (shared bank actuator);   ReplanningGuidance --alpha_command--> (shared alpha actuator)

The pre-flight plan (``make_planner``) is made once per mission from the scenario's entry
state to its target's DRS box and verified (between-node limits, its controls propagated);
each flight flies it, re-planned on board every ``replan_period_s`` from the navigation
estimate. The bank is flown signed: the plan chooses its reversals (no shared reversal logic).
"""
from __future__ import annotations

import functools
import math

import numpy as np

from drake_entry.guidance.interface import (
    ActuatorLimits,
    GuidanceCommands,
    GuidanceMethod,
    GuidanceSummary,
    LoggedSignal,
    PlantPorts,
)
from drake_entry.guidance.scvx.planner import ScvxPlan, plan_entry, replan_from
from drake_entry.systems.replanning_guidance import ReplanningGuidance

GUIDANCE_SYSTEM = "scvx_guidance"


class ScvxMethod(GuidanceMethod):
    name = "scvx"

    def make_planner(self, scenario, verifier) -> ScvxPlan:
        problem, scvx = scenario.guidance.planner_settings()
        return plan_entry(scenario.make_vehicle(), scenario.make_planet(), scenario.make_atmosphere(),
                          scenario.guidance.mission(scenario), problem_settings=problem, settings=scvx,
                          flight=scenario.guidance.flight_check(), verifier=verifier)

    def add_systems(self, builder, scenario, planner: ScvxPlan, plant: PlantPorts) -> GuidanceCommands:
        g = scenario.guidance
        settings = g.planner_settings()[1]
        guidance = builder.AddNamedSystem(GUIDANCE_SYSTEM, ReplanningGuidance(
            planner, replan=functools.partial(replan_from, settings=settings),
            period=g.period_s, replan_period=g.replan_period_s, min_time_to_go=g.replan_min_time_to_go_s,
            lead=g.command_lead_s))
        builder.Connect(plant.estimated_state, guidance.GetInputPort("estimated_state"))
        lo, hi = np.radians(g.alpha_bounds_deg)
        return GuidanceCommands(
            bank=guidance.GetOutputPort("bank_command"), alpha=guidance.GetOutputPort("alpha_command"),
            alpha_limits=ActuatorLimits(float(lo), float(hi), math.radians(g.alpha_rate_limit_deg_s),
                                        math.radians(planner.flight.alpha_acceleration_deg_s2)),
            initial_bank=float(planner.bank[0]), initial_alpha=float(planner.alpha[0]),
            logged={"alpha_command": LoggedSignal(guidance.GetOutputPort("alpha_command"), ("alpha_command_rad",)),
                    "plan_stats": LoggedSignal(guidance.GetOutputPort("plan_stats"),
                                               ("replans", "replans_refused", "replan_wall_s"))})

    def summarise(self, diagram, context, planner: ScvxPlan) -> GuidanceSummary:
        system = diagram.GetSubsystemByName(GUIDANCE_SYSTEM)
        mem = system.memory(system.GetMyContextFromRoot(context))
        flown = mem.flown.plan
        return GuidanceSummary(
            planner.success, "" if planner.success else f"the pre-flight plan is not verified: {planner.message}",
            plans=mem.replans, planning_wall_s=mem.wall_s,
            fields={"replans_refused": len(mem.refused), "plan_heat_load_MJ_m2": planner.metrics["heat_load_MJ_m2"],
                    "plan_final_time_s": planner.final_time, "plan_iterations": planner.iterations,
                    "last_plan_start_s": mem.flown.start, "last_plan_final_time_s": mem.flown.start + flown.final_time},
            details={"plan": planner, "last_plan": flown, "refused": mem.refused})


METHOD = ScvxMethod()
