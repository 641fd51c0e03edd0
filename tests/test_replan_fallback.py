"""A re-plan that fails mid-flight (the solver raises, or returns an unsuccessful plan): the
guidance keeps serving the previous reference, records the failure with its time and reason,
and retries one re-plan period later, as systems/drag_energy_guidance.py documents."""
import types

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.systems.drag_energy_guidance import DragEnergyGuidance


class ScriptedPlanner:
    """A planner stub: plan k (1, 2, ...) serves the constant drag k m/s^2, unless the script
    says the k-th call raises or returns an unsuccessful plan."""

    E_entry, E_final = 0.0, -1.0

    def __init__(self, script: dict):
        self.script, self.calls, self.call_times = script, 0, []

    def energy(self, x):
        return -0.5  # half-way: re-planning stays allowed (replan_until_e 0.9)

    def drag_state(self, x, sensed):
        return types.SimpleNamespace(D_prime=1.0)  # drag no longer rising: guidance may engage

    def plan_from_state(self, x, previous=None, sensed_drag=None):
        self.calls += 1
        what = self.script.get(self.calls)
        if what == "raise":
            raise FloatingPointError("forced solver failure")
        level = float(self.calls)
        return types.SimpleNamespace(
            success=what != "unsuccessful", message="forced: not converged" if what == "unsuccessful" else "ok",
            profile=lambda E, level=level: (np.array([level]), np.array([0.0]), np.array([0.0])))


def _fly(planner, until_s: float, replan_s: float = 10.0):
    builder = DiagramBuilder()
    guidance = builder.AddSystem(DragEnergyGuidance(planner, period=1.0, pre_guidance_min_s=0.0,
                                                    replan_period_s=replan_s))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    conditions = builder.AddSystem(ConstantVectorSource(np.ones(len(FLIGHT_CONDITION_NAMES))))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    builder.Connect(conditions.get_output_port(), guidance.GetInputPort("flight_conditions"))
    simulator = Simulator(builder.Build())
    served = []
    for t in np.arange(0.5, until_s, 1.0):  # between the 1-s guidance updates
        simulator.AdvanceTo(t)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        served.append(guidance.GetOutputPort("reference").Eval(context)[0])
    context = guidance.GetMyContextFromRoot(simulator.get_context())
    return np.array(served), guidance.memory(context), guidance.replan_stats(context)


def test_a_failed_replan_keeps_the_previous_reference_and_is_retried_a_period_later():
    planner = ScriptedPlanner({2: "raise", 3: "unsuccessful"})
    served, memory, stats = _fly(planner, 45.0)
    # plans at t = 0 (1), 10 (raises), 20 (unsuccessful), 30 (drag 4), 40 (drag 5)
    assert planner.calls == 5
    expected = np.repeat([1.0, 1.0, 1.0, 4.0, 5.0], 10)[: len(served)]
    assert np.array_equal(served, expected)
    assert stats.applied == 3 and stats.attempts == 5 and memory.engaged_at == 0.0
    assert [(t, m) for t, m in memory.failures] == [(10.0, "FloatingPointError: forced solver failure"),
                                                    (20.0, "forced: not converged")]


def test_a_failed_first_plan_stays_in_pre_guidance_until_one_succeeds():
    planner = ScriptedPlanner({1: "raise", 2: "unsuccessful"})
    served, memory, _ = _fly(planner, 35.0)
    # without a reference the guidance serves zeros (not engaged); the first plan is retried at
    # the next guidance update (no re-plan period applies before engagement)
    assert np.array_equal(served[:2], [0.0, 0.0]) and served[2] == 3.0
    assert memory.engaged_at == 2.0 and len(memory.failures) == 2


class _StubPlan:
    """What ReplanningGuidance reads of a plan: its commands (a constant bank ``level`` rad), t_f,
    success and message."""

    def __init__(self, level: float, success: bool = True, message: str = "converged"):
        self.level, self.success, self.message, self.final_time = level, success, message, 2000.0

    def control_samples(self):
        t = np.array([0.0, self.final_time])
        return t, np.full(2, self.level), np.full(2, 0.2)


def test_a_refused_scvx_replan_keeps_the_plan_in_flight(monkeypatch):
    """ReplanningGuidance re-plans every 100 s; the first re-plan raises, the second is not a verified
    success, the third succeeds: the pre-flight plan's bank flies until t = 300 s, both refusals
    are recorded with time and reason, and plan_stats counts 1 re-plan and 2 refused."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    calls = []

    def scripted_replan(plan, x, t_plan, bank, alpha):
        calls.append(t_plan)
        if len(calls) == 1:
            raise ValueError("forced: Clarabel failed")
        if len(calls) == 2:
            return _StubPlan(2.0, success=False, message="converged but its controls flown end 9 km away")
        return _StubPlan(3.0)

    builder = DiagramBuilder()
    guidance = builder.AddSystem(ReplanningGuidance(_StubPlan(1.0), replan=scripted_replan, period=1.0,
                                                    replan_period=100.0, min_time_to_go=300.0))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    simulator = Simulator(builder.Build())
    bank = []
    for t in np.arange(50.0, 451.0, 50.0):
        simulator.AdvanceTo(t + 0.5)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        bank.append(guidance.GetOutputPort("bank_command").Eval(context)[0])
    assert calls == [100.0, 200.0, 300.0, 100.0]  # time since the flown plan began (a new one at 300 s)
    assert bank == [1.0, 1.0, 1.0, 1.0, 1.0, 3.0, 3.0, 3.0, 3.0]
    memory = guidance.memory(context)
    assert memory.refused == [(100.0, "ValueError: forced: Clarabel failed"),
                              (200.0, "converged but its controls flown end 9 km away")]
    stats = guidance.GetOutputPort("plan_stats").Eval(context)
    assert stats[0] == 2 and stats[1] == 2  # t = 300 s and 400 s succeeded
    assert [(t, ok) for t, _, ok in memory.log] == [(100.0, False), (200.0, False), (300.0, True), (400.0, True)]


def test_a_replan_held_for_its_latency_flies_from_then_read_at_its_own_time():
    """ReplanningGuidance with a 30-s computing latency: the re-plan computed at 100 s flies from
    130 s (the pre-flight plan until then), its start stays 100 s (it is read 30 s into itself), and
    the next re-plan is due 100 s after the attempt, at 200 s."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    calls = []

    def replan(plan, x, t_plan, bank, alpha):
        calls.append(t_plan)
        return _StubPlan(2.0 + len(calls))

    builder = DiagramBuilder()
    guidance = builder.AddSystem(ReplanningGuidance(_StubPlan(1.0), replan=replan, period=1.0, replan_period=100.0,
                                                    min_time_to_go=300.0, latency_s=30.0))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    simulator = Simulator(builder.Build())
    bank = {}
    for t in (129.5, 130.5, 229.5, 230.5):
        simulator.AdvanceTo(t)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        bank[t] = guidance.GetOutputPort("bank_command").Eval(context)[0]
    assert bank == {129.5: 1.0, 130.5: 3.0, 229.5: 3.0, 230.5: 4.0}
    assert calls == [100.0, 100.0]  # the second at 200 s, 100 s into the plan that began at 100 s
    assert guidance.memory(context).flown.start == 200.0


@pytest.mark.parametrize("latency_s", [0.0, 4.0])
def test_a_swarm_resolution_that_raises_keeps_sigma0_and_is_counted(monkeypatch, latency_s):
    """SwarmBankGuidance re-solves sigma_0 every 10 s; a re-solution that raises (the first) or
    returns a non-finite sigma_0 (the second) leaves the sigma_0 in use, and plan_stats counts
    both as failed; the third re-solution's bracketed root is taken (at 30 s, or with a 4-s
    computing latency at 34 s)."""
    import math

    import drake_entry.systems.swarm_bank_guidance as swarm
    from drake_entry.guidance.swarm_bank.search import Resolution, problem_from_scenario
    from drake_entry.scenario import load_scenario

    problem = problem_from_scenario(load_scenario("cav_h_paper004"))
    script = iter([FloatingPointError("forced"), Resolution(math.nan, False, math.nan, 8),
                   Resolution(61.0, True, 0.0, 24)])

    def scripted(here, previous_deg, bounds_deg):
        outcome = next(script)
        if isinstance(outcome, Exception):
            raise outcome
        return outcome

    monkeypatch.setattr(swarm, "resolve_sigma0", scripted)
    builder = DiagramBuilder()
    guidance = builder.AddSystem(swarm.SwarmBankGuidance(problem, math.radians(58.0), period=1.0,
                                                         replan_period=10.0, acceleration_scaling=False,
                                                         latency_s=latency_s))
    for port, value in (("estimated_state", problem.x0), ("flight_conditions", np.ones(len(FLIGHT_CONDITION_NAMES))),
                        ("bank_command", [0.5])):
        builder.Connect(builder.AddSystem(ConstantVectorSource(np.asarray(value, float))).get_output_port(),
                        guidance.GetInputPort(port))
    simulator = Simulator(builder.Build())
    sigma0 = []
    for t in (5.5, 15.5, 25.5, 32.5, 35.5):
        simulator.AdvanceTo(t)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        sigma0.append(math.degrees(guidance.GetOutputPort("sigma0").Eval(context)[0]))
    at_32 = 61.0 if latency_s == 0 else 58.0
    assert sigma0 == pytest.approx([58.0, 58.0, 58.0, at_32, 61.0], abs=1e-12)
    stats = guidance.GetOutputPort("plan_stats").Eval(context)
    assert stats[0] == 3 and stats[1] == 2


def test_replans_come_closer_as_the_time_to_go_shrinks_and_carry_the_model_scales():
    """With time_to_go_fraction 0.4 the next re-plan is min(replan_period, max(period, 0.4 x time
    to go)) after the last (the plan in use ends at 2000 s): 100 s apart while more than 250 s
    remain, then 0.4 of the time to go, none with less than min_time_to_go left; each re-plan
    gets the "model_scales" input as ``scales``."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    calls = []

    def scripted_replan(plan, x, elapsed, bank, alpha, scales=None):
        calls.append((elapsed, scales))
        return None if len(calls) == 1 else _StubPlan(2.0, success=False, message="refused")

    builder = DiagramBuilder()
    guidance = builder.AddSystem(ReplanningGuidance(
        _StubPlan(1.0), replan=scripted_replan, period=1.0, replan_period=100.0, min_time_to_go=30.0,
        first_replan=1600.0, time_to_go_fraction=0.4, model_scales=True))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    scales = builder.AddSystem(ConstantVectorSource(np.array([1.05, 0.97])))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    builder.Connect(scales.get_output_port(), guidance.GetInputPort("model_scales"))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(2000.0)
    times = [t for t, _ in calls]
    # 1600 (400 to go) -> 1700 (300) -> 1800 (200: 80 s) -> 1880 (120: 48 s) -> 1928 (72: 28.8 s)
    # -> 1957 (43: 17.2 s) -> 1975 (25 to go: under min_time_to_go, no re-plan)
    assert times == [1600.0, 1700.0, 1800.0, 1880.0, 1928.0, 1957.0]
    assert all(s == (1.05, 0.97) for _, s in calls)
    memory = guidance.memory(guidance.GetMyContextFromRoot(simulator.get_context()))
    assert memory.refused[0] == (1600.0, "the re-planner returned no plan") and len(memory.refused) == 6


class _RampFeedback:
    """A tracking law stub: the offsets (bank, alpha) change at constant rates [rad/s]."""

    def __init__(self, plan):
        self.level = plan.level

    def rates(self, s, x, offsets):
        return np.array([0.01, -0.002]) * self.level


def test_feedback_offsets_integrate_clip_and_restart_with_each_accepted_replan():
    """Every 1-s period the offsets advance by rates x period (bank +0.01 rad/s, alpha -0.002
    rad/s for the plan of level 1), bounded by offset_limits (0.5, 0.05 rad); the commands are the
    plan's plus the offsets; the re-plan at 100 s is handed the commands flown (offsets included)
    and, accepted, starts its own offsets from zero (its rates doubled: level 2)."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    handed = []

    def scripted_replan(plan, x, elapsed, bank, alpha):
        handed.append((elapsed, bank, alpha))
        return _StubPlan(2.0)

    builder = DiagramBuilder()
    guidance = builder.AddSystem(ReplanningGuidance(
        _StubPlan(1.0), replan=scripted_replan, period=1.0, replan_period=100.0, min_time_to_go=1900.0,
        feedback=_RampFeedback, offset_limits=(0.5, 0.05)))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    simulator = Simulator(builder.Build())
    seen = {}
    for t in (10.5, 30.5, 99.5, 100.5, 110.5):
        simulator.AdvanceTo(t)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        seen[t] = (guidance.GetOutputPort("bank_command").Eval(context)[0],
                   guidance.GetOutputPort("alpha_command").Eval(context)[0])
    # updates at 0, 1, ..., 10: 11 steps by 10.5 s; alpha's offset reaches -0.05 after 25 steps
    assert seen[10.5] == pytest.approx((1.0 + 0.11, 0.2 - 0.022), abs=1e-12)
    assert seen[30.5] == pytest.approx((1.0 + 0.31, 0.2 - 0.05), abs=1e-12)
    assert seen[99.5] == pytest.approx((1.0 + 0.5, 0.2 - 0.05), abs=1e-12)
    # the update at 100 s advances the offsets (already at their bounds), then re-plans from them
    assert handed == [(100.0, pytest.approx(1.5, abs=1e-12), pytest.approx(0.15, abs=1e-12))]
    assert seen[100.5] == pytest.approx((2.0, 0.2), abs=1e-12)
    assert seen[110.5] == pytest.approx((2.0 + 10 * 0.02, 0.2 - 10 * 0.004), abs=1e-12)


def test_a_plan_whose_feedback_law_cannot_be_made_flies_on_its_own_and_is_counted():
    """The law maker returns None (e.g. a conjugate point of the costate law): the commands are the
    plan's alone, and the flight times at which such a plan began are recorded."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    builder = DiagramBuilder()
    guidance = builder.AddSystem(ReplanningGuidance(
        _StubPlan(1.0), replan=lambda *a: _StubPlan(2.0), period=1.0, replan_period=100.0, min_time_to_go=1900.0,
        feedback=lambda plan: None, offset_limits=(0.5, 0.05)))
    estimate = builder.AddSystem(ConstantVectorSource(np.array([60e3, 0.1, 0.2, 6000.0, -0.01, 1.0])))
    builder.Connect(estimate.get_output_port(), guidance.GetInputPort("estimated_state"))
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(50.5)
    context = guidance.GetMyContextFromRoot(simulator.get_context())
    assert guidance.GetOutputPort("bank_command").Eval(context)[0] == pytest.approx(1.0, abs=1e-15)
    simulator.AdvanceTo(100.5)
    context = guidance.GetMyContextFromRoot(simulator.get_context())
    assert guidance.GetOutputPort("bank_command").Eval(context)[0] == pytest.approx(2.0, abs=1e-15)
    assert guidance.memory(context).unfed == [0.0, 100.0]


def test_a_swarm_resolution_without_a_root_in_sigma0_re_solves_sigma_f(monkeypatch):
    """With end bounds, a sigma_0 re-solution that brackets no root (here at its 89-deg bound)
    is followed by the sigma_f re-solution with that sigma_0 held; both fly from then on (the
    sigma_f port), and a bracketed sigma_f counts as a good re-solution."""
    import math

    import drake_entry.systems.swarm_bank_guidance as swarm
    from drake_entry.guidance.swarm_bank.search import Resolution, problem_from_scenario
    from drake_entry.scenario import load_scenario

    problem = problem_from_scenario(load_scenario("cav_h_paper004"))
    held = []
    monkeypatch.setattr(swarm, "resolve_sigma0", lambda here, previous_deg, bounds_deg: Resolution(89.0, False, -9e3, 24))

    def end(here, sigma0_deg, bounds_deg):
        held.append((sigma0_deg, tuple(bounds_deg), math.degrees(here.sigma_f)))
        return Resolution(sigma0_deg, True, 0.0, 16, sigma_f_deg=72.5)

    monkeypatch.setattr(swarm, "resolve_bank_end", end)
    out = {}
    for bounds in ((20.0, 85.0), None):
        builder = DiagramBuilder()
        guidance = builder.AddSystem(swarm.SwarmBankGuidance(problem, math.radians(58.0), period=1.0,
                                                             replan_period=10.0, acceleration_scaling=False,
                                                             end_bounds_deg=bounds))
        for port, value in (("estimated_state", problem.x0),
                            ("flight_conditions", np.ones(len(FLIGHT_CONDITION_NAMES))), ("bank_command", [0.5])):
            builder.Connect(builder.AddSystem(ConstantVectorSource(np.asarray(value, float))).get_output_port(),
                            guidance.GetInputPort(port))
        simulator = Simulator(builder.Build())
        simulator.AdvanceTo(12.5)
        context = guidance.GetMyContextFromRoot(simulator.get_context())
        out[bounds] = [math.degrees(guidance.GetOutputPort(p).Eval(context)[0]) for p in ("sigma0", "sigma_f")] + [
            guidance.GetOutputPort("plan_stats").Eval(context)[1]]
    assert held == [(89.0, (20.0, 85.0), pytest.approx(60.0))]  # once, from the planned sigma_f
    assert out[(20.0, 85.0)] == pytest.approx([89.0, 72.5, 0.0])
    # without end bounds the best sigma_0 flies, the re-solution counted without a root, sigma_f planned
    assert out[None] == pytest.approx([89.0, 60.0, 1.0])
