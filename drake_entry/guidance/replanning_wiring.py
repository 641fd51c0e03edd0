"""The shared re-planning guidance (systems/replanning_guidance.py) wired and read the same way
for every method whose plans are flown in time and re-planned on board (``ReplanningSpec``:
paper 001's SCvx, paper 002's LGL)."""
from __future__ import annotations

import math

import numpy as np

from drake_entry.guidance.interface import ActuatorLimits, GuidanceCommands, LoggedSignal, PlantPorts
from drake_entry.systems.acceleration_ratios import AccelerationRatioFilter
from drake_entry.systems.replan_scheduler import ReplanStats
from drake_entry.systems.replanning_guidance import ReplanMemory, ReplanningGuidance

__all__ = ["RATIO_SYSTEM", "add_replanning_guidance", "add_ratio_filter", "scheduled_alpha_ratio_filter",
           "replanning_commands", "replanning_record"]

#: the name of the filter of the sensed lift and drag ratios the re-plans predict with
RATIO_SYSTEM = "acceleration_ratios"


def add_replanning_guidance(builder, name: str, plan, replan, scenario, plant: PlantPorts, **options):
    """Add ReplanningGuidance (named ``name``) flying ``plan`` with the method's ``replan``, the
    guidance spec's period, re-plan period, time to go (and its fraction) and command lead
    (``options``: the system's other arguments), connected to the navigation estimate; with the
    spec's ``replan_model_scales``, an AccelerationRatioFilter (RATIO_SYSTEM) of the scenario's
    nominal models gives the re-plans the lift and drag ratios the flight has shown. Return the
    guidance system."""
    spec = scenario.guidance
    system = builder.AddNamedSystem(name, ReplanningGuidance(
        plan, replan=replan, period=spec.period_s, replan_period=spec.replan_period_s,
        min_time_to_go=spec.replan_min_time_to_go_s, lead=spec.command_lead_s,
        time_to_go_fraction=spec.replan_time_to_go_fraction or None, model_scales=spec.replan_model_scales,
        **spec.latency(), **options))
    builder.Connect(plant.estimated_state, system.GetInputPort("estimated_state"))
    if spec.replan_model_scales:
        ratios = add_ratio_filter(builder, scenario, plant, system.GetInputPort("model_scales"))
        builder.Connect(system.GetOutputPort("alpha_command"), ratios.GetInputPort("alpha_command"))
    return system


def add_ratio_filter(builder, scenario, plant: PlantPorts, model_scales, atmosphere=None):
    """Add the AccelerationRatioFilter (RATIO_SYSTEM) of ``scenario``'s nominal models
    (``atmosphere``: the scenario's when None), at the guidance period, fed by the navigation
    estimate and the sensed flight conditions, its ratios connected to the input port
    ``model_scales``; return it (its input "alpha_command" is the caller's to connect)."""
    ratios = builder.AddNamedSystem(RATIO_SYSTEM, AccelerationRatioFilter(
        scenario.make_vehicle(), scenario.make_planet(), atmosphere or scenario.make_atmosphere(),
        period=scenario.guidance.period_s))
    builder.Connect(plant.estimated_state, ratios.GetInputPort("estimated_state"))
    builder.Connect(plant.flight_conditions, ratios.GetInputPort("flight_conditions"))
    builder.Connect(ratios.GetOutputPort("ratios"), model_scales)
    return ratios


def scheduled_alpha_ratio_filter(builder, scenario, plant: PlantPorts, model_scales, atmosphere=None) -> tuple:
    """``add_ratio_filter`` for a method whose alpha is the scenario's schedule: returns the
    filter's "alpha_command" input as ``GuidanceCommands.alpha_sinks``, which the closed loop
    feeds with the alpha flown."""
    return (add_ratio_filter(builder, scenario, plant, model_scales, atmosphere).GetInputPort("alpha_command"),)


def replanning_commands(system, alpha_limits: ActuatorLimits, initial_bank: float,
                        initial_alpha: float) -> GuidanceCommands:
    """The commands of a ReplanningGuidance: its signed bank and its alpha through the shared
    actuators, its alpha command and re-plan statistics logged."""
    return GuidanceCommands(
        bank=system.GetOutputPort("bank_command"), alpha=system.GetOutputPort("alpha_command"),
        alpha_limits=alpha_limits, initial_bank=float(initial_bank), initial_alpha=float(initial_alpha),
        logged={"alpha_command": LoggedSignal(system.GetOutputPort("alpha_command"), ("alpha_command_rad",)),
                "plan_stats": LoggedSignal(system.GetOutputPort("plan_stats"),
                                           ("replans", "replans_refused", "replan_wall_s"))})


def replanning_record(diagram, context, name: str) -> tuple[ReplanMemory, ReplanStats, dict]:
    """(memory, the schedule's account, row fields) of the ReplanningGuidance ``name`` after a
    flight: re-plans tried and refused, the median and largest wall time of one [s] (nan without
    any), and when the last plan flown began and ends [s of the flight]."""
    system = diagram.GetSubsystemByName(name)
    own = system.GetMyContextFromRoot(context)
    mem, stats = system.memory(own), system.replan_stats(own)
    walls = np.array([w for _, w, _ in mem.log]) if mem.log else np.array([math.nan])
    return mem, stats, {"replans_tried": len(mem.log), "replans_refused": len(mem.refused),
                 "replan_wall_median_s": float(np.median(walls)), "replan_wall_max_s": float(np.max(walls)),
                 "last_plan_start_s": mem.flown.start,
                 "last_plan_final_time_s": mem.flown.start + mem.flown.plan.final_time}
