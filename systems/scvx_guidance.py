"""ScvxGuidance: flies an SCvx plan's bank and angle of attack in time (paper 001) and
re-plans on board from the navigation estimate.

The plan's commands are its own segment polynomials sampled densely (``ScvxPlan.control_samples``)
and read at the time since the plan began; alpha is the planned one where the formulation plans
it, else the mission's alpha(V) law at the estimated speed. With ``replan_period`` > 0, every
period (while the plan in use has more than ``min_time_to_go`` seconds left) a new plan is
made from the estimate, holding the bank and alpha being commanded
(``guidance.scvx.planner.replan_from``); a plan that is not a verified success is recorded and
the previous one is kept.

Ports:
  - input  "estimated_state"  [6]  navigation estimate [h m, lon, lat rad, V m/s, gamma, psi rad]
  - output "bank_command"     [1]  sigma [rad] (signed: the plan chooses its reversals)
  - output "alpha_command"    [1]  alpha [rad]
  - output "plan_stats"       [3]  re-plans made, re-plans refused, wall time of re-planning [s]
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from drake_entry.guidance.scvx.planner import ScvxPlan, replan_from


@dataclass(frozen=True)
class FlownPlan:
    """A plan as flown: it began at ``start`` [s] of the flight; commands sampled at ``time``
    [s since start]: ``bank`` [rad] (unwrapped) and ``alpha`` [rad] or None (alpha(V) law)."""

    plan: ScvxPlan
    start: float
    time: np.ndarray
    bank: np.ndarray
    alpha: np.ndarray | None

    @staticmethod
    def of(plan: ScvxPlan, start: float) -> "FlownPlan":
        t, bank, alpha = plan.control_samples()
        return FlownPlan(plan, start, t, bank, alpha)

    def commands(self, t: float, speed: float, lead: float = 0.0) -> tuple[float, float]:
        """(bank, alpha) [rad] at flight time t [s] and speed [m/s] (held after the plan's end),
        read ``lead`` [s] ahead on the plan (the actuators' lag)."""
        s = t + lead - self.start
        bank = float(np.interp(s, self.time, self.bank))
        alpha = (float(np.interp(s, self.time, self.alpha)) if self.alpha is not None
                 else float(self.plan.problem.alpha(speed)))
        return bank, alpha


@dataclass
class ScvxMemory:
    flown: FlownPlan
    next_replan: float
    replans: int = 0
    refused: list = field(default_factory=list)  # (time, message)
    wall_s: float = 0.0

    def __deepcopy__(self, memo):  # the plans are never mutated: copies share them
        return ScvxMemory(self.flown, self.next_replan, self.replans, list(self.refused), self.wall_s)


class ScvxGuidance(LeafSystem):
    def __init__(self, plan: ScvxPlan, *, period: float = 1.0, replan_period: float = 0.0,
                 min_time_to_go: float = 300.0, scvx_settings=None, lead: float = 0.0):
        """Args: plan (the pre-flight plan, flown from t = 0); period [s] of the re-plan check;
        replan_period [s] (0: no re-planning); min_time_to_go [s]: no re-plan with less left;
        scvx_settings: ScvxSettings of the re-plans; lead [s]: the commands are read this far
        ahead on the plan (the actuators' lag; the plans are verified flown the same way)."""
        super().__init__()
        self.lead = lead
        self.replan_period, self.min_time_to_go, self.scvx_settings = replan_period, min_time_to_go, scvx_settings
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        first = ScvxMemory(FlownPlan.of(plan, 0.0), replan_period if replan_period > 0 else np.inf)
        self._memory = self.DeclareAbstractState(AbstractValue.Make(first))
        if replan_period > 0:
            self.DeclarePeriodicUnrestrictedUpdateEvent(period, 0.0, self._update)
        deps = {self.est_port.ticket(), self.all_state_ticket(), self.time_ticket()}
        self.DeclareVectorOutputPort("bank_command", 1, lambda c, o: o.SetAtIndex(0, self._commands(c)[0]),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("alpha_command", 1, lambda c, o: o.SetAtIndex(0, self._commands(c)[1]),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("plan_stats", 3, self._stats, prerequisites_of_calc={self.all_state_ticket()})

    def memory(self, context) -> ScvxMemory:
        return context.get_abstract_state(int(self._memory)).get_value()

    def _commands(self, context):
        x = self.est_port.Eval(context)
        return self.memory(context).flown.commands(context.get_time(), float(x[3]), self.lead)

    def _stats(self, context, output):
        mem = self.memory(context)
        output.SetFromVector([mem.replans, len(mem.refused), mem.wall_s])

    def _update(self, context, state):
        mem = self.memory(context)
        t = context.get_time()
        flown = mem.flown
        if t < mem.next_replan - 1e-9 or flown.start + flown.plan.final_time - t < self.min_time_to_go:
            return
        new = ScvxMemory(flown, mem.next_replan + self.replan_period, mem.replans, list(mem.refused), mem.wall_s)
        x = np.asarray(self.est_port.Eval(context), float)
        bank, alpha = flown.commands(t, float(x[3]))
        t_wall = time.perf_counter()
        try:
            plan = replan_from(flown.plan, x, t - flown.start, bank, alpha, settings=self.scvx_settings)
        except Exception as e:  # a failed re-plan must not stop the flight: the previous plan flies on
            plan = None
            new.refused.append((t, f"{type(e).__name__}: {e}"))
        new.wall_s += time.perf_counter() - t_wall
        if plan is not None and plan.success:
            new.flown = FlownPlan.of(plan, t)
            new.replans += 1
        elif plan is not None:
            new.refused.append((t, plan.message))
        state.get_mutable_abstract_state(int(self._memory)).set_value(new)
