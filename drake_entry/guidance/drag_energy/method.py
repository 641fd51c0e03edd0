"""Drag-energy guidance (paper 000 Secs. IV.A, VI.D) as a GuidanceMethod:

  estimate, sensed drag --> DragEnergyGuidance --reference--> DragTrackingController
    --|sigma|--> BankReversalLogic --sigma_cmd--> (shared bank actuator)
  with ``replan_model_scales``: estimate, sensed lift and drag, alpha flown -->
      AccelerationRatioFilter --k_L, k_D--> DragEnergyGuidance (re-plans in the sensed air)

The vehicle flies the scenario's alpha(E) schedule (paper 000 Sec. IV.A). The planner
(``DragEnergyPlanner``: the corridor, computed once) is shared by every flight and sample.
"""
from __future__ import annotations

import math

import numpy as np

from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner
from drake_entry.guidance.interface import GuidanceCommands, GuidanceMethod, GuidanceSummary, LoggedSignal, PlantPorts
from drake_entry.guidance.replanning_wiring import scheduled_alpha_ratio_filter
from drake_entry.guidance.reversal_wiring import add_bank_reversal, reversal_count
from drake_entry.systems.drag_energy_guidance import DragEnergyGuidance
from drake_entry.systems.drag_energy_tracking import DragTrackingController

__all__ = ["REFERENCE_COLUMNS", "DragEnergyMethod", "METHOD"]

REFERENCE_COLUMNS = ("reference_drag_m_s2", "reference_drag_slope_1_m", "reference_drag_curvature_s2_m3",
                     "guidance_engaged")


class DragEnergyMethod(GuidanceMethod):
    name = "drag_energy"

    def make_planner(self, scenario, verifier) -> DragEnergyPlanner:
        return DragEnergyPlanner.from_scenario(scenario)

    def add_systems(self, builder, scenario, planner, plant: PlantPorts) -> GuidanceCommands:
        g = scenario.guidance
        guidance = builder.AddNamedSystem("drag_energy_guidance", DragEnergyGuidance(
            planner, period=g.period_s, pre_guidance_min_s=g.pre_guidance_min_s, replan_period_s=g.replan_period_s,
            replan_until_e=g.replan_until_e, model_scales=g.replan_model_scales, **g.latency()))
        builder.Connect(plant.estimated_state, guidance.GetInputPort("estimated_state"))
        # the accelerometer's drag: guidance and feedback act on the drag actually felt
        builder.Connect(plant.flight_conditions, guidance.GetInputPort("flight_conditions"))
        pre_bank = math.radians(g.pre_guidance_bank_deg)
        magnitude = self.add_controller(builder, scenario, planner, plant, guidance.GetOutputPort("reference"))
        reversal = add_bank_reversal(builder, scenario, plant, magnitude, initial_sign=1.0 if pre_bank >= 0 else -1.0)
        sinks = scheduled_alpha_ratio_filter(builder, scenario, plant, guidance.GetInputPort("model_scales")) \
            if g.replan_model_scales else ()
        return GuidanceCommands(bank=reversal.GetOutputPort("bank_command"), initial_bank=pre_bank,
                                logged={"reference": LoggedSignal(guidance.GetOutputPort("reference"),
                                                                  REFERENCE_COLUMNS)}, alpha_sinks=sinks)

    def add_controller(self, builder, scenario, planner, plant: PlantPorts, reference):
        """Add the drag-tracking controller and return its bank-magnitude port |sigma| [rad];
        ``reference`` is DragEnergyGuidance's output [D_ref m/s^2, D'_ref 1/m, D''_ref s^2/m^3,
        engaged flag]. Override it to fly a controller of your own with paper 000's planner,
        reference and reversal logic (examples/02_custom_controller.py)."""
        g = scenario.guidance
        controller = builder.AddNamedSystem("drag_tracking", DragTrackingController(
            planner, zeta=g.zeta, omega=g.omega_per_J, integral_ratio=g.integral_ratio, period=g.period_s,
            pre_guidance_bank=abs(math.radians(g.pre_guidance_bank_deg)), bandwidth=g.bandwidth_rad_s))
        builder.Connect(plant.estimated_state, controller.GetInputPort("estimated_state"))
        builder.Connect(reference, controller.GetInputPort("reference"))
        builder.Connect(plant.flight_conditions, controller.GetInputPort("flight_conditions"))
        return controller.GetOutputPort("bank_magnitude")

    def summarise(self, diagram, context, planner) -> GuidanceSummary:
        guidance = diagram.GetSubsystemByName("drag_energy_guidance")
        own = guidance.GetMyContextFromRoot(context)
        mem, stats = guidance.memory(own), guidance.replan_stats(own)
        active = mem.engaged_at is not None
        message = ""
        if not active:
            message = "guidance never engaged: " + (mem.failures[-1][1] if mem.failures
                                                    else "engagement condition never met")
        fields = {"engaged_at_s": mem.engaged_at if active else np.nan, "planning_failures": len(mem.failures),
                  "reversals": reversal_count(diagram, context)}
        return GuidanceSummary(active, message, plans=stats.applied, planning_wall_s=stats.wall_s, fields=fields,
                               details=mem)

    def flight_plots(self, result, out_dir: str, *, title: str = "") -> list[str]:
        from drake_entry.guidance.drag_energy.plots import tracking_plot

        return tracking_plot(result.trajectory, out_dir, title=f"{title}: drag tracking")


METHOD = DragEnergyMethod()
