"""Paper 003's guidance as a GuidanceMethod.

  estimate --> ReferenceTracker (at entry: the database reference for the measured state,
      AMPI or NTT, and its TVLQR; then sigma_c' = u_ref - K (x - x_ref)) --bank_command-->
      (shared bank actuator);   alpha: the scenario's schedule (Table 2)
  with ``model_scales``: estimate, sensed lift and drag, alpha flown --> AccelerationRatioFilter
      --k_L, k_D--> ReferenceTracker (the reference read at the sensed ratios)
  with ``path_gain``: sensed flight conditions --> ReferenceTracker (Lu 2014's path-limit feedback)

The planner (``make_planner``) loads the database once per mission and checks it (every case
verified, none out of line with its neighbours); each flight makes its own reference at
t = 0 from the navigation estimate.
"""
from __future__ import annotations

import math

from drake_entry.guidance.ampi.mission import built_database
from drake_entry.guidance.ampi.reference import DatabaseReference
from drake_entry.guidance.ampi.spec import MISSION_DATABASE
from drake_entry.guidance.interface import GuidanceCommands, GuidanceMethod, GuidanceSummary, LoggedSignal, PlantPorts
from drake_entry.guidance.path_feedback import PathLimits
from drake_entry.guidance.replanning_wiring import scheduled_alpha_ratio_filter
from drake_entry.systems.reference_tracking import ReferenceTracker

__all__ = ["GUIDANCE_SYSTEM", "AmpiMethod", "METHOD"]

GUIDANCE_SYSTEM = "reference_tracker"


class AmpiMethod(GuidanceMethod):
    name = "ampi"
    preparation = "drake_entry.guidance.ampi.mission_study:prepare"

    def make_planner(self, scenario, verifier) -> DatabaseReference:
        g = scenario.guidance
        database = g.database
        if database == MISSION_DATABASE:  # built for this mission beforehand (preparation), cached
            database = built_database(g, scenario).path
        return DatabaseReference.load(database, g.reference, hd_points=g.hd_points, weights=g.weights(),
                                      gain_samples=g.gain_samples)

    def add_systems(self, builder, scenario, planner: DatabaseReference, plant: PlantPorts) -> GuidanceCommands:
        vehicle, g = scenario.make_vehicle(), scenario.guidance
        bank0 = float(planner.evaluate([0.0])["sigma"][0])
        atmosphere = scenario.make_atmosphere() if g.model_scales else None
        path = PathLimits.of_vehicle(vehicle.limits, scenario.make_planet(), gain=g.path_gain,
                                     horizon=g.path_horizon_s, fraction=g.path_limit_fraction)
        tracker = builder.AddNamedSystem(GUIDANCE_SYSTEM, ReferenceTracker(
            planner, bank_limit=vehicle.bank_limit, rate_limit=vehicle.bank_rate_limit,
            period=g.period_s, initial_bank=bank0, lead=g.bank_lead_s, index=g.tracking_index,
            density=None if atmosphere is None else atmosphere.density, path=path))
        builder.Connect(plant.estimated_state, tracker.GetInputPort("estimated_state"))
        if tracker.HasInputPort("flight_conditions"):  # the path-limit feedback reads the sensed loads
            builder.Connect(plant.flight_conditions, tracker.GetInputPort("flight_conditions"))
        sinks = scheduled_alpha_ratio_filter(builder, scenario, plant, tracker.GetInputPort("model_scales"),
                                             atmosphere) if g.model_scales else ()
        return GuidanceCommands(
            bank=tracker.GetOutputPort("bank_command"), initial_bank=bank0,
            logged={"reference_state": LoggedSignal(tracker.GetOutputPort("reference_state"), (
                "h_ref_m", "lon_ref_rad", "lat_ref_rad", "V_ref_m_s", "gamma_ref_rad", "psi_ref_rad", "bank_ref_rad"))},
            alpha_sinks=sinks)

    def summarise(self, diagram, context, planner: DatabaseReference) -> GuidanceSummary:
        system = diagram.GetSubsystemByName(GUIDANCE_SYSTEM)
        mem = system.memory(system.GetMyContextFromRoot(context))
        ref = mem.reference
        if ref is None:
            return GuidanceSummary(False, f"no reference at entry: {mem.message}")
        syn = ref.synthesis
        fields = {"reference_mode": ref.mode, "reference_final_time_s": syn.final_time,
                  "reference_extrapolated": int(syn.extrapolated.sum()), "reference_case": syn.cases[0],
                  "synthesis_ms": ref.synthesis_s * 1e3, "gains_s": ref.gains_s}
        units = {"h": ("m", 1.0), "V": ("m_s", 1.0)}
        for n, v in zip(planner.database.grid.names, ref.offsets):
            unit, factor = units.get(n, ("deg", math.degrees(1.0)))
            fields[f"entry_offset_{n}_{unit}"] = float(v * factor)
        return GuidanceSummary(True, plans=1, planning_wall_s=ref.synthesis_s + ref.gains_s, fields=fields,
                               details={"reference": ref})


METHOD = AmpiMethod()
