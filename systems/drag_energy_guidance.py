"""DragEnergyGuidance: plans the drag-energy reference on board and serves it (paper 000).

Pre-guidance (Sec. IV.A): until the drag stops rising (D' >= 0, the flight-path angle
levels out) after ``pre_guidance_min_s``, no reference is served. Then the SOCP is solved
from the navigation estimate (one plan, about 10 ms of solver time at 40 nodes); with
``replan_period_s`` > 0 it is re-solved from the current estimate at that period until the
normalised energy reaches ``replan_until_e``. A failed plan keeps the previous reference
(or stays in pre-guidance), is recorded, and is retried a period later.

With ``model_scales`` every re-plan is made in the air the flight has sensed: the corridor,
the terminal drag and the drag-to-state maps of the vehicle with the filtered lift and drag
ratios (DragEnergyPlanner.sensed), so that the drag a limit allows is the drag the flight will
sense there.

Ports:
  - input  "estimated_state"  [6]
  - input  "flight_conditions" [9]  only its drag entry is read: the accelerometer's drag
                                  (EntryVehicle output; the plan starts from the sensed drag)
  - input  "model_scales"     [2]  (model_scales only) k_L, k_D sensed (systems/acceleration_ratios.py)
  - output "reference"        [4]  D_ref [m/s^2], D'_ref [1/m], D''_ref [s^2/m^3] at the
                                 estimate's energy, engaged flag (1 after the first plan)
  - output "replan_stats"     [4]  the schedule's account (systems/replan_scheduler.py)
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue

from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner, DragEnergyReference
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.lifetime import weak_method
from drake_entry.systems.replan_scheduler import ReplanScheduler

__all__ = ["sensed_drag", "GuidanceMemory", "DragEnergyGuidance"]

_DRAG = FLIGHT_CONDITION_NAMES.index("drag")


def sensed_drag(port, context) -> float | None:
    """The accelerometer's drag [m/s^2] from a connected flight-conditions port, else None."""
    return float(port.Eval(context)[_DRAG]) if port.HasValue(context) else None


@dataclass
class GuidanceMemory:
    reference: DragEnergyReference | None = None
    first_reference: DragEnergyReference | None = None  # the plan at engagement
    engaged_state: object = None  # navigation estimate at engagement
    engaged_at: float | None = None
    failures: list = field(default_factory=list)  # (time, message)

    def __deepcopy__(self, memo):
        # Drake copies abstract state at every update; the reference is never mutated after
        # planning, so copies share it (a deep copy of the corridor each second cost ~1 ms).
        return GuidanceMemory(self.reference, self.first_reference, self.engaged_state, self.engaged_at,
                              list(self.failures))


class DragEnergyGuidance(ReplanScheduler):
    def __init__(self, planner: DragEnergyPlanner, *, period: float = 1.0, pre_guidance_min_s: float = 100.0,
                 replan_period_s: float = 0.0, replan_until_e: float = 0.9, latency_s: float = 0.0,
                 latency_factor: float = 0.0, model_scales: bool = False):
        """Args: planner; period [s]; pre_guidance_min_s [s]; replan_period_s [s] (0: plan once);
        replan_until_e: no re-plan past this normalised energy; latency_s [s], latency_factor: the
        computing latency of each plan (systems/replan_scheduler.py); model_scales: re-plans in
        the sensed air (input "model_scales", module docstring)."""
        super().__init__()
        self.planner = planner
        self.pre_min = pre_guidance_min_s
        self.replan_until_e = replan_until_e
        self.DeclareReplanSchedule(replan_period_s=replan_period_s, latency_s=latency_s,  # the first at engagement
                                   latency_factor=latency_factor)
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.fc_port = self.DeclareVectorInputPort("flight_conditions", len(FLIGHT_CONDITION_NAMES))
        self.scales_port = self.DeclareVectorInputPort("model_scales", 2) if model_scales else None
        self._memory = self.DeclareAbstractState(AbstractValue.Make(GuidanceMemory()))
        self.DeclarePeriodicUnrestrictedUpdateEvent(period, 0.0, weak_method(self._update))
        self.DeclareVectorOutputPort("reference", 4, weak_method(self._calc),
                                     prerequisites_of_calc={self.est_port.ticket(), self.all_state_ticket()})

    def memory(self, context) -> GuidanceMemory:
        return context.get_abstract_state(int(self._memory)).get_value()

    def _update(self, context, state):
        mem = self.memory(context)
        t = context.get_time()
        held = self.take_held(context, state)
        if held is not None:  # a plan computed one latency ago: it flies from now
            mem = copy.deepcopy(mem)
            self._apply(mem, *held, t)
            state.get_mutable_abstract_state(int(self._memory)).set_value(mem)
        x = self.est_port.Eval(context)
        sensed = sensed_drag(self.fc_port, context)
        if mem.reference is None:  # engagement: tried at every update until a plan succeeds
            due = (not self.holding(context) and t >= self.pre_min
                   and self.planner.drag_state(x, sensed).D_prime >= 0.0)
        else:
            E0, Ef = self.planner.E_entry, self.planner.E_final
            e = (E0 - self.planner.energy(x)) / (E0 - Ef)
            due = self.replan_due(context) and e < self.replan_until_e
        if not due:
            return
        new = copy.deepcopy(mem)
        sensed_air = ({} if self.scales_port is None or mem.reference is None
                      else self.planner.sensed(self.scales_port.Eval(context)))  # re-plans: the filter has settled

        def solve():
            ref = self.planner.plan_from_state(x, previous=mem.reference, sensed_drag=sensed, **sensed_air)
            ok = ref is not None and bool(ref.success)
            return (ref, np.array(x)), ok, "" if ok else ("the planner returned no plan" if ref is None else ref.message)

        outcome = self.attempt(context, state, solve)
        if outcome.apply_now:
            self._apply(new, *outcome.result, t)
        elif not outcome.applied:
            new.failures.append((t, outcome.note))
        state.get_mutable_abstract_state(int(self._memory)).set_value(new)

    @staticmethod
    def _apply(mem: GuidanceMemory, ref: DragEnergyReference, x_planned: np.ndarray, t: float) -> None:
        """Fly ``ref`` (planned from the estimate ``x_planned``) from flight time ``t`` [s]."""
        mem.reference = ref
        if mem.engaged_at is None:
            mem.engaged_at = t
            mem.first_reference = ref
            mem.engaged_state = x_planned

    def _calc(self, context, output):
        mem = self.memory(context)
        if mem.reference is None:
            output.SetFromVector([0.0, 0.0, 0.0, 0.0])
            return
        E = self.planner.energy(self.est_port.Eval(context))
        D, Dp, Dpp = mem.reference.profile(E)
        output.SetFromVector([D[0], Dp[0], Dpp[0], 1.0])
