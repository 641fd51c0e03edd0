"""The shared bank-reversal logic wired for any method that commands a bank magnitude
(``ReversingBankSpec``): heading-error corridor from the spec, target from the scenario."""
from __future__ import annotations

import math

from drake_entry.guidance.interface import PlantPorts
from drake_entry.systems.bank_reversal import BankReversalLogic

__all__ = ["REVERSAL_SYSTEM", "add_bank_reversal", "reversal_count"]

REVERSAL_SYSTEM = "bank_reversal"


def add_bank_reversal(builder, scenario, plant: PlantPorts, magnitude_port, *, initial_sign: float = 1.0):
    """Add BankReversalLogic (named "bank_reversal") after ``magnitude_port`` (|sigma| [rad]);
    its "bank_command" output is the signed bank command [rad]."""
    g = scenario.guidance
    reversal = builder.AddNamedSystem(REVERSAL_SYSTEM, BankReversalLogic(
        target_lon=math.radians(scenario.target.longitude_deg), target_lat=math.radians(scenario.target.latitude_deg),
        corridor_deg=tuple(g.reversal_heading_deg), corridor_velocity=tuple(g.reversal_velocity_m_s),
        period=g.period_s, initial_sign=1.0 if initial_sign >= 0 else -1.0))
    builder.Connect(plant.estimated_state, reversal.GetInputPort("estimated_state"))
    builder.Connect(magnitude_port, reversal.GetInputPort("bank_magnitude"))
    return reversal


def reversal_count(diagram, context) -> int:
    """Bank reversals flown so far, from the finished simulation's root context."""
    reversal = diagram.GetSubsystemByName(REVERSAL_SYSTEM)
    return int(reversal.GetOutputPort("reversals").Eval(reversal.GetMyContextFromRoot(context))[0])
