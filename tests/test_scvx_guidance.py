"""Paper 001's SCvx as a registered guidance method (``guidance: !Scvx``): the spec's errors,
the mission it builds from the scenario and the guidance system against its plan (the closed
loop and a campaign: example 09's test)."""
import dataclasses as dc
import math

import numpy as np
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
    assert m.final_altitude_m == (10e3, 13e3) and m.site_radius_m == 9.5e3  # 500 m inside eq. 69, the box judges 10 km


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


def test_scvx_derived_for_horus2b_ends_its_plans_where_the_flight_stops_below_the_dynamic_pressure_limit():
    """On HORUS-2B's mission SCvx plans to the box's centre altitude (the flight's stop), within
    50 m of it, inside the box's Mach window and below the Mach number where 10 kPa is met there
    (25 km at Mach 2.5 would be 11 kPa); each searched altitude likewise; it tracks its plans
    between re-plans and keeps the shared limit margin."""
    import math

    from drake_entry.guidance.derivation import LIMIT_MARGIN, derivation_for
    from drake_entry.guidance.scvx.spec import Scvx

    mission = load_scenario("horus2b")
    t = mission.terminal
    d = derivation_for(mission, Scvx)
    spec = d.spec
    assert spec.terminal_altitude_km == t.altitude_km == 25.0
    assert spec.feedback == "tvlqr" and spec.objective == "control_effort"
    assert spec.path_margin == pytest.approx(1.0 - LIMIT_MARGIN)
    atmosphere, q_max = mission.make_atmosphere(), mission.make_vehicle().limits.dynamic_pressure_max
    assert q_max == 10e3
    candidates = d.search[0].candidates
    assert len(candidates) >= 4
    for c in candidates:
        h = c["guidance.terminal_altitude_km"]
        lo, hi = c["guidance.final_altitude_m"]
        assert t.altitude_km - t.altitude_tolerance_km <= lo / 1e3 < h < hi / 1e3 <= t.altitude_km + t.altitude_tolerance_km
        assert hi - lo - 2.0 * c["guidance.final_altitude_margin_m"] == pytest.approx(20.0)  # the aim: h +- 10 m
        q_mach = math.sqrt(2.0 * q_max / float(atmosphere.density(h * 1e3))) / float(atmosphere.speed_of_sound(h * 1e3))
        assert t.mach - t.mach_tolerance <= c["guidance.final_mach_min"] < c["guidance.final_mach_max"] < q_mach
        assert c["guidance.final_mach_min"] <= c["guidance.terminal_mach"] <= c["guidance.final_mach_max"]
        # the flown plan is judged up to the q-limited window it aims inside, plus half its own width
        window = c["guidance.final_mach_max"] - c["guidance.final_mach_min"]
        assert c["guidance.final_mach_max"] + c["guidance.flown_mach_margin"] == pytest.approx(
            min(t.mach + t.mach_tolerance, q_mach) + 0.5 * window, abs=2e-4)
    assert q_mach < t.mach + t.mach_tolerance


def test_an_scvx_plan_flown_with_its_tracking_law_ends_where_it_planned_and_open_loop_does_not():
    """HORUS-2B's derived SCvx plan, flown by the Drake verifier through the closed loop's
    actuators with the TVLQR feedback the guidance flies between re-plans, ends 0.29 km from its
    terminal point and is verified; its same controls without the feedback drift 36.8 km over
    the 1500-s glide (the actuators' lag alone)."""
    from drake_entry.comparison.derive import apply_derivation
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.derivation import derivation_for
    from drake_entry.guidance.scvx.method import METHOD
    from drake_entry.guidance.scvx.planner import PROPAGATION_TOLERANCE_M, flown_check, plan_controls
    from drake_entry.guidance.scvx.spec import Scvx
    from drake_entry.planning.verification import EntryControls

    mission = load_scenario("horus2b")
    plan = METHOD.make_planner(apply_derivation(mission, derivation_for(mission, Scvx)), fly_controls)
    assert plan.success, plan.message
    assert plan.flight.feedback == "tvlqr" and plan.propagated_error_m < 0.2 * PROPAGATION_TOLERANCE_M
    assert plan.flown.within_limits and plan.flown.drs_ok
    assert plan.peaks["heat_flux_W_m2"] <= 530e3 and plan.metrics["max_dynamic_pressure_kPa"] <= 10.0
    open_loop = flown_check(plan, fly_controls(plan_controls(plan, dc.replace(plan.flight, feedback="none"))))
    assert open_loop.from_plan_m > 4 * PROPAGATION_TOLERANCE_M
    controls = plan_controls(plan, plan.flight)
    with pytest.raises(ScenarioError, match="tracking needs an actuation"):
        dc.replace(controls, actuation=None)
    assert isinstance(controls, EntryControls)


def test_scvx_derived_where_the_box_checks_no_speed_aims_at_the_interface_speed_and_replans_near_the_end():
    """Lu 2014's box checks altitude and distance only; the other methods stop at the
    interface's energy, so the derived SCvx plans arrive within 2.5 % of its Mach number rather
    than at any speed (the vehicle's load bound is far below there); it re-plans closer together
    near the end (0.4 of the time to go, to 60 s) and bounds gamma at -45 deg (paper 001's -30 is
    its own mission's)."""
    from drake_entry.guidance.derivation import derivation_for, terminal_interface
    from drake_entry.guidance.scvx.derive import FLIGHT_PATH_BOUNDS_DEG, INTERFACE_SPEED_WINDOW, MACH_WINDOW_FRACTION
    from drake_entry.guidance.scvx.spec import Scvx

    mission = load_scenario("cav_h_fnpeg")
    assert mission.terminal.velocity_tolerance_m_s is None and mission.terminal.mach_tolerance is None
    mach = terminal_interface(mission).mach
    d = derivation_for(mission, Scvx)
    half = MACH_WINDOW_FRACTION * INTERFACE_SPEED_WINDOW
    for c in d.search[0].candidates:
        assert c["guidance.final_mach_min"] == pytest.approx(mach * (1 - half), abs=1e-4)
        assert c["guidance.final_mach_max"] == pytest.approx(mach * (1 + half), abs=1e-4)
        assert c["guidance.flown_mach_margin"] == pytest.approx(mach * (INTERFACE_SPEED_WINDOW - half) + mach * half,
                                                              abs=2e-4)
    spec = d.spec
    assert (spec.replan_period_s, spec.replan_time_to_go_fraction, spec.replan_min_time_to_go_s) == (200.0, 0.4, 60.0)
    assert tuple(spec.flight_path_bounds_deg) == FLIGHT_PATH_BOUNDS_DEG == (-45.0, 5.0)


def test_scvx_derived_mach_window_lies_below_the_load_bound_and_reaches_down_for_the_dispersed_forces():
    """Paper 004's CAV-H meets its 2 g total-load bound near the interface (1.97 g at Mach 6.79,
    30.5 km, alpha 20 deg): each candidate's Mach window tops out where the nominal vehicle meets
    0.93 of the limit, and its lower edge reaches down to where forces force_ratio_high x the
    nominal (3 sigma of density and aerodynamic scales) meet it, so a re-plan predicting with
    the forces the flight sensed keeps a feasible last node. The load there, computed by hand
    from the aerodynamic model, is the planned bound."""
    import math

    from drake_entry.guidance.derivation import FORCE_SIGMAS, LIMIT_MARGIN, derivation_for, terminal_interface
    from drake_entry.guidance.scvx.derive import INTERFACE_SPEED_WINDOW
    from drake_entry.guidance.scvx.spec import Scvx
    from drake_entry.models.dispersions import force_ratio_high
    from drake_entry.models.planet import G0

    mission = load_scenario("cav_h_paper004")
    vehicle, atmosphere = mission.make_vehicle(), mission.make_atmosphere()
    force_high = force_ratio_high(mission.dispersions, FORCE_SIGMAS)
    assert force_high > 1.15

    def load_g(h_km, mach, scale=1.0):
        a, rho = float(atmosphere.speed_of_sound(h_km * 1e3)), float(atmosphere.density(h_km * 1e3))
        CL, CD = vehicle.aero.coefficients(math.radians(20.0), mach)
        return scale * 0.5 * rho * (mach * a) ** 2 * vehicle.area_over_mass * math.hypot(CL, CD) / G0

    bound = LIMIT_MARGIN * vehicle.limits.total_load_max
    interface_low = terminal_interface(mission).mach * (1 - INTERFACE_SPEED_WINDOW)
    d = derivation_for(mission, Scvx)
    reached_down = 0
    for c in d.search[0].candidates:
        h = c["guidance.terminal_altitude_km"]
        lo, hi = c["guidance.final_mach_min"], c["guidance.final_mach_max"]
        assert lo < hi <= terminal_interface(mission).mach * (1 + INTERFACE_SPEED_WINDOW)
        assert load_g(h, hi) <= bound * (1 + 1e-3)
        assert load_g(h, lo, force_high) <= bound * (1 + 1e-3)
        if lo < interface_low:  # reached down: exactly to where the dispersed forces meet the bound
            assert load_g(h, lo + 0.01, force_high) > bound
            reached_down += 1
        assert lo <= c["guidance.terminal_mach"] <= hi
    assert reached_down >= 3  # the box's centre, 30 km, and the altitudes below it


def test_scvx_derived_aim_is_tight_where_the_vehicle_glides_at_the_interface_and_wider_where_it_dives():
    """A vehicle holding level flight at the interface (HORUS-2B at 25 km, 650 m/s, alpha 15 deg:
    lift above g - V^2/r) ends its plans at the shallow descent bound, so its plans aim within
    10 m of the stop altitude; Lu 2008's capsule (18 km, 300 m/s, L/D 0.3) cannot hold it and
    dives through, and aims within 50 m. The check is the lift's: just above the level-flight
    speed it glides, just below it does not."""
    import math

    import scipy.optimize

    from drake_entry.guidance.derivation import derivation_for
    from drake_entry.guidance.scvx.derive import AIM_TOLERANCE_KM, GLIDE_AIM_TOLERANCE_KM, glides_at
    from drake_entry.guidance.scvx.spec import Scvx

    horus, capsule = load_scenario("horus2b"), load_scenario("capsule_lu2008")
    assert glides_at(horus, 25.0, 650.0, 15.0) and not glides_at(capsule, 18.25, 305.0, 20.0)
    for mission, tolerance_km in ((horus, GLIDE_AIM_TOLERANCE_KM), (capsule, AIM_TOLERANCE_KM)):
        for c in derivation_for(mission, Scvx).search[0].candidates:
            lo, hi = c["guidance.final_altitude_m"]
            assert hi - lo - 2.0 * c["guidance.final_altitude_margin_m"] == pytest.approx(2e3 * tolerance_km)
    # the level-flight speed of HORUS-2B at 25 km, alpha 15 deg: glides above it, not below
    vehicle, atmosphere, planet = horus.make_vehicle(), horus.make_atmosphere(), horus.make_planet()
    r, rho, a = float(planet.radius(25e3)), float(atmosphere.density(25e3)), float(atmosphere.speed_of_sound(25e3))

    def excess(V):
        CL, _ = vehicle.aero.coefficients(math.radians(15.0), V / a)
        return 0.5 * rho * V * V * vehicle.area_over_mass * float(CL) - (planet.mu / r ** 2 - V * V / r)

    V_level = scipy.optimize.brentq(excess, 100.0, 650.0)
    assert glides_at(horus, 25.0, V_level * 1.01, 15.0) and not glides_at(horus, 25.0, V_level * 0.99, 15.0)


def test_force_ratio_high_combines_the_force_dispersions_root_sum_square():
    """1 + k sqrt(sum of relative sigmas^2) times the mean scales; a uniform's sigma is its
    width / sqrt(12); the density waves' amplitude adds; nothing dispersed gives 1."""
    import math

    import pydrake.common.schema as schema

    from drake_entry.models.dispersions import DispersionSpec, force_ratio_high

    assert force_ratio_high(DispersionSpec()) == 1.0
    spec = DispersionSpec(density_scale=schema.Gaussian(mean=1.0, stddev=0.05),
                          lift_scale=schema.Uniform(min=0.9, max=1.1), drag_scale=schema.Gaussian(mean=1.0, stddev=0.03),
                          density_wave_amplitude=schema.Uniform(min=-0.02, max=0.02))
    s_lift = 0.2 / math.sqrt(12.0)
    assert force_ratio_high(spec, 3.0) == pytest.approx(1.0 + 3.0 * math.hypot(0.05, s_lift) + 0.02, rel=1e-12)
    spec.mass_scale = schema.Gaussian(mean=1.1, stddev=0.0)
    assert force_ratio_high(spec, 2.0) == pytest.approx((1.0 + 2.0 * math.hypot(0.05, s_lift) + 0.02) / 1.1, rel=1e-12)


def test_load_limit_speed_meets_the_limit_and_is_infinite_without_one(monkeypatch):
    """brentq's speed puts the nominal vehicle exactly at the fraction of its load bound; a
    vehicle limiting no load has none."""
    import dataclasses as dc
    import math

    from drake_entry.guidance.derivation import load_limit_speed
    from drake_entry.models.planet import G0

    mission = load_scenario("cav_h_paper004")
    V = load_limit_speed(mission, 30.0, lambda V: 20.0, 0.9)
    vehicle, atmosphere = mission.make_vehicle(), mission.make_atmosphere()
    CL, CD = vehicle.aero.coefficients(math.radians(20.0), V / float(atmosphere.speed_of_sound(30e3)))
    load = 0.5 * float(atmosphere.density(30e3)) * V * V * vehicle.area_over_mass * math.hypot(CL, CD) / G0
    assert load == pytest.approx(0.9 * vehicle.limits.total_load_max, rel=1e-5)
    unlimited = mission.make_vehicle()
    unlimited.limits = dc.replace(unlimited.limits, total_load_max=math.inf, normal_load_max=math.inf)
    monkeypatch.setattr(mission, "make_vehicle", lambda: unlimited)
    assert load_limit_speed(mission, 30.0, lambda V: 20.0) == math.inf


def test_a_flown_plan_is_judged_up_to_its_mach_margin_and_a_heading_a_turn_away_is_the_same():
    """drs_point's Mach criterion is final_mach_max plus the mission's flown margin (Lu 2014's
    CAV-H: a plan flown to Mach 6.83 against its 6.82 aim was refused); a re-plan's heading past
    the entry heading + 180 deg is taken a turn lower where that lies in the bounds."""
    from drake_entry.guidance.scvx.mission import ScvxMission
    from drake_entry.guidance.scvx.planner import drs_point, equivalent_heading
    from drake_entry.models.planet import Earth

    planet = Earth.spherical()
    m = ScvxMission(final_altitude_m=(27.5e3, 28.5e3), final_mach_min=6.49, final_mach_max=6.82,
                    final_vertical_speed_min_m_s=-300.0, site_radius_m=2.5e3)
    xf = np.array([28e3, *m.site(planet), 2000.0, -0.02, 0.0])
    assert drs_point(m, planet, xf, 6.80, 3e3)[1] and not drs_point(m, planet, xf, 6.83, 3e3)[1]
    assert drs_point(dc.replace(m, flown_mach_margin=0.33), planet, xf, 6.83, 3e3)[1]
    with pytest.raises(Exception, match="flown_mach_margin"):
        dc.replace(m, flown_mach_margin=-0.1)
    bounds = np.radians([-141.4332, 218.5668])
    assert equivalent_heading(math.radians(221.27), bounds) == pytest.approx(math.radians(221.27 - 360.0))
    assert equivalent_heading(math.radians(100.0), bounds) == pytest.approx(math.radians(100.0))
    narrow = np.radians([0.0, 90.0])
    assert equivalent_heading(math.radians(200.0), narrow) == pytest.approx(math.radians(200.0))  # none inside
