"""Paper 002's terminal guidance (guidance/lgl_terminal): the scenario's problem, its design
margin, the re-solve mesh, the plan's flight verdict, and the spec's errors. The nominal closed
loop (plan, re-solves, impact) is flown once per session by example 14 (tests/test_examples.py);
the shared re-planning system's fall-back by tests/test_replan_fallback.py."""
import math

import numpy as np
import pytest

from drake_entry.errors import ScenarioError
from drake_entry.scenario import load_scenario


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("marv_guidance")


def test_the_problem_flown_is_the_scenarios_mission_with_the_files_conditions(scenario):
    """Entry state, target, vehicle, planet and atmosphere come from the scenario; the final speed
    and alpha, the bounds and the objective from problems/marv.yaml (eqs. 16-19); the final
    flight-path angle from the spec."""
    from drake_entry.planning.ocp_yaml import load_problem

    p = scenario.guidance.problem_for(scenario)
    file, _ = load_problem("marv")
    assert np.allclose([p.initial[k] for k in ("h", "lon", "lat", "V", "gamma", "psi")], scenario.initial_state())
    assert p.final["lon"] == pytest.approx(math.radians(25.15)) and p.final["lat"] == 0.0 and p.final["h"] == 0.0
    assert p.final["gamma"] == pytest.approx(math.radians(-80.0)) and file.final["gamma"] == pytest.approx(math.radians(-89.0))
    assert p.final["V"] == file.final["V"] == 1219.0 and p.final["alpha"] == 0.0
    assert p.planet.reference_radius == 6378145.0 and p.vehicle.mass / p.vehicle.reference_area == 1000.0
    assert p.state_bounds == file.state_bounds and p.control_bounds == file.control_bounds
    assert scenario.guidance.terminal_speed(300.0) == 1219.0  # the impact speed, not a Mach number


def test_path_constraints_are_planned_inside_the_bounds_the_verdict_checks(scenario):
    """q >= 12 kPa and a <= 45 g (eq. 18) are planned 8 % inside (12.96 kPa, 41.4 g); the verdict's
    mission limits are the file's bounds themselves."""
    planned = {c.label: c for c in scenario.guidance.problem_for(scenario).path}
    assert planned["dynamic_pressure"].min == pytest.approx(12e3 * 1.08)
    assert planned["sensed_acceleration"].max == pytest.approx(45.0 * 0.92)
    limits = {lim.name: lim for lim in scenario.path_limits()}
    assert limits["path_dynamic_pressure"].lower == 12e3 and limits["path_dynamic_pressure"].column == "dynamic_pressure"
    assert limits["path_sensed_acceleration"].upper == 45.0 and limits["path_sensed_acceleration"].column == "total_load"


def test_resolve_mesh_is_one_node_per_spacing_within_the_bounds(scenario):
    from drake_entry.guidance.lgl_terminal.planner import replan_nodes

    g = scenario.guidance  # 10 s per node, within [40, 60]
    assert [replan_nodes(g, h) for h in (700.0, 500.0, 450.0, 120.0, 5.0)] == [60, 51, 46, 40, 40]


def test_a_plan_flight_is_ok_only_inside_every_criterion_with_every_limit_held():
    from drake_entry.guidance.lgl_terminal.planner import PlanFlight
    from drake_entry.models.verdict import LimitCheck, PathLimit

    inside = {"distance": {"error": 90.0, "tolerance": 1000.0, "inside": True}}
    held = [LimitCheck(PathLimit("q", "dynamic_pressure", lower=12e3), 13e3, 500.0, 0.08, True)]
    assert PlanFlight(inside, held).ok
    missed = {**inside, "alpha": {"error": math.radians(3.0), "tolerance": math.radians(2.0), "inside": False}}
    assert not PlanFlight(missed, held).ok and "alpha error +3.00 deg outside +-2 deg" in PlanFlight(missed, held).text()
    breached = [LimitCheck(PathLimit("q", "dynamic_pressure", lower=12e3), 11.9e3, 560.0, -0.01, False)]
    assert not PlanFlight(inside, breached).ok and "path limits breached" in PlanFlight(inside, breached).text()
    assert not PlanFlight(inside, held, failure="stopped at t = 3 s").ok


@pytest.mark.parametrize("field, value, words", [
    ("solver", "cplex", "guidance.solver = 'cplex' is unknown; allowed: snopt, ipopt"),
    ("replan_nodes", [30, 20], "guidance.replan_nodes = [30, 20]; allowed [min, max]"),
    ("path_margin", 0.7, "guidance.path_margin"),
    ("final_flight_path_deg", -95.0, "guidance.final_flight_path_deg"),
    ("replan_period_s", 0.5, "replan_period_s = 0.5 is out of range; allowed: 0 "),
    ("problem", "no_such_problem", "no_such_problem"),
    ("feedback", "pid", "guidance.feedback = 'pid' is unknown; allowed: tvlqr, costate, none"),
    ("feedback_state_weight", 0.0, "guidance.feedback_state_weight"),
    ("feedback_alpha_limit_deg", 50.0, "guidance.feedback_alpha_limit_deg"),
])
def test_bad_spec_fields_are_named(scenario, field, value, words):
    import dataclasses as dc

    bad = dc.replace(scenario, guidance=dc.replace(scenario.guidance, **{field: value}))
    with pytest.raises(ScenarioError) as e:
        bad.validate()
    assert words in str(e.value)


def test_a_problem_with_direct_controls_is_refused(scenario, tmp_path):
    """The guidance flies alpha and sigma states: a 'direct' problem file is refused by name."""
    from importlib import resources

    text = resources.files("drake_entry").joinpath("problems/marv.yaml").read_text()
    head, rest = text.split("state_bounds:")
    text = (head.replace("controls: rates", "controls: direct").replace("  alpha_deg: {value: 0.0}", "")
            + "control_bounds: {alpha_deg: {min: 0.0, max: 25.0}, bank_deg: {min: -90.0, max: 90.0}}\n"
            + "objective: [{kind: heat_load}]\n")
    path = tmp_path / "direct.yaml"
    path.write_text(text)
    import dataclasses as dc

    bad = dc.replace(scenario, guidance=dc.replace(scenario.guidance, problem=str(path)))
    with pytest.raises(ScenarioError, match="controls must be 'rates'"):
        bad.validate()


def test_terminal_windows_need_their_centre():
    import dataclasses as dc

    s = load_scenario("marv_guidance")
    bad = dc.replace(s, terminal=dc.replace(s.terminal, flight_path_deg=None))
    with pytest.raises(ScenarioError, match="terminal.flight_path_tolerance_deg is given without terminal.flight_path_deg"):
        bad.validate()


def test_resolves_aim_at_windows_of_the_final_speed_and_flight_path_angle(scenario):
    """A re-solve's problem opens the fixed final speed and flight-path angle to the spec's
    windows (25 m/s, 2.5 deg) and keeps the final position and alpha fixed; opening twice changes
    nothing."""
    from drake_entry.guidance.lgl_terminal.planner import final_windows

    p = scenario.guidance.problem_for(scenario)
    w = final_windows(p, scenario.guidance)
    assert w.final["V"] == (1194.0, 1244.0)
    assert w.final["gamma"] == pytest.approx((math.radians(-82.5), math.radians(-77.5)))
    assert all(w.final[k] == p.final[k] for k in ("h", "lon", "lat", "alpha"))
    assert final_windows(w, scenario.guidance).final == w.final


def test_feedback_kinds_map_to_the_plans_laws():
    """'none' gives no law maker; 'tvlqr' and 'costate' ask the plan for that law."""
    from drake_entry.guidance.lgl_terminal.planner import feedback_maker

    class Plan:
        def feedback(self, kind):
            return f"law {kind}"

    assert feedback_maker("none") is None
    assert feedback_maker("tvlqr")(Plan()) == "law tvlqr" and feedback_maker("costate")(Plan()) == "law costate"
