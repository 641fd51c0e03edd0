"""The one on-board re-planning schedule (systems/replan_scheduler.py): when re-plans are due,
what an attempt records, and the guidance computing latency: a plan computed at t is applied at
t + latency, exactly when the latency is a whole number of update periods, else at the first
update after it; nothing else starts while a plan is held."""
import math
import time

import numpy as np
import pytest
from pydrake.common.value import AbstractValue
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector

from drake_entry.errors import ScenarioError
from drake_entry.systems.replan_scheduler import ReplanScheduler


class _Counter(ReplanScheduler):
    """Plans 'the time it was computed at'; outputs the plan in use. ``numbers``: a discrete update
    that holds plans as numbers, else an unrestricted one that holds them as objects."""

    def __init__(self, *, numbers: bool, replan_period_s=10.0, latency_s=0.0, latency_factor=0.0, solve_s=0.0):
        super().__init__()
        self.solve_s, self.numbers = solve_s, numbers
        self.DeclareReplanSchedule(replan_period_s=replan_period_s, first_due_s=replan_period_s, latency_s=latency_s,
                                   latency_factor=latency_factor, pending_size=1 if numbers else None)
        self.computed = []  # (flight time, plan) of every attempt, in order
        if numbers:
            self._plan = self.DeclareDiscreteState(BasicVector([-1.0]))
            self.DeclarePeriodicDiscreteUpdateEvent(1.0, 0.0, self._update)
            self.DeclareVectorOutputPort("plan", 1, lambda c, o: o.SetFromVector(c.get_discrete_state(self._plan)
                                                                                  .get_value()),
                                         prerequisites_of_calc={self.xd_ticket()})
        else:
            self._plan = self.DeclareAbstractState(AbstractValue.Make(-1.0))
            self.DeclarePeriodicUnrestrictedUpdateEvent(1.0, 0.0, self._update)
            self.DeclareVectorOutputPort("plan", 1, lambda c, o: o.SetAtIndex(0, c.get_abstract_state(
                int(self._plan)).get_value()), prerequisites_of_calc={self.all_state_ticket()})

    def _set(self, values, plan):
        if self.numbers:
            values.get_mutable_vector(self._plan).SetAtIndex(0, plan)
        else:
            values.get_mutable_abstract_state(int(self._plan)).set_value(float(plan))

    def _update(self, context, values):
        held = self.take_held(context, values)
        if held is not None:
            self._set(values, held[0] if self.numbers else held)
        if not self.replan_due(context):
            return
        t = context.get_time()

        def solve():
            time.sleep(self.solve_s)
            return t, True, ""

        self.computed.append(t)
        outcome = self.attempt(context, values, solve, encode=lambda plan: [plan])
        if outcome.apply_now:
            self._set(values, outcome.result)


def _plans_in_use(system: _Counter, until_s: float) -> dict:
    """{flight time [s]: the plan in use}, read between the 1-s updates."""
    simulator = Simulator(system)
    out = {}
    for t in np.arange(0.5, until_s, 1.0):
        simulator.AdvanceTo(t)
        out[round(t - 0.5)] = float(system.get_output_port(1).Eval(simulator.get_context())[0])
    return out


@pytest.mark.parametrize("numbers", [False, True], ids=["object held", "numbers held"])
def test_without_latency_a_plan_flies_from_the_update_that_computed_it(numbers):
    used = _plans_in_use(_Counter(numbers=numbers), 32.0)
    assert [used[t] for t in (9, 10, 19, 20, 30)] == [-1.0, 10.0, 10.0, 20.0, 30.0]


@pytest.mark.parametrize("numbers", [False, True], ids=["object held", "numbers held"])
def test_a_plan_computed_at_t_is_applied_at_t_plus_the_latency_exactly(numbers):
    system = _Counter(numbers=numbers, latency_s=3.0)
    used = _plans_in_use(system, 36.0)
    assert [used[t] for t in (10, 12, 13, 22, 23, 33)] == [-1.0, -1.0, 10.0, 10.0, 20.0, 30.0]
    assert system.computed[:3] == [10.0, 20.0, 30.0]  # the schedule keeps its period


@pytest.mark.parametrize("numbers", [False, True], ids=["object held", "numbers held"])
def test_a_latency_between_updates_applies_at_the_first_update_after_it(numbers):
    used = _plans_in_use(_Counter(numbers=numbers, latency_s=2.5), 16.0)
    assert [used[t] for t in (12, 13)] == [-1.0, 10.0]


@pytest.mark.parametrize("numbers", [False, True], ids=["object held", "numbers held"])
def test_no_re_plan_starts_while_one_is_held(numbers):
    """A latency longer than the period: the computer is busy; the next attempt starts at the
    update where the held plan flies (5 s, then 8 s), and the period counts from each attempt."""
    system = _Counter(numbers=numbers, replan_period_s=2.0, latency_s=3.0)
    used = _plans_in_use(system, 13.0)
    assert system.computed[:3] == [2.0, 5.0, 8.0]
    assert [used[t] for t in (4, 5, 7, 8, 11)] == [-1.0, 2.0, 2.0, 5.0, 8.0]


@pytest.mark.parametrize("numbers", [False, True], ids=["object held", "numbers held"])
def test_a_latency_of_one_period_keeps_the_re_plan_rate(numbers):
    """Re-plans every update, each computed in one period: every update applies the plan of the
    update before and starts the next (FNPEG's 1-Hz corrector on a computer that needs 1 s)."""
    system = _Counter(numbers=numbers, replan_period_s=1.0, latency_s=1.0)
    used = _plans_in_use(system, 8.0)
    assert system.computed[:5] == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert [used[t] for t in (1, 2, 3, 6)] == [-1.0, 1.0, 2.0, 5.0]


def test_the_latency_factor_scales_the_measured_computing_time():
    """latency = factor x wall time: a solve of at least 50 ms at factor 40 flies 2 s or more later."""
    system = _Counter(numbers=True, latency_factor=40.0, solve_s=0.05)
    used = _plans_in_use(system, 16.0)
    applied = min(t for t, plan in used.items() if plan == 10.0)
    assert 12 <= applied <= 14


@pytest.mark.parametrize("field, value", [("replan_latency_s", -1.0), ("replan_latency_s", math.inf),
                                          ("replan_latency_factor", -0.5), ("replan_latency_factor", math.nan)])
def test_a_bad_latency_is_one_line_naming_the_field(field, value):
    from drake_entry.scenario import apply_overrides, load_scenario

    scenario = load_scenario("horus2b")
    with pytest.raises(ScenarioError, match=f"guidance.{field}"):
        apply_overrides(scenario, {f"guidance.{field}": str(value).replace("inf", ".inf").replace("nan", ".nan")})


def test_the_drag_energy_guidance_flies_each_plan_one_latency_later():
    """The scripted drag-energy planner of the fallback tests with a 3-s latency: the first plan,
    computed at engagement (t = 0), flies from 3 s, which is when the guidance engages; the
    re-plan computed at 10 s flies from 13 s."""
    import types

    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
    from drake_entry.systems.drag_energy_guidance import DragEnergyGuidance

    class Planner:
        calls = 0
        E_entry, E_final = 0.0, -1.0

        def energy(self, x):
            return -0.5

        def drag_state(self, x, sensed):
            return types.SimpleNamespace(D_prime=1.0)

        def plan_from_state(self, x, previous=None, sensed_drag=None):
            self.calls += 1
            level = float(self.calls)
            return types.SimpleNamespace(success=True, message="ok",
                                         profile=lambda E: (np.array([level]), np.array([0.0]), np.array([0.0])))

    builder = DiagramBuilder()
    guidance = builder.AddSystem(DragEnergyGuidance(Planner(), period=1.0, pre_guidance_min_s=0.0,
                                                    replan_period_s=10.0, latency_s=3.0))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    conditions = builder.AddSystem(ConstantVectorSource(np.ones(len(FLIGHT_CONDITION_NAMES))))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    builder.Connect(conditions.get_output_port(), guidance.GetInputPort("flight_conditions"))
    simulator = Simulator(builder.Build())
    served = {}
    for t in np.arange(0.5, 16.0, 1.0):
        simulator.AdvanceTo(t)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        served[round(t - 0.5)] = tuple(guidance.GetOutputPort("reference").Eval(context)[[0, 3]])
    assert [served[t] for t in (2, 3, 12, 13)] == [(0.0, 0.0), (1.0, 1.0), (1.0, 1.0), (2.0, 1.0)]
    assert guidance.memory(context).engaged_at == 3.0
    assert guidance.replan_stats(context).attempts == 2
