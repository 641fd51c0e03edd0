"""Paper 002's terminal guidance as a GuidanceMethod.

  estimate, sensed lift and drag --> AccelerationRatioFilter --ratios (k_L, k_D)--+   (replanning_wiring)
  estimate --> ReplanningGuidance (the LGL solution's sigma(t), alpha(t) plus the offsets of   <--+
      its TVLQR; re-solves on the remaining horizon with the models
      scaled by k_L, k_D)                                   --bank_command--> (shared bank actuator)
                                                            --alpha_command--> (shared alpha actuator)

The pre-flight plan (``make_planner``) is solved once per mission and verified (planner module
docstring); each flight flies it, corrected between re-solves by the time-varying LQR of the
solution in use (``feedback: tvlqr``), and re-solves it from the navigation estimate every
``replan_period_s``; a re-solve that fails or is not verified is recorded and the solution in
use flies on. The closed loop stops at impact (``stops_at_altitude``).
"""
from __future__ import annotations

from drake_entry.guidance.interface import (
    ActuatorLimits,
    GuidanceCommands,
    GuidanceMethod,
    GuidanceSummary,
    LoggedSignal,
    PlantPorts,
)
from drake_entry.guidance.lgl_terminal.planner import LglPlan, actuation, feedback_maker, plan_terminal, replan
from drake_entry.guidance.replanning_wiring import add_replanning_guidance, replanning_commands, replanning_record

__all__ = ["GUIDANCE_SYSTEM", "LglTerminalMethod", "METHOD"]

GUIDANCE_SYSTEM = "lgl_terminal_guidance"


class LglTerminalMethod(GuidanceMethod):
    name = "lgl_terminal"

    def make_planner(self, scenario, verifier) -> LglPlan:
        return plan_terminal(scenario, verifier, progress=False)

    def add_systems(self, builder, scenario, planner: LglPlan, plant: PlantPorts) -> GuidanceCommands:
        g = scenario.guidance
        guidance = add_replanning_guidance(builder, GUIDANCE_SYSTEM, planner, replan, scenario, plant,
                                           first_replan=g.replan_start_s,
                                           feedback=feedback_maker(g.feedback),
                                           offset_limits=g.feedback_offset_limits())
        _, bank, alpha = planner.control_samples()
        act = actuation(planner.result.problem, g, bank[0], alpha[0])  # the actuators the plans are verified with
        commands = replanning_commands(guidance, ActuatorLimits(*act.alpha_bounds, act.alpha_rate_limit,
                                                                act.alpha_accel_limit),
                                       act.initial_bank, act.initial_alpha)
        commands.logged["command_offsets"] = LoggedSignal(guidance.GetOutputPort("command_offsets"),
                                                          ("bank_offset_rad", "alpha_offset_rad"))
        return commands

    def summarise(self, diagram, context, planner: LglPlan) -> GuidanceSummary:
        mem, stats, fields = replanning_record(diagram, context, GUIDANCE_SYSTEM)
        return GuidanceSummary(
            planner.success, "" if planner.success else f"the pre-flight plan is not verified: {planner.message}",
            plans=stats.applied, planning_wall_s=stats.wall_s,
            fields={**fields, "plan_objective": float(planner.result.objective), "plan_final_time_s": planner.final_time,
                    "plans_without_feedback": len(mem.unfed)},
            details={"plan": planner, "last_plan": mem.flown.plan, "refused": mem.refused, "replans": mem.log})


METHOD = LglTerminalMethod()
