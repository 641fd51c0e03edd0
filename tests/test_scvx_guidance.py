"""Paper 001's SCvx as a registered guidance method (``guidance: !Scvx``): the spec's errors,
the mission it builds from the scenario and the guidance system against its plan (the closed
loop and a campaign: example 09's test)."""
import dataclasses as dc

import pytest

from drake_entry.errors import ScenarioError
from drake_entry.scenario import load_scenario


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("sphynx_paper001")


@pytest.fixture(scope="module")
def setup(scenario):
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup

    return ClosedLoopSetup.from_scenario(scenario)


@pytest.mark.parametrize("field, value, match", [
    ("formulation", "polar", "guidance.formulation = .polar.; allowed: lossless, hybrid, direct_bank, direct"),
    ("final_altitude_m", [13e3, 10e3], r"guidance.final_altitude_m = \(13000.0, 10000.0\) needs two values"),
    ("site_radius_m", -1.0, r"guidance.site_radius_m = -1.0 is out of range"),
    ("segments", 0, r"guidance.segments = 0 must be an integer in \[1, 2000\]"),
    ("terminal_mach", 1.5, "guidance.terminal_mach = 1.5 exceeds guidance.final_mach_max = 1.0"),
    ("replan_period_s", 0.5, "guidance.replan_period_s = 0.5 is out of range; allowed: 0 "),
    ("solver", "ecos", "guidance.solver = 'ecos'; allowed: clarabel, scs"),
])
def test_spec_names_the_bad_field_and_its_allowed_values(scenario, field, value, match):
    bad = dc.replace(scenario, guidance=dc.replace(scenario.guidance, **{field: value}))
    with pytest.raises(ScenarioError, match=match):
        bad.guidance.validate(bad)


@pytest.mark.parametrize("solver, defect_tolerance", [("clarabel", 1e-6), ("scs", 1e-5)])
def test_spec_gives_each_solver_its_scvx_tolerances(scenario, solver, defect_tolerance):
    spec = dc.replace(scenario.guidance, solver=solver, max_iterations=70)
    settings = spec.planner_settings()[1]
    assert (settings.solver, settings.max_iterations, settings.defect_tolerance) == (solver, 70, defect_tolerance)


def test_mission_of_the_scenario_is_paper001_table1(scenario):
    """The scenario's geocentric entry and target convert back to Table 1's geodetic figures."""
    m = scenario.guidance.mission(scenario)
    assert m.entry_altitude_m == pytest.approx(120e3, abs=1e-3)
    assert m.entry_latitude_deg == pytest.approx(30.0, abs=1e-9)
    assert m.site_latitude_deg == pytest.approx(36.974, abs=1e-9)
    assert (m.entry_speed_m_s, m.entry_flight_path_deg, m.entry_heading_deg) == pytest.approx((7643.7, -1.29, 43.04))
    assert m.final_altitude_m == (10e3, 13e3) and m.site_radius_m == 10e3


def test_guidance_system_serves_the_plan_bank_and_alpha(setup):
    """The system's commands are the plan's own bank and (direct formulation) alpha at the
    flight time, held after its end."""
    from drake_entry.systems.replanning_guidance import ReplanningGuidance

    plan = setup.planner
    system = ReplanningGuidance(plan)
    context = system.CreateDefaultContext()
    for t in (0.0, 400.0, 0.5 * plan.final_time, plan.final_time + 50.0):
        context.SetTime(t)
        x = plan.evaluate(t)
        system.GetInputPort("estimated_state").FixValue(context, [x[k][0] for k in ("h", "lon", "lat", "V", "gamma", "psi")])
        assert system.GetOutputPort("bank_command").Eval(context)[0] == pytest.approx(x["bank"][0], abs=2e-3)
        assert system.GetOutputPort("alpha_command").Eval(context)[0] == pytest.approx(x["alpha"][0], abs=1e-3)
    assert list(system.GetOutputPort("plan_stats").Eval(context)) == [0.0, 0.0, 0.0]


# The nominal closed loop (re-planned, plan alone, without the lead) and a campaign of the
# scenario's dispersions are flown once per session, by example 09 (tests/test_examples.py).
