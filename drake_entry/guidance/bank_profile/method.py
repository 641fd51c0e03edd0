"""Bank-profile guidance as a GuidanceMethod: the worked example of adding a method.

  estimate --> ScheduleSource(|sigma|(E)) --|sigma|--> BankReversalLogic --sigma_cmd-->
      (shared bank actuator)

The magnitude is open loop in energy (``BankProfile``: linear in normalised energy, paper
004 eq. 17 form); the shared reversal logic closes the lateral loop on the heading error.
"""
from __future__ import annotations

import dataclasses as dc
import time

import numpy as np

from drake_entry.guidance.interface import GuidanceCommands, GuidanceMethod, GuidanceSummary, PlantPorts
from drake_entry.guidance.reversal_wiring import add_bank_reversal, reversal_count
from drake_entry.models.schedules import Schedule
from drake_entry.planning.result import PlanResult
from drake_entry.systems.schedule import ScheduleSource

__all__ = ["BankProfilePlan", "BankProfileMethod", "METHOD"]


@dc.dataclass
class BankProfilePlan(PlanResult):
    """The bank-magnitude profile |sigma|(E) [rad vs J/kg] of a BankProfile spec (nothing is
    optimised: objective nan, no iterations)."""

    variable = "energy"

    schedule: Schedule | None = None

    def evaluate(self, energy) -> dict:
        """{'bank_magnitude_rad': |sigma|} at specific energies [J/kg]."""
        return {"bank_magnitude_rad": np.array([self.schedule(float(e)) for e in np.atleast_1d(energy)])}


class BankProfileMethod(GuidanceMethod):
    name = "bank_profile"

    def make_planner(self, scenario, verifier) -> BankProfilePlan:
        t0 = time.perf_counter()
        g = scenario.guidance
        E0, Ef = scenario.entry_energy(), scenario.guidance_terminal_state()[2]
        schedule = Schedule((Ef, E0), (np.radians(g.bank_end_deg), np.radians(g.bank_start_deg)), "energy")
        return BankProfilePlan(success=True, message="bank magnitude linear in normalised energy",
                               build_time=time.perf_counter() - t0, schedule=schedule)

    def add_systems(self, builder, scenario, planner: BankProfilePlan, plant: PlantPorts) -> GuidanceCommands:
        g = scenario.guidance
        planet = scenario.make_planet().with_(j2=0.0)  # energy-valued schedules use central gravity
        magnitude = builder.AddNamedSystem("bank_profile", ScheduleSource(
            planner.schedule, planet, period=g.period_s, initial_value=np.radians(g.bank_start_deg)))
        builder.Connect(plant.estimated_state, magnitude.GetInputPort("state"))
        reversal = add_bank_reversal(builder, scenario, plant, magnitude.get_output_port())
        return GuidanceCommands(bank=reversal.GetOutputPort("bank_command"), initial_bank=np.radians(g.bank_start_deg))

    def summarise(self, diagram, context, planner) -> GuidanceSummary:
        return GuidanceSummary(True, fields={"reversals": reversal_count(diagram, context)}, details=planner)


METHOD = BankProfileMethod()
