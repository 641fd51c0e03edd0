"""Paper 002's terminal guidance (guidance/lgl_terminal): the scenario's problem, its design
margin, the re-solve mesh, the plan's flight verdict, and the spec's errors. The nominal closed
loop (plan, re-solves, impact) is flown once per session by example 14 (tests/test_examples.py);
the shared re-planning system's fall-back by tests/test_replan_fallback.py."""
import dataclasses as dc
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
    and alpha, the bounds and the objective from problems/marv.yaml (eqs. 16-19), the bank within
    the vehicle's limit; the final flight-path angle from the spec."""
    from drake_entry.planning.ocp_yaml import load_problem

    p = scenario.guidance.problem_for(scenario)
    file, _ = load_problem("marv")
    assert np.allclose([p.initial[k] for k in ("h", "lon", "lat", "V", "gamma", "psi")], scenario.initial_state())
    assert p.final["lon"] == pytest.approx(math.radians(25.15)) and p.final["lat"] == 0.0 and p.final["h"] == 0.0
    assert p.final["gamma"] == pytest.approx(math.radians(-80.0)) and file.final["gamma"] == pytest.approx(math.radians(-89.0))
    assert p.final["V"] == file.final["V"] == 1219.0 and p.final["alpha"] == 0.0
    assert p.planet.reference_radius == 6378145.0 and p.vehicle.mass / p.vehicle.reference_area == 1000.0
    assert p.state_bounds["alpha"] == file.state_bounds["alpha"] and p.control_bounds == file.control_bounds
    # the bank within the actuator's limit (180 deg), not the file's +-360 deg: a plan that banks
    # 268.9 deg means -91.1 deg, and the actuator would fly 180
    assert file.state_bounds["sigma"] == pytest.approx((-2 * math.pi, 2 * math.pi))
    assert p.state_bounds["sigma"] == pytest.approx((-math.pi, math.pi)) == (-p.vehicle.bank_limit, p.vehicle.bank_limit)
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
    four = dc.replace(g, segments=4, nodes=81)  # rounded up to a count 4 segments of >= 3 nodes share
    assert [replan_nodes(four, h) for h in (700.0, 500.0, 450.0, 120.0, 5.0)] == [61, 53, 49, 41, 41]
    assert all((n - 1) % 4 == 0 for n in (replan_nodes(four, h) for h in np.linspace(0.0, 900.0, 91)))


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
    early = PlanFlight({"distance": {"error": 2e5, "tolerance": 5e3, "inside": False}}, held, interface_early_s=97.5)
    assert not early.ok and early.text().startswith(
        "flown through the actuators: it meets the terminal altitude 97.5 s before the plan's end")


def test_a_plan_flight_is_judged_where_it_first_meets_the_terminal_altitude():
    """The closed loop stops at the first descent through the terminal altitude: a plan whose
    flight dips through it before its end is judged there (interpolated), not at its t_f."""
    from drake_entry.guidance.lgl_terminal.planner import interface_crossing
    from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
    from drake_entry.models.trajectory import Trajectory

    t = np.linspace(0.0, 100.0, 101)
    h = 28e3 + 1e3 * np.cos(np.pi * t / 50.0) - 50.0 * t / 100.0  # 29 km, under 28 km near t = 50 s, up again
    state = np.column_stack([h, 1e-4 * t, np.zeros_like(t), 2500.0 - 5.0 * t, np.zeros((t.size, 2))])
    conditions = np.zeros((t.size, len(FLIGHT_CONDITION_NAMES)))
    conditions[:, FLIGHT_CONDITION_NAMES.index("mach")] = 8.0 - 0.05 * t
    tr = Trajectory(time=t, state=state, conditions=conditions, bank=np.zeros_like(t), alpha=np.full_like(t, 0.2),
                    reason="t_f", wall_time=0.0)
    x, mach, alpha, t_stop = interface_crossing(tr, 28e3)
    exact = 50.0 / np.pi * np.arccos(0.0)  # cos(pi t / 50) = 0 less the small linear term: just before 25 s
    assert 24.0 < t_stop < exact and x[0] == pytest.approx(28e3, abs=1.0)
    assert x[1] == pytest.approx(1e-4 * t_stop, rel=1e-9) and mach == pytest.approx(8.0 - 0.05 * t_stop, rel=1e-9)
    assert alpha == pytest.approx(0.2)
    x_end, _, _, t_end = interface_crossing(tr, 26e3)  # never that low: judged at its end
    assert t_end == 100.0 and x_end[0] == h[-1]
    # the altitude the stop reads (geodetic): 2 km above the state altitude, it crosses 30 km where h does 28 km
    x_geo, _, _, t_geo = interface_crossing(tr, 30e3, h + 2e3)
    assert t_geo == pytest.approx(t_stop, rel=1e-12) and x_geo[0] == pytest.approx(x[0], rel=1e-12)


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
    ("segments", 0, "guidance.segments = 0 is out of range"),
    ("segments", 4, "guidance.nodes = 80 with guidance.segments = 4: guidance.nodes - 1 must be a multiple of "
                    "guidance.segments with at least 3 nodes per segment; allowed near it: 77 or 81"),
    ("segments", 3, "guidance.nodes = 80 with guidance.segments = 3: guidance.nodes - 1 must be a multiple of "
                    "guidance.segments with at least 3 nodes per segment; allowed near it: 79 or 82"),
    ("segments", 40, "guidance.nodes = 80 with guidance.segments = 40: guidance.nodes - 1 must be a multiple of "
                     "guidance.segments with at least 3 nodes per segment; allowed near it: 81"),
    ("segments", 41, "guidance.segments = 41 is out of range"),
    ("snopt_scale_option", 3, "guidance.snopt_scale_option = 3; allowed 0 (none), 1 (linear constraints and "
                              "variables), 2 (all)"),
])
def test_bad_spec_fields_are_named(scenario, field, value, words):
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
    bad = dc.replace(scenario, guidance=dc.replace(scenario.guidance, problem=str(path)))
    with pytest.raises(ScenarioError, match="controls must be 'rates'"):
        bad.validate()


def test_terminal_windows_need_their_centre():
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


# -- the problem a mission poses (problem: mission) --------------------------------------------
@pytest.fixture(scope="module")
def horus_derived():
    """HORUS-2B's mission with the LGL settings derived from it."""
    from drake_entry.guidance.derivation import derivation_for
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal

    mission = load_scenario("horus2b")
    derivation = derivation_for(mission, LglTerminal)
    return dc.replace(mission, guidance=derivation.spec).validate(), derivation


def test_a_mission_poses_its_own_terminal_problem(horus_derived):
    """Entry state to the box's altitude over the target, alpha within the mission's schedule, the
    bank within the vehicle's limit and rate, the vehicle's limits planned 8 % inside, eq. 11."""
    from drake_entry.guidance.lgl_terminal.mission import GAMMA_BOUNDS_DEG, without_interface_floor

    s, _ = horus_derived
    g, v = s.guidance, s.make_vehicle()
    p = g.problem_for(s)
    assert g.problem == "mission" and p.controls == "rates"
    assert (g.nodes, g.segments) == (81, 4)  # the derivation's: 4 LGL segments of 21 nodes
    assert np.allclose([p.initial[k] for k in ("h", "lon", "lat", "V", "gamma", "psi")], s.initial_state())
    assert p.final["h"] == 25e3 and p.final["V"] == g.terminal_velocity_m_s
    # the box checks no flight-path angle: the plan ends descending at least 1 deg (FINAL_DESCENT_DEG)
    assert g.final_flight_path_deg is None and g.final_descent_deg == 1.0
    assert np.degrees(p.final["gamma"]) == pytest.approx((GAMMA_BOUNDS_DEG[0], -1.0))
    assert (p.final["lon"], p.final["lat"]) == pytest.approx((math.radians(s.target.longitude_deg),
                                                              math.radians(s.target.latitude_deg)))
    assert np.degrees(p.state_bounds["alpha"]) == pytest.approx([15.0, 40.0])  # the mission's schedule
    assert p.state_bounds["sigma"] == pytest.approx((-v.bank_limit, v.bank_limit))
    assert np.degrees(p.state_bounds["gamma"]) == pytest.approx(GAMMA_BOUNDS_DEG)
    # never below the terminal altitude, where the closed loop stops, before the end
    assert p.state_bounds["h"] == (25e3, math.inf) and p.bounds_arrays()[0][0] == 25e3
    assert p.control_bounds["u_sigma"] == pytest.approx((-v.bank_rate_limit, v.bank_rate_limit))
    assert p.control_bounds["u_alpha"] == pytest.approx((-math.radians(2.0), math.radians(2.0)))
    floor = [c for c in p.path if c.label == "interface_floor"]
    assert len(floor) == 1 and floor[0].min == 0.0
    s_far = (6000.0 - g.terminal_velocity_m_s) / 100.0
    for V, above in ((g.terminal_velocity_m_s, 0.0), (g.terminal_velocity_m_s + 100.0, 150.0),
                     (6000.0, 300.0 * s_far ** 2 / (1.0 + s_far ** 2))):  # 300 m s^2 / (1 + s^2), s = dV / 100
        x = np.array([25e3 + above, 0.0, 0.0, V, 0.0, 0.0, 0.3, 0.0])
        assert floor[0].quantity(x, None, None) == pytest.approx(0.0, abs=1e-9)
        x[0] -= 1.0
        assert floor[0].quantity(x, None, None) == pytest.approx(-1.0, abs=1e-9)
    # the pre-flight plan's first solve drops the floor alone; a problem without one is kept
    relaxed = without_interface_floor(p)
    assert [c.label for c in relaxed.path] == [c.label for c in p.path if c.label != "interface_floor"]
    assert len(relaxed.path) == len(p.path) - 1 and relaxed.state_bounds == p.state_bounds
    assert without_interface_floor(relaxed) is relaxed
    planned = {c.label: c.max for c in p.path if c.label != "interface_floor"}
    assert planned == pytest.approx({"heat_flux": 0.92 * v.limits.heat_flux_max,
                                     "dynamic_pressure": 0.92 * v.limits.dynamic_pressure_max,
                                     "normal_load": 0.92 * v.limits.normal_load_max})
    assert [t.kind for t in p.objective] == ["control_margin"] and p.objective[0].k == (1.0, 18.0, 20.0)
    assert s.guidance.path_limits(s) == []  # its constraints are the vehicle's limits, checked anyway
    assert s.guidance.terminal_speed(300.0) == g.terminal_velocity_m_s


def test_a_mission_with_geodetic_altitudes_plans_and_floors_the_geodetic_terminal_altitude():
    """SHEFEX-3's altitudes are geodetic (altitude_datum 'ellipsoid'), as the closed loop's stop
    reads them: the plan ends at the state altitude whose geodetic altitude at the target is the
    terminal altitude (23.5 km geodetic is a 5.1-km state altitude at 68.1 N; the state altitude
    23.5 km is 41.9 km geodetic there), and the interface floor reads the geodetic altitude."""
    from drake_entry.guidance.derivation import derivation_for
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal

    mission = load_scenario("shefex3_ampi")
    s = dc.replace(mission, guidance=derivation_for(mission, LglTerminal).spec).validate()
    planet, h_f = s.make_planet(), s.guidance.terminal_altitude_km * 1e3
    p = s.guidance.problem_for(s)
    lat_f = math.radians(s.target.latitude_deg)
    assert h_f == 23.5e3 and p.final["lat"] == lat_f
    assert float(planet.atmospheric_altitude(p.final["h"], lat_f)) == pytest.approx(h_f, abs=1e-6)
    assert 4.5e3 < p.final["h"] < 5.5e3
    # the state bound: the geodetic floor's lowest state altitude between the entry's and the target's latitude
    lat0 = p.initial["lat"]
    assert abs(lat0) > abs(lat_f)  # flying from 71.9 N to 68.1 N: the entry's latitude gives the lower bound
    assert p.state_bounds["h"][0] == pytest.approx(float(planet.state_altitude(h_f, lat0)), abs=1e-6)
    assert p.state_bounds["h"][0] < p.final["h"]
    floor = next(c for c in p.path if c.label == "interface_floor")
    for lat in (lat0, lat_f):
        x = np.array([float(planet.state_altitude(h_f, lat)), 0.0, lat, s.guidance.terminal_velocity_m_s, 0.0, 0.0,
                      0.3, 0.0])
        assert floor.quantity(x, None, None) == pytest.approx(0.0, abs=1e-6)


def test_the_derived_final_speed_stays_below_the_planned_dynamic_pressure(horus_derived):
    """HORUS-2B's box centre (Mach 2.5 at 25 km) is 11 kPa against its 10 kPa limit: each candidate
    altitude ends below Q_SPEED_FRACTION of the speed where 0.92 of the limit is met, inside the box."""
    from drake_entry.guidance.derivation import Q_SPEED_FRACTION

    s, derivation = horus_derived
    atmosphere, q_max = s.make_atmosphere(), s.make_vehicle().limits.dynamic_pressure_max
    (step,) = derivation.search
    assert [c["guidance.terminal_altitude_km"] for c in step.candidates] == [25.0, 25.5, 26.0, 26.5, 24.5, 24.0]
    for c in step.candidates:
        h, V = c["guidance.terminal_altitude_km"] * 1e3, c["guidance.terminal_velocity_m_s"]
        q = 0.5 * float(atmosphere.density(h)) * V ** 2
        assert q == pytest.approx(Q_SPEED_FRACTION ** 2 * 0.92 * q_max, rel=1e-5)
        assert 2.0 <= V / float(atmosphere.speed_of_sound(h)) <= 2.5  # the box's Mach window, below its centre


def test_the_derived_final_speed_keeps_the_last_node_under_the_load_bound_with_dispersed_forces():
    """Paper 004's CAV-H at its 30 km, 2000 m/s interface is over 0.92 x 2 g at alpha 19 deg with the
    3-sigma forces a re-solve may sense (its last node is fixed): each candidate's speed is capped
    where that load, computed here from the aerodynamic model, meets the planned bound; where the
    cap is above the box's 2000 m/s the centre speed stays."""
    from drake_entry.guidance.derivation import FORCE_SIGMAS, derivation_for
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal
    from drake_entry.models.dispersions import force_ratio_high
    from drake_entry.models.planet import G0

    mission = load_scenario("cav_h_paper004")
    vehicle, atmosphere = mission.make_vehicle(), mission.make_atmosphere()
    force_high = force_ratio_high(mission.dispersions, FORCE_SIGMAS)
    derivation = derivation_for(mission, LglTerminal)
    (step,) = derivation.search
    assert derivation.spec.alpha_bounds_deg == [19.0, 21.0]

    def load_g(h, V):
        CL, CD = vehicle.aero.coefficients(math.radians(19.0), V / float(atmosphere.speed_of_sound(h)))
        return 0.5 * float(atmosphere.density(h)) * V ** 2 * vehicle.area_over_mass * math.hypot(CL, CD) / G0

    assert load_g(30e3, 2000.0) * force_high > 0.92 * 2.0  # the box centre is beyond the bound
    capped = 0
    for c in step.candidates:
        h, V = c["guidance.terminal_altitude_km"] * 1e3, c["guidance.terminal_velocity_m_s"]
        if V < 2000.0:
            capped += 1
            assert load_g(h, V) * force_high == pytest.approx(0.92 * 2.0, rel=1e-4)
        else:
            assert load_g(h, V) * force_high <= 0.92 * 2.0
    assert capped == 5  # 31.5 km meets the bound above 2000 m/s
    lu = derivation_for(load_scenario("cav_h_fnpeg"), LglTerminal).search[0]
    assert {c["guidance.terminal_velocity_m_s"] for c in lu.candidates} == {2000.0}  # far from its load bound


def test_a_mission_whose_box_is_beyond_the_dynamic_pressure_or_load_limit_cannot_be_flown():
    from drake_entry.guidance.derivation import CannotFly, derivation_for
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal
    from drake_entry.scenario import apply_overrides

    s = load_scenario("horus2b")
    apply_overrides(s, {"vehicle_limits": "{dynamic_pressure_max_kPa: 5.0}"})
    with pytest.raises(CannotFly, match=r"at 24 km the vehicle's dynamic-pressure limit, planned at 0.92 of it, is met "
                                        r"at \d+ m/s, below the box's 597 m/s"):
        derivation_for(s, LglTerminal)
    s = load_scenario("horus2b")
    apply_overrides(s, {"vehicle_limits": "{normal_load_max_g: 0.5}"})
    with pytest.raises(CannotFly, match=r"at 24 km the vehicle's load limit, planned at 0.92 of it with forces 1 x the "
                                        r"nominal at alpha 15 deg, is met at 2\d\d m/s, below the box's 597 m/s"):
        derivation_for(s, LglTerminal)


@pytest.mark.parametrize("field, value, words", [
    ("terminal_velocity_m_s", None, "guidance.terminal_velocity_m_s is needed with problem: mission"),
    ("alpha_bounds_deg", [20.0], "guidance.alpha_bounds_deg = [20.0]: with problem: mission give [min, max]"),
    ("alpha_bounds_deg", [30.0, 10.0], "with -90 <= min < max <= 90 deg"),
    ("alpha_rate_deg_s", 0.0, "guidance.alpha_rate_deg_s"),
    ("final_descent_deg", 50.0, "guidance.final_descent_deg = 50"),
    ("final_flight_path_deg", -5.0, "guidance.final_descent_deg = 1 with final_flight_path_deg = -5: give one of them"),
])
def test_bad_mission_problem_fields_are_named(horus_derived, field, value, words):
    s, _ = horus_derived
    with pytest.raises(ScenarioError) as e:
        dc.replace(s, guidance=dc.replace(s.guidance, **{field: value})).validate()
    assert words in str(e.value)


@pytest.mark.slow  # an 81-node SNOPT solve in 4 segments and its verification flights: about 40 s of a core
def test_the_derived_horus_plan_is_verified_flown_with_its_feedback(horus_derived):
    """The plan solved on HORUS-2B's own mission is verified (between the nodes and propagated)
    and, flown through the closed loop's actuators with the TVLQR it flies between re-solves, ends
    inside the 2-km box (measured 4.7 m); the same plan flown open loop ended 3.6 km away."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.lgl_terminal.planner import plan_terminal

    s, _ = horus_derived
    plan = plan_terminal(s, fly_controls, progress=False)
    assert plan.result.success and plan.success, plan.message
    assert plan.flight.box["distance"]["error"] < 200.0 and all(c.held for c in plan.flight.checks)


@pytest.mark.slow  # two 81-node SNOPT solves in 4 segments and their verification flights: about 60 s of a core
def test_a_plan_meeting_the_interface_early_is_solved_again_with_the_floor(monkeypatch):
    """Lu 2014's CAV-H at its derived interface (28 km, 2000 m/s): solved without the interface
    floor the plan rides 28 km and its flight meets it before the plan's end, so it is refused
    there; solved again with the floor from it, it meets 28 km only at its end, inside the box
    (measured 0.9 m from the target). HORUS-2B's plan is kept from the first solve (the test above)."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.derivation import derivation_for
    from drake_entry.guidance.lgl_terminal import planner
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal

    mission = load_scenario("cav_h_fnpeg")
    derivation = derivation_for(mission, LglTerminal)
    s = dc.replace(mission, guidance=derivation.spec)
    if derivation.alpha is not None:
        s.alpha = dc.replace(derivation.alpha)
    s.validate()
    original, judged = planner.judged, []

    def recording(*args):
        judged.append(original(*args))
        return judged[-1]

    monkeypatch.setattr(planner, "judged", recording)
    plan = planner.plan_terminal(s, fly_controls, progress=False)
    floors = [any(c.label == "interface_floor" for c in p.result.problem.path) for p in judged]
    assert floors == [False, True]
    first = judged[0]
    assert not first.success and first.flight.interface_early_s > 10.0, first.message
    assert "before the plan's end" in first.message
    assert plan is judged[1] and plan.success, plan.message
    assert plan.flight.interface_early_s == 0.0 and plan.flight.box["distance"]["error"] < 100.0


@pytest.mark.parametrize("converged, solved_on", [(False, [4, 1]), (True, [4])])
def test_a_pre_flight_plan_whose_segments_do_not_converge_is_solved_on_one_polynomial(horus_derived, monkeypatch,
                                                                                     converged, solved_on):
    """The spec's 4 segments first; only when they do not converge, one polynomial of the same
    nodes (each solve without the interface floor: it is added only for a plan meeting the
    terminal altitude early)."""
    import types

    from drake_entry.guidance.lgl_terminal import planner
    from drake_entry.planning import nlp

    s, _ = horus_derived
    calls = []

    def solve(problem, **kw):
        calls.append((kw["segments"], kw["nodes"], [c.label for c in problem.path], kw["refine"]))
        return types.SimpleNamespace(success=False, converged=converged and kw["segments"] == 4,
                                     message="not solved: SNOPT: major iteration limit reached (info 32)")

    monkeypatch.setattr(nlp, "solve", solve)
    plan = planner.plan_terminal(s, lambda *a, **k: None, progress=False)
    assert [c[0] for c in calls] == solved_on and all(c[1] == 81 for c in calls)
    assert all("interface_floor" not in c[2] for c in calls) and not plan.success
    assert all(c[3] is True for c in calls)  # the mesh refined from the spec's nodes (refine_mesh)
    calls.clear()
    planner.plan_terminal(dc.replace(s, guidance=dc.replace(s.guidance, refine_mesh=False)), lambda *a, **k: None,
                          progress=False)
    assert calls and all(c[3] is False for c in calls)


def test_a_resolve_in_denser_air_holds_q_and_the_heat_rate_there():
    """sensed_path: with lift and drag sensed 1.21 and 1.21 times the models' (air 21 % denser)
    the q bound is divided by 1.21 and the heat-rate bound by 1.1; the load and a terminal-like
    callable constraint are kept; thinner air keeps every bound."""
    from drake_entry.guidance.lgl_terminal.planner import sensed_path
    from drake_entry.planning.ocp import PathConstraint

    path = [PathConstraint("heat_flux", max=5e5), PathConstraint("dynamic_pressure", max=3e4),
            PathConstraint("total_load", max=3.0), PathConstraint(lambda x, u, env: x[0], max=1.0, name="h")]
    dense = sensed_path(path, (1.21, 1.21))
    assert dense[0].max == pytest.approx(5e5 / 1.1, rel=1e-14)
    assert dense[1].max == pytest.approx(3e4 / 1.21, rel=1e-14)
    assert dense[2] == path[2] and dense[3] is path[3]
    assert sensed_path(path, (0.8, 0.9)) == path


def test_a_resolve_plans_a_bound_its_measured_state_already_passes_halfway_to_the_vehicles_own():
    """measured_path: a bound the state at the re-solve passes (its planned margin spent) is
    planned halfway from the planned bound to the vehicle's (MEASURED_MARGIN_FRACTION), or at the
    value when past that too; a lower bound likewise; the rest as planned (the same objects)."""
    from drake_entry.guidance.lgl_terminal.planner import MEASURED_MARGIN_FRACTION, measured_path
    from drake_entry.planning.ocp import PathConstraint

    limits = [PathConstraint("heat_flux", max=5e5), PathConstraint("dynamic_pressure", min=1.2e4),
              PathConstraint("normal_load", max=2.5)]
    planned = [PathConstraint("heat_flux", max=4.6e5), PathConstraint("dynamic_pressure", min=1.296e4),
               PathConstraint("normal_load", max=2.3)]
    inside = measured_path(planned, limits, [4.0e5, 1.5e4, 2.0])
    assert all(a is b for a, b in zip(inside, planned))
    assert MEASURED_MARGIN_FRACTION == 0.5
    spent = measured_path(planned, limits, [4.7e5, 1.26e4, 2.35])  # past the margins, not halfway to the limits
    assert [c.max for c in spent] == pytest.approx([4.8e5, math.inf, 2.4], rel=1e-14)
    assert spent[1].min == pytest.approx(1.248e4, rel=1e-14)
    beyond = measured_path(planned, limits, [4.9e5, 1.22e4, 2.45])  # past halfway: at the value
    assert [c.max for c in beyond] == [4.9e5, math.inf, 2.45] and beyond[1].min == 1.22e4
    past = measured_path(planned, limits, [5.1e5, 1.1e4, 2.0])  # past the limits themselves
    assert past[0].max == 5.1e5 and past[1].min == 1.1e4 and past[2] is planned[2]
    assert [c.label for c in past] == [c.label for c in planned]


@pytest.mark.slow  # HORUS-2B's derived plan and 14 re-solves: about 60 s of a core
def test_resolves_from_a_dispersed_horus_flight_hold_their_bounds_from_the_pre_flight_problem(horus_derived):
    """Every re-solve of a dispersed HORUS-2B flight plans from the pre-flight problem's bounds
    held in the air it senses (never a previous re-solve's: they compounded, 9200 -> 9102 Pa over
    4 accepted re-solves), and none is refused for a bound its first node passes."""
    from drake_entry.campaign.sample import run_sample
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup
    from drake_entry.guidance.lgl_terminal import planner as lgl
    from drake_entry.models.acceleration_ratios import sensed_limit_factors

    s, derivation = horus_derived
    s = dc.replace(s, guidance=dc.replace(s.guidance, terminal_altitude_km=25.5,
                                          terminal_velocity_m_s=derivation.search[0].candidates[1][
                                              "guidance.terminal_velocity_m_s"]))
    planned_q = s.guidance.problem_for(s).path[1].max
    seen = []
    original = lgl.replan

    def recorded(previous, x, elapsed, bank, alpha, scales=None):
        plan = original(previous, x, elapsed, bank, alpha, scales)
        q = plan.result.problem.path[1]
        seen.append((q.max, planned_q / sensed_limit_factors(scales)["dynamic_pressure"], plan.message))
        return plan

    import drake_entry.guidance.lgl_terminal.method as method
    try:
        lgl.replan = method.replan = recorded
        row, _ = run_sample(ClosedLoopSetup.from_scenario(s), 2026, 3, trajectory_step_s=0)
    finally:
        lgl.replan = method.replan = original
    assert row["success"] and len(seen) >= 10
    for q_max, expected, message in seen:
        assert q_max == pytest.approx(expected, rel=1e-12) or q_max >= expected, message
        assert "largest violation" not in message or "at node 0" not in message, message


def test_a_least_final_descent_is_refused_on_a_problem_file():
    """MaRV's problem file states its own final conditions: final_descent_deg is named as a field
    of problem: mission."""
    s = load_scenario("marv_guidance")
    with pytest.raises(ScenarioError, match="guidance.final_descent_deg is a field of problem: mission"):
        dc.replace(s, guidance=dc.replace(s.guidance, final_flight_path_deg=None, final_descent_deg=1.0)).validate()
