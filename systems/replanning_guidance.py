"""ReplanningGuidance: flies a plan's bank and angle of attack in time and re-plans on board
from the navigation estimate (paper 001's SCvx plans, paper 002's shrinking-horizon LGL
solutions).

A plan is any object with ``control_samples() -> (t [s], bank [rad], alpha [rad] or None)``
(dense samples from its start), ``final_time`` [s], ``success`` and ``message``; a plan whose
alpha samples are None flies ``plan.problem.alpha(V)`` (an alpha(V) law) at the estimated
speed. The commands are read at the time since the plan began, ``lead`` seconds ahead (the
actuators' lag), and held after its end.

With ``replan_period`` > 0, re-plans follow the shared schedule (systems/replan_scheduler.py):
the first at ``first_replan``, then one every ``replan_period`` (with ``time_to_go_fraction`` the
period shrinks to that fraction of the time to go, never below the guidance period), while the
plan in use has more than ``min_time_to_go`` seconds left. A new plan is made from the estimate
by the method's ``replan(plan, x, elapsed, bank, alpha)`` callable, holding the bank and alpha
being commanded; a re-plan that raises or is not a verified success is recorded with its time
and reason, and the previous plan flies on.

With ``feedback``, the commands are the plan's plus offsets that a tracking law of the plan in
use builds up between re-plans: ``feedback(plan)`` gives an object whose ``rates(s, x, offsets)``
is d(offsets)/dt [rad/s] at s seconds into the plan (planning.tracking.CommandFeedback); every
period the offsets (bank, alpha) [rad] advance by the rates times the period, clipped to
``offset_limits``, and an accepted re-plan (which starts from the commands flown) sets them
back to zero.

With ``model_scales``, the re-planner is also given ``scales=(k_L, k_D)``, the lift and drag
ratios the flight has shown (systems/acceleration_ratios.py), read from the "model_scales" input.

Ports:
  - input  "estimated_state"  [6]  navigation estimate [h m, lon, lat rad, V m/s, gamma, psi rad]
  - input  "model_scales"     [2]  k_L, k_D (only with model_scales)
  - output "bank_command"     [1]  sigma [rad] (signed: the plan chooses its reversals)
  - output "alpha_command"    [1]  alpha [rad]
  - output "plan_stats"       [3]  re-plans made, re-plans refused, wall time of re-planning [s]
  - output "replan_stats"     [4]  the schedule's account (systems/replan_scheduler.py)
  - output "command_offsets"  [2]  the feedback's bank and alpha offsets [rad] (zero without feedback)
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from pydrake.common.value import AbstractValue

from drake_entry.systems.lifetime import weak_element, weak_method
from drake_entry.systems.replan_scheduler import ReplanScheduler

__all__ = ["FlownPlan", "ReplanMemory", "Replan", "ReplanningGuidance"]


@dataclass(frozen=True)
class FlownPlan:
    """A plan as flown: it began at ``start`` [s] of the flight; commands sampled at ``time``
    [s since start]: ``bank`` [rad] (unwrapped) and ``alpha`` [rad] or None (alpha(V) law)."""

    plan: object
    start: float
    time: np.ndarray
    bank: np.ndarray
    alpha: np.ndarray | None
    feedback: object = None

    @staticmethod
    def of(plan, start: float, feedback=None) -> "FlownPlan":
        """The plan flown from ``start`` [s]; ``feedback``: the plan's tracking law maker (or None)."""
        t, bank, alpha = plan.control_samples()
        return FlownPlan(plan, start, t, bank, alpha, None if feedback is None else feedback(plan))

    def commands(self, t: float, speed: float, lead: float = 0.0) -> tuple[float, float]:
        """(bank, alpha) [rad] at flight time t [s] and speed [m/s] (held after the plan's end),
        read ``lead`` [s] ahead on the plan (the actuators' lag)."""
        s = t + lead - self.start
        bank = float(np.interp(s, self.time, self.bank))
        alpha = (float(np.interp(s, self.time, self.alpha)) if self.alpha is not None
                 else float(self.plan.problem.alpha(speed)))
        return bank, alpha


@dataclass
class ReplanMemory:
    """The guidance's state besides its schedule: the plan flown, the refused re-plans as (time
    [s], reason), per re-plan (time [s], wall time [s], accepted), and the flight times [s] at
    which a plan began without the feedback law asked for (it could not be made: the plan flies
    on its own)."""

    flown: FlownPlan
    refused: list = field(default_factory=list)
    log: list = field(default_factory=list)
    unfed: list = field(default_factory=list)

    def __deepcopy__(self, memo):  # the plans are never mutated: copies share them
        return ReplanMemory(self.flown, list(self.refused), list(self.log), list(self.unfed))


#: replan(plan, x [6], elapsed [s since the plan began], bank [rad], alpha [rad]) -> a new plan
Replan = Callable[[object, np.ndarray, float, float, float], object]


class ReplanningGuidance(ReplanScheduler):
    def __init__(self, plan, *, replan: Replan | None = None, period: float = 1.0, replan_period: float = 0.0,
                 min_time_to_go: float = 300.0, lead: float = 0.0, first_replan: float | None = None,
                 time_to_go_fraction: float | None = None, model_scales: bool = False,
                 feedback: Callable[[object], object] | None = None, offset_limits=(0.0, 0.0),
                 latency_s: float = 0.0, latency_factor: float = 0.0):
        """Args: plan (the pre-flight plan, flown from t = 0); replan: the method's re-planner
        (needed when replan_period > 0); period [s] of the re-plan check; replan_period [s] (0: no
        re-planning); min_time_to_go [s]: no re-plan with less left; lead [s]: the commands are
        read this far ahead on the plan (the actuators' lag; the plans are verified flown the
        same way); first_replan [s]: the flight time of the first re-plan (default
        replan_period), the next ones every replan_period after it, or, with
        time_to_go_fraction, after min(replan_period, max(period, fraction x time to go)) [s]
        (the time to go of the plan in use after the re-plan); model_scales: declare the
        "model_scales" input and pass its value to ``replan`` as ``scales``; feedback: the
        tracking law maker of a plan and offset_limits (bank, alpha) [rad] its offsets' bounds
        (module docstring); latency_s [s], latency_factor: each re-plan's computing latency
        (systems/replan_scheduler.py: it flies from then, read at its own time since it began)."""
        super().__init__()
        if replan_period > 0 and replan is None:
            raise ValueError("ReplanningGuidance: replan_period > 0 needs a replan callable")
        self.lead, self.replan, self.period, self.time_to_go_fraction = lead, replan, period, time_to_go_fraction
        self.min_time_to_go = min_time_to_go
        self.feedback, self.offset_limits = feedback, np.asarray(offset_limits, float)
        self.est_port = self.DeclareVectorInputPort("estimated_state", 6)
        self.scales_port = self.DeclareVectorInputPort("model_scales", 2) if model_scales else None
        first_at = (replan_period if first_replan is None else first_replan) if replan_period > 0 else np.inf
        self.DeclareReplanSchedule(replan_period_s=replan_period, first_due_s=first_at, latency_s=latency_s,
                                   latency_factor=latency_factor)
        flown = FlownPlan.of(plan, 0.0, feedback)
        first = ReplanMemory(flown, unfed=[0.0] if feedback is not None and flown.feedback is None else [])
        self._memory = self.DeclareAbstractState(AbstractValue.Make(first))
        self._offsets = self.DeclareDiscreteState(2)
        if replan_period > 0 or feedback is not None:
            self.DeclarePeriodicUnrestrictedUpdateEvent(period, 0.0, weak_method(self._update))
        deps = {self.est_port.ticket(), self.all_state_ticket(), self.time_ticket()}
        self.DeclareVectorOutputPort("bank_command", 1, weak_element(self._commands, 0),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("alpha_command", 1, weak_element(self._commands, 1),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("plan_stats", 3, weak_method(self._stats),
                                     prerequisites_of_calc={self.all_state_ticket()})
        self.DeclareStateOutputPort("command_offsets", self._offsets)

    def memory(self, context) -> ReplanMemory:
        return context.get_abstract_state(int(self._memory)).get_value()

    def _commands(self, context):
        x = self.est_port.Eval(context)
        bank, alpha = self.memory(context).flown.commands(context.get_time(), float(x[3]), self.lead)
        d = context.get_discrete_state(self._offsets).value()
        return bank + float(d[0]), alpha + float(d[1])

    def _stats(self, context, output):
        s = self.replan_stats(context)
        output.SetFromVector([s.applied, s.refused, s.wall_s])

    def _update(self, context, state):
        mem = self.memory(context)
        t = context.get_time()
        held = self.take_held(context, state)
        if held is not None:  # a re-plan computed one latency ago flies from now
            mem = copy.deepcopy(mem)  # the plans are shared, the records copied (ReplanMemory.__deepcopy__)
            mem.flown = held
            self._start(mem, state, t)
            state.get_mutable_abstract_state(int(self._memory)).set_value(mem)
        flown = mem.flown
        x = np.asarray(self.est_port.Eval(context), float)
        offsets = np.zeros(2) if held is not None else context.get_discrete_state(self._offsets).value().copy()
        if held is None and flown.feedback is not None and t - flown.start < flown.plan.final_time:
            offsets = np.clip(offsets + self.period * flown.feedback.rates(t - flown.start, x, offsets),
                              -self.offset_limits, self.offset_limits)
            state.get_mutable_discrete_state(self._offsets).SetFromVector(offsets)
        if not self.replan_due(context) or flown.start + flown.plan.final_time - t < self.min_time_to_go:
            return
        new = copy.deepcopy(mem)
        bank, alpha = flown.commands(t, float(x[3]))  # the commands flown now (not read ahead)
        bank, alpha = bank + float(offsets[0]), alpha + float(offsets[1])

        def solve():
            extra = {} if self.scales_port is None else {"scales": tuple(self.scales_port.Eval(context))}
            plan = self.replan(flown.plan, x, t - flown.start, bank, alpha, **extra)
            accepted = plan is not None and bool(plan.success)
            note = "" if accepted else ("the re-planner returned no plan" if plan is None else plan.message)
            return (FlownPlan.of(plan, t, self.feedback) if accepted else None), accepted, note

        if self.time_to_go_fraction is not None:  # the plan in use after this attempt sets the next
            outcome = self.attempt(context, state, solve, interval=0.0)
            in_use = outcome.result if outcome.applied else flown
            to_go = in_use.start + in_use.plan.final_time - t
            interval = min(self.replan_period_s, max(self.period, self.time_to_go_fraction * to_go))
            self.due_now(state, t + interval)
        else:
            outcome = self.attempt(context, state, solve)
        new.log.append((t, outcome.wall_s, outcome.applied))
        if outcome.apply_now:
            new.flown = outcome.result
            self._start(new, state, t)
        elif not outcome.applied:
            new.refused.append((t, outcome.note))
        state.get_mutable_abstract_state(int(self._memory)).set_value(new)

    def _start(self, mem: ReplanMemory, state, t: float) -> None:
        """``mem.flown`` (just accepted) flies from flight time ``t`` [s]: its feedback, if asked
        for and not made, is recorded, and the offsets restart at zero (it starts where we are)."""
        if self.feedback is not None and mem.flown.feedback is None:
            mem.unfed.append(t)
        state.get_mutable_discrete_state(self._offsets).SetFromVector(np.zeros(2))
