"""FNPEG (Lu 2014) as a GuidanceMethod.

  estimate, flight conditions --> FnpegGuidance --|sigma|--> BankReversalLogic --sigma_cmd-->
      (shared bank actuator);   FnpegGuidance --alpha_command--> (shared alpha actuator)
  BankReversalLogic --sigma_cmd--> FnpegGuidance (the sign the predictions hold)

Nothing is planned before flight: the "planner" is the mission's on-board predictor and
corrector (guidance/fnpeg/onboard.py), built once per campaign worker; every flight is judged
by the shared verdict (terminal box and path limits).
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np

from drake_entry.guidance.fnpeg.onboard import FnpegSetup
from drake_entry.guidance.interface import (
    ActuatorLimits,
    GuidanceCommands,
    GuidanceMethod,
    GuidanceSummary,
    LoggedSignal,
    PlantPorts,
)
from drake_entry.guidance.reversal_wiring import add_bank_reversal, reversal_count
from drake_entry.planning.result import PlanResult
from drake_entry.systems.fnpeg_guidance import FnpegGuidance

__all__ = ["GUIDANCE_SYSTEM", "FnpegPlan", "FnpegMethod", "METHOD"]

GUIDANCE_SYSTEM = "fnpeg_guidance"


@dc.dataclass
class FnpegPlan(PlanResult):
    """The on-board FNPEG of a mission (``setup``): nothing is optimised before flight, so
    success only says the predictor was built; each flight's verdict is its own."""

    setup: FnpegSetup | None = None
    engage_acceleration: float = math.nan

    def evaluate(self, at) -> dict:
        raise NotImplementedError("FNPEG has no pre-flight reference: it predicts on board")


class FnpegMethod(GuidanceMethod):
    name = "fnpeg"

    def make_planner(self, scenario, verifier) -> FnpegPlan:
        t0 = time.perf_counter()
        setup = FnpegSetup.from_scenario(scenario)
        return FnpegPlan(success=True, message="FNPEG solves its bank profile on board: nothing is planned before "
                         "flight", build_time=time.perf_counter() - t0, setup=setup,
                         engage_acceleration=scenario.guidance.engage_acceleration_m_s2)

    def add_systems(self, builder, scenario, planner: FnpegPlan, plant: PlantPorts) -> GuidanceCommands:
        g, s = scenario.guidance, planner.setup
        alpha0 = s.alpha_command(scenario.entry.velocity_m_s)
        guidance = builder.AddNamedSystem(GUIDANCE_SYSTEM, FnpegGuidance(
            s, sigma0_guess=math.radians(g.bank_start_guess_deg), bank_before=math.radians(g.bank_before_engagement_deg),
            initial_alpha=alpha0, engage_acceleration=g.engage_acceleration_m_s2, period=g.period_s,
            replan_period=g.replan_period_s, scaling=g.acceleration_scaling, **g.latency()))
        builder.Connect(plant.estimated_state, guidance.GetInputPort("estimated_state"))
        builder.Connect(plant.flight_conditions, guidance.GetInputPort("flight_conditions"))
        reversal = add_bank_reversal(builder, scenario, plant, guidance.GetOutputPort("bank_magnitude"))
        builder.Connect(reversal.GetOutputPort("bank_command"), guidance.GetInputPort("bank_command"))
        alphas = np.radians(g.alpha_deg)
        return GuidanceCommands(
            bank=reversal.GetOutputPort("bank_command"), alpha=guidance.GetOutputPort("alpha_command"),
            alpha_limits=ActuatorLimits(float(alphas.min()) - math.radians(1.0), float(alphas.max()) + math.radians(1.0),
                                        math.radians(g.alpha_rate_deg_s), math.radians(g.alpha_accel_deg_s2)),
            initial_bank=math.radians(g.bank_before_engagement_deg), initial_alpha=alpha0,
            logged={"alpha_command": LoggedSignal(guidance.GetOutputPort("alpha_command"), ("alpha_command_rad",)),
                    "sigma0": LoggedSignal(guidance.GetOutputPort("sigma0"), ("sigma0_rad",)),
                    "range_error": LoggedSignal(guidance.GetOutputPort("range_error"), ("predicted_range_error_m",))})

    def summarise(self, diagram, context, planner: FnpegPlan) -> GuidanceSummary:
        system = diagram.GetSubsystemByName(GUIDANCE_SYSTEM)
        mine = system.GetMyContextFromRoot(context)
        engaged, t_engage, corrections, predictions, unconverged, wall = system.GetOutputPort("stats").Eval(mine)
        sigma0 = math.degrees(system.GetOutputPort("sigma0").Eval(mine)[0])
        z = float(system.GetOutputPort("range_error").Eval(mine)[0])
        message = "" if engaged else ("FNPEG never engaged: the sensed aerodynamic acceleration never reached "
                                      f"{planner.engage_acceleration:g} m/s^2")
        return GuidanceSummary(bool(engaged), message, plans=int(corrections), planning_wall_s=float(wall),
                               fields={"reversals": reversal_count(diagram, context), "engage_time_s": float(t_engage),
                                       "sigma0_final_deg": sigma0, "predictions": int(predictions),
                                       "corrections_unconverged": int(unconverged),
                                       "last_predicted_range_error_m": z},
                               details=planner)


METHOD = FnpegMethod()
