"""ReplanScheduler: the one on-board re-planning schedule, shared by every guidance method that
plans on board (paper 000's drag-energy SOCP, paper 001's SCvx and paper 002's LGL plans, paper
004's sigma_0 re-solved on board, FNPEG's corrector).

A method's guidance system derives from ``ReplanScheduler`` (a ``LeafSystem``), declares its
schedule once with ``DeclareReplanSchedule`` and, in its own periodic update at flight time t,
asks ``replan_due`` and re-plans through ``attempt``:

    if self.replan_due(context) and <the method's own condition>:
        outcome = self.attempt(context, values, solve)

The rule, the same for every method (``replan_period_s`` in every spec, checked by
``drake_entry.guidance.spec.check_replanning``):

- the first re-plan is due at ``first_due_s``, or, for a method that plans when it engages,
  from the flight time given to ``due_now``;
- after an attempt at t the next is due at t + ``replan_period_s`` (or the method's own interval
  for that attempt, e.g. a horizon that shrinks); ``replan_period_s`` = 0: none after it;
- a due re-plan that the method declines is either kept due (its condition is checked again at
  the next sample) or skipped to one period later (``skip``), as the method says;
- ``attempt`` times the solve (wall-clock, for cost accounting only), catches what it raises
  (the plan in use flies on: a failed re-plan never stops a flight) and counts the attempt, the
  plans applied and the clean ones (applied without a caveat such as "not converged");
- guidance computing latency: a plan computed from the estimate at t is applied at
  t + ``latency_s`` + ``latency_factor`` x its measured wall time (a flight computer's stated
  time, or what this machine took scaled to one), at the first update at or after that instant
  (exactly then when the latency is a whole number of update periods); until then it is held
  (``take_held``), the plan in use flies on, and no other re-plan starts before it flies (the
  computer is busy); the next may start at the update where it does.

The schedule is a discrete-state group of the system (a periodic discrete update and an
unrestricted one both write it), so the order of events in the diagram is the method's own
(in Drake a discrete update sees an unrestricted update's result at the same instant). A held
plan is kept as numbers in a discrete-state group (``pending_size``: systems whose update is
discrete) or as an object in an abstract state (systems with an unrestricted update).

Ports added by ``DeclareReplanSchedule``:
  - output "replan_stats" [4]  attempts, plans applied, clean plans, wall time of the attempts [s]
"""
from __future__ import annotations

import dataclasses as dc
import math
import time
from typing import Callable

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, DiscreteValues, LeafSystem

from drake_entry.systems.lifetime import weak_method

__all__ = ["DUE_TOLERANCE_S", "ReplanOutcome", "Solve", "ReplanStats", "ReplanScheduler"]

#: the schedule's discrete state: next due time [s], attempts, applied, clean, wall time [s], and
#: when the held plan is applied [s] (inf: none held)
_NEXT, _ATTEMPTS, _APPLIED, _CLEAN, _WALL, _HELD_UNTIL = range(6)
#: a re-plan is due from this much before its time [s] (periodic samples land on k * period)
DUE_TOLERANCE_S = 1e-9


@dc.dataclass(frozen=True)
class ReplanOutcome:
    """One attempt: the method's result (None when the solve raised), whether it was applied,
    whether it was clean (applied without a caveat), why not (or the caveat), its wall time [s],
    and until when it is held for the computing latency [s] (inf: not held)."""

    result: object
    applied: bool
    clean: bool
    note: str
    wall_s: float
    held_until: float = math.inf

    @property
    def apply_now(self) -> bool:
        """The method applies the result now (accepted, and no latency holds it)."""
        return self.applied and self.held_until == math.inf


#: solve() -> (result, applied, note): the method's re-plan; note is '' for a clean plan, else why
#: it was not applied or the caveat it was applied with
Solve = Callable[[], tuple]


@dc.dataclass(frozen=True)
class ReplanStats:
    """The schedule's account after a flight: attempts, plans applied, clean plans, wall time [s]."""

    attempts: int
    applied: int
    clean: int
    wall_s: float

    @property
    def refused(self) -> int:
        """Attempts whose result was not applied (the previous plan flew on)."""
        return self.attempts - self.applied

    @property
    def flawed(self) -> int:
        """Attempts not applied or applied with a caveat."""
        return self.attempts - self.clean


class ReplanScheduler(LeafSystem):
    """Base of the guidance systems that re-plan on board (module docstring)."""

    def DeclareReplanSchedule(self, *, replan_period_s: float, first_due_s: float = math.inf, latency_s: float = 0.0,
                              latency_factor: float = 0.0, pending_size: int | None = None):
        """Declare the schedule: re-plans every ``replan_period_s`` [s] (0: none after the first),
        the first due at ``first_due_s`` [s] (inf: when the method calls ``due_now``); each plan
        applied ``latency_s`` [s] plus ``latency_factor`` times its wall time after it was
        computed; a held plan kept as ``pending_size`` numbers (``attempt``'s ``encode``) or, None,
        as an object."""
        if not (replan_period_s == 0 or 0 < replan_period_s < math.inf):
            raise ValueError(f"{type(self).__name__}: replan_period_s must be 0 or > 0, got {replan_period_s}")
        if not (0 <= latency_s < math.inf and 0 <= latency_factor < math.inf):
            raise ValueError(f"{type(self).__name__}: latency_s = {latency_s} and latency_factor = {latency_factor} "
                             f"must be finite and >= 0")
        self.replan_period_s = float(replan_period_s)
        self.latency_s, self.latency_factor = float(latency_s), float(latency_factor)
        self._schedule = self.DeclareDiscreteState(BasicVector([first_due_s, 0.0, 0.0, 0.0, 0.0, math.inf]))
        self._held = self._held_numbers = None
        if self.latency_s > 0 or self.latency_factor > 0:
            if pending_size is None:
                self._held = self.DeclareAbstractState(AbstractValue.Make(_Held(None)))
            else:
                self._held_numbers = self.DeclareDiscreteState(int(pending_size))
        self.DeclareVectorOutputPort("replan_stats", 4, weak_method(self._replan_stats),
                                     prerequisites_of_calc={self.xd_ticket()})

    def _schedule_of(self, context):
        return context.get_discrete_state(self._schedule).get_value()

    def _replan_stats(self, context, output):
        output.SetFromVector(self._schedule_of(context)[_ATTEMPTS:_HELD_UNTIL])

    def _mutable(self, values, index=None):
        """A discrete group's vector in an update's output (a DiscreteValues or a State)."""
        index = self._schedule if index is None else index
        if isinstance(values, DiscreteValues):
            return values.get_mutable_vector(index)
        return values.get_mutable_discrete_state(index)

    def replan_due(self, context) -> bool:
        """A re-plan is due at this sample, and no plan is held for its latency beyond it (a plan
        whose time has come is taken at this update, and the computer is free again)."""
        s = self._schedule_of(context)
        t = context.get_time()
        return t >= s[_NEXT] - DUE_TOLERANCE_S and (s[_HELD_UNTIL] == math.inf
                                                    or t >= s[_HELD_UNTIL] - DUE_TOLERANCE_S)

    def holding(self, context) -> bool:
        """A computed plan is held for its latency."""
        return self._schedule_of(context)[_HELD_UNTIL] < math.inf

    def due_now(self, values, t: float) -> None:
        """Make a re-plan due at flight time ``t`` [s] (a method that engages plans at once)."""
        self._mutable(values).SetAtIndex(_NEXT, t)

    def skip(self, values, t: float) -> None:
        """Decline the re-plan due at ``t`` [s]: the next is due one period later."""
        self._mutable(values).SetAtIndex(_NEXT, self._after(t, self.replan_period_s))

    @staticmethod
    def _after(t: float, interval: float) -> float:
        return t + interval if interval > 0 else math.inf

    def attempt(self, context, values, solve: Solve, *, interval: float | None = None,
                encode: Callable[[object], object] | None = None) -> ReplanOutcome:
        """Re-plan now: run ``solve`` (timed; what it raises becomes a refused attempt with its
        reason), count the attempt, and make the next due ``interval`` [s] after now (default
        ``replan_period_s``; 0: none). With a latency an accepted result is held (``encode``
        gives its numbers when the schedule keeps it as numbers) and applied by ``take_held``;
        ``outcome.apply_now`` says whether the method applies it now."""
        t = context.get_time()
        t_wall = time.perf_counter()
        try:
            result, applied, note = solve()
        except Exception as e:  # a failed re-plan must not stop the flight: the plan in use flies on
            result, applied, note = None, False, f"{type(e).__name__}: {e}"
        wall = time.perf_counter() - t_wall
        applied = bool(applied)
        clean = applied and not note
        v = self._mutable(values)
        old = self._schedule_of(context)
        v.SetAtIndex(_NEXT, self._after(t, self.replan_period_s if interval is None else interval))
        v.SetAtIndex(_ATTEMPTS, old[_ATTEMPTS] + 1)
        v.SetAtIndex(_APPLIED, old[_APPLIED] + applied)
        v.SetAtIndex(_CLEAN, old[_CLEAN] + clean)
        v.SetAtIndex(_WALL, old[_WALL] + wall)
        held_until = math.inf
        latency = self.latency_s + self.latency_factor * wall
        if applied and latency > 0:
            held_until = t + latency
            v.SetAtIndex(_HELD_UNTIL, held_until)
            if self._held_numbers is not None:
                self._mutable(values, self._held_numbers).SetFromVector(np.asarray(encode(result), float))
            else:
                values.get_mutable_abstract_state(int(self._held)).set_value(_Held(result))
        return ReplanOutcome(result, applied, clean, note, wall, held_until)

    def take_held(self, context, values):
        """The plan held for its latency when its time has come (it is then no longer held):
        its numbers, or the object; else None."""
        held_until = self._schedule_of(context)[_HELD_UNTIL]
        if held_until == math.inf or context.get_time() < held_until - DUE_TOLERANCE_S:
            return None
        self._mutable(values).SetAtIndex(_HELD_UNTIL, math.inf)
        if self._held_numbers is not None:
            return context.get_discrete_state(self._held_numbers).get_value().copy()
        return context.get_abstract_state(int(self._held)).get_value().result

    def replan_stats(self, context) -> ReplanStats:
        """The schedule's account in this system's ``context``."""
        s = self._schedule_of(context)
        return ReplanStats(int(s[_ATTEMPTS]), int(s[_APPLIED]), int(s[_CLEAN]), float(s[_WALL]))


@dc.dataclass(frozen=True)
class _Held:
    """A computed plan held for its latency (abstract state; never mutated, so copies share it)."""

    result: object

    def __deepcopy__(self, memo):
        return self
