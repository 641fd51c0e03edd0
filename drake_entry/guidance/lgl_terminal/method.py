"""Paper 002's terminal guidance as a GuidanceMethod.

  estimate, sensed lift and drag --> AccelerationRatioFilter --ratios (k_L, k_D)--+
  estimate --> ReplanningGuidance (the LGL solution's sigma(t), alpha(t); re-solves on the   <--+
      remaining horizon with the models scaled by k_L, k_D) --bank_command--> (shared bank actuator)
                                                            --alpha_command--> (shared alpha actuator)

The pre-flight plan (``make_planner``) is solved once per mission and verified (planner module
docstring); each flight flies it and re-solves it from the navigation estimate every
``replan_period_s``; a re-solve that fails or is not verified is recorded and the solution in
use flies on. The closed loop stops at impact (``stops_at_altitude``).
"""
from __future__ import annotations

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
from drake_entry.guidance.lgl_terminal.planner import LglPlan, plan_terminal, replan
from drake_entry.systems.acceleration_ratios import AccelerationRatioFilter
from drake_entry.systems.replanning_guidance import ReplanningGuidance

GUIDANCE_SYSTEM, RATIO_SYSTEM = "lgl_terminal_guidance", "acceleration_ratios"


class LglTerminalMethod(GuidanceMethod):
    name = "lgl_terminal"

    def make_planner(self, scenario, verifier) -> LglPlan:
        return plan_terminal(scenario, verifier, progress=False)

    def add_systems(self, builder, scenario, planner: LglPlan, plant: PlantPorts) -> GuidanceCommands:
        g = scenario.guidance
        guidance = builder.AddNamedSystem(GUIDANCE_SYSTEM, ReplanningGuidance(
            planner, replan=replan, period=g.period_s, replan_period=g.replan_period_s,
            min_time_to_go=g.replan_min_time_to_go_s, lead=g.command_lead_s, first_replan=g.replan_start_s,
            time_to_go_fraction=g.replan_time_to_go_fraction or None, model_scales=g.replan_model_scales))
        builder.Connect(plant.estimated_state, guidance.GetInputPort("estimated_state"))
        if g.replan_model_scales:
            ratios = builder.AddNamedSystem(RATIO_SYSTEM, AccelerationRatioFilter(
                scenario.make_vehicle(), scenario.make_planet(), scenario.make_atmosphere(), period=g.period_s))
            builder.Connect(plant.estimated_state, ratios.GetInputPort("estimated_state"))
            builder.Connect(plant.flight_conditions, ratios.GetInputPort("flight_conditions"))
            builder.Connect(guidance.GetOutputPort("alpha_command"), ratios.GetInputPort("alpha_command"))
            builder.Connect(ratios.GetOutputPort("ratios"), guidance.GetInputPort("model_scales"))
        problem = planner.result.problem
        lo, hi = problem.state_bounds["alpha"]
        _, bank, alpha = planner.control_samples()
        return GuidanceCommands(
            bank=guidance.GetOutputPort("bank_command"), alpha=guidance.GetOutputPort("alpha_command"),
            alpha_limits=ActuatorLimits(float(lo), float(hi), float(max(abs(r) for r in problem.control_bounds["u_alpha"])),
                                        math.radians(g.alpha_accel_limit_deg_s2)),
            initial_bank=float(bank[0]), initial_alpha=float(alpha[0]),
            logged={"alpha_command": LoggedSignal(guidance.GetOutputPort("alpha_command"), ("alpha_command_rad",)),
                    "plan_stats": LoggedSignal(guidance.GetOutputPort("plan_stats"),
                                               ("replans", "replans_refused", "replan_wall_s"))})

    def summarise(self, diagram, context, planner: LglPlan) -> GuidanceSummary:
        system = diagram.GetSubsystemByName(GUIDANCE_SYSTEM)
        mem = system.memory(system.GetMyContextFromRoot(context))
        walls = np.array([w for _, w, _ in mem.log]) if mem.log else np.array([math.nan])
        return GuidanceSummary(
            planner.success, "" if planner.success else f"the pre-flight plan is not verified: {planner.message}",
            plans=mem.replans, planning_wall_s=mem.wall_s,
            fields={"replans_tried": len(mem.log), "replans_refused": len(mem.refused),
                    "replan_wall_median_s": float(np.median(walls)), "replan_wall_max_s": float(np.max(walls)),
                    "plan_objective": float(planner.result.objective), "plan_final_time_s": planner.final_time,
                    "last_plan_start_s": mem.flown.start,
                    "last_plan_final_time_s": mem.flown.start + mem.flown.plan.final_time},
            details={"plan": planner, "last_plan": mem.flown.plan, "refused": mem.refused, "replans": mem.log})


METHOD = LglTerminalMethod()
