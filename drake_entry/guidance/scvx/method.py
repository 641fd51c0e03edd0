"""Paper 001's guidance as a GuidanceMethod.

  estimate --> ReplanningGuidance (the plan's sigma(t), alpha(t) or alpha(V); re-plans, with the
      sensed lift and drag ratios when replan_model_scales: replanning_wiring) --bank_command-->
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

from drake_entry.guidance.interface import ActuatorLimits, GuidanceCommands, GuidanceMethod, GuidanceSummary, PlantPorts
from drake_entry.guidance.replanning_wiring import add_replanning_guidance, replanning_commands, replanning_record
from drake_entry.guidance.scvx.feedback import feedback_maker
from drake_entry.guidance.scvx.planner import ScvxPlan, plan_entry, replan_from

__all__ = ["GUIDANCE_SYSTEM", "ScvxMethod", "METHOD"]

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
        guidance = add_replanning_guidance(builder, GUIDANCE_SYSTEM, planner,
                                           functools.partial(replan_from, settings=g.planner_settings()[1]), scenario,
                                           plant,
                                           feedback=feedback_maker(g.feedback, g.feedback_state_weight),
                                           offset_limits=g.feedback_offset_limits())
        lo, hi = np.radians(g.alpha_bounds_deg)
        return replanning_commands(guidance, ActuatorLimits(float(lo), float(hi), math.radians(g.alpha_rate_limit_deg_s),
                                                            math.radians(planner.flight.alpha_acceleration_deg_s2)),
                                   planner.bank[0], planner.alpha[0])

    def summarise(self, diagram, context, planner: ScvxPlan) -> GuidanceSummary:
        mem, stats, fields = replanning_record(diagram, context, GUIDANCE_SYSTEM)
        return GuidanceSummary(
            planner.success, "" if planner.success else f"the pre-flight plan is not verified: {planner.message}",
            plans=stats.applied, planning_wall_s=stats.wall_s,
            fields={**fields, "plan_heat_load_MJ_m2": planner.metrics["heat_load_MJ_m2"],
                    "plan_final_time_s": planner.final_time, "plan_iterations": planner.iterations},
            details={"plan": planner, "last_plan": mem.flown.plan, "refused": mem.refused, "replans": mem.log})


METHOD = ScvxMethod()
