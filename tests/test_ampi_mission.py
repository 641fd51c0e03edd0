"""AMPI on any mission: the optimal-control problem's alpha scheduled in speed, energy or Mach,
the problem a mission poses for the database, the derived settings and their checks."""
import dataclasses as dc
import math

import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi import mission as mission_module
from drake_entry.guidance.ampi.mission import ALTITUDE_WINDOW_FRACTION, fingerprint, mission_problem_spec, source_digest
from drake_entry.guidance.ampi.spec import MAX_MISSION_CASES, Ampi
from drake_entry.guidance.derivation import CannotFly, derivation_for
from drake_entry.models.dispersions import entry_spread
from drake_entry.models.dynamics import air_data, specific_energy
from drake_entry.models.schedules import Schedule
from drake_entry.planning.ocp_yaml import load_problem, problem_from_spec
from drake_entry.scenario import load_scenario

X = np.array([40e3, -0.3, 1.2, 4000.0, -0.05, -1.5, math.radians(-20.0), 70.0])
U = np.array([math.radians(2.0)])


def _schedule(variable: str) -> Schedule:
    """A two-corner alpha law in ``variable`` whose ramp holds X's value of it."""
    problem, _ = load_problem("shefex3")
    at = {"velocity": X[3], "energy": float(specific_energy(X, problem.planet.with_(j2=0.0))),
          "mach": X[3] / float(air_data(X, problem.planet, problem.atmosphere)[1])}[variable]
    return Schedule((at - 0.2 * abs(at), at + 0.2 * abs(at)), (math.radians(30.0), math.radians(15.0)), variable, smooth=True)


@pytest.mark.parametrize("variable", ["velocity", "energy", "mach"])
def test_alpha_scheduled_in_speed_energy_or_mach_and_its_derivatives(variable):
    """alpha = the schedule at the state's speed, central-gravity energy or Mach (the closed
    loop's variables), and the dynamics' Jacobian through it (AutoDiffXd) equals central
    differences in every state."""
    problem, _ = load_problem("shefex3")
    schedule = _schedule(variable)
    p = dc.replace(problem, alpha_schedule=schedule)
    alpha, _ = p.alpha_sigma(X, U)
    assert alpha == pytest.approx(math.radians(22.5), rel=1e-9)  # the ramp's middle
    xa = np.array([AutoDiffXd(v, np.eye(8)[i]) for i, v in enumerate(X)], dtype=object)
    fa = p.dynamics(xa, U)
    J = np.array([v.derivatives() if isinstance(v, AutoDiffXd) else np.zeros(8) for v in fa])
    steps = np.array([1.0, 1e-7, 1e-7, 1e-3, 1e-7, 1e-7, 1e-7, 1e-3])
    fd = np.column_stack([(p.dynamics(X + s * e, U) - p.dynamics(X - s * e, U)) / (2 * s)
                          for s, e in zip(steps, np.eye(8))])
    assert J == pytest.approx(fd, rel=1e-5, abs=1e-10)
    # the schedule matters: the same state under time scheduling gives other derivatives
    assert np.abs(p.dynamics(X, U) - problem.dynamics(X, U)).max() > 1e-3


def test_alpha_schedule_block_reads_any_variable_and_names_bad_fields():
    from drake_entry.planning.ocp_yaml import AlphaScheduleSpec, _alpha_schedule

    s = _alpha_schedule(AlphaScheduleSpec(variable="velocity", breakpoints=[2000.0, 5000.0], values_deg=[10.0, 14.0],
                                          smooth=True))
    assert s.variable == "velocity" and s.smooth and s(3500.0) == pytest.approx(math.radians(12.0))
    with pytest.raises(ScenarioError, match="alpha_schedule.variable = 'speed' is unknown; allowed: time, energy"):
        _alpha_schedule(AlphaScheduleSpec(variable="speed", breakpoints=[1.0], values_deg=[1.0]))
    with pytest.raises(ScenarioError, match="alpha_schedule.breakpoints_s: not with variable 'mach'; give breakpoints"):
        _alpha_schedule(AlphaScheduleSpec(variable="mach", breakpoints_s=[1.0], values_deg=[1.0]))


def _derived(name: str):
    scenario = load_scenario(name)
    d = derivation_for(scenario, Ampi)
    scenario.guidance = d.spec
    if d.alpha is not None:
        scenario.alpha = dc.replace(d.alpha)
    return scenario, d


def test_derived_settings_grid_the_deviations_that_move_the_end_most():
    """HORUS-2B (paper 000 Table 2): the speed (15 m/s, ~26 km at the end), latitude and longitude
    (0.1 deg, ~11 km) make the grid; the box centre 25 km at 0.97 of the speed where 0.93 of the
    10 kPa limit is met. The Lu-2008 capsule: its position and heading spread."""
    scenario, d = _derived("horus2b")
    assert d.spec.database == "mission" and d.spec.grid == {"V": 15.0, "lat": 0.1, "lon": 0.1}
    q = 0.5 * float(scenario.make_atmosphere().density(25e3)) * d.spec.terminal_velocity_m_s ** 2
    assert d.spec.terminal_altitude_km == 25.0 and q == pytest.approx(0.97 ** 2 * 0.93 * 1e4, rel=1e-4)
    assert "gamma, psi, h left to the tracker" in d.choices[2].how
    # the final position weighted at a tenth of the 2-km box (paper 003's 0.01 deg is 1.1 km), then a
    # fiftieth, searched
    assert d.spec.terminal_scales[1] == pytest.approx(math.degrees(200.0 / 6378137.0), rel=2e-3)
    heavier = d.search[-1].candidates[1]["guidance.terminal_scales"]
    assert heavier[1] == heavier[2] == pytest.approx(math.degrees(40.0 / 6378137.0), rel=2e-3)
    # Lu 2014's path-limit feedback where the vehicle has limits (HORUS-2B: heat rate, q, load)
    assert (d.spec.path_gain, d.spec.path_limit_fraction) == (40.0, 0.95)
    _, capsule = _derived("capsule_lu2008")
    assert set(capsule.spec.grid) == {"lat", "lon", "psi"}
    # the reading of the reference searched; the sensed ratios only where the air or aerodynamics
    # are dispersed (the capsule's density, C_L, C_D, mass; HORUS-2B's entry alone)
    assert [step.name for step in d.search] == ["guidance.tracking_index", "guidance.terminal_scales"]
    assert [step.name for step in capsule.search] == ["guidance.tracking_index", "guidance.model_scales",
                                                       "guidance.terminal_scales"]
    assert capsule.search[1].candidates == ({"guidance.model_scales": False}, {"guidance.model_scales": True})
    assert "density_scale, lift_scale, drag_scale, mass_scale" in capsule.search[1].why
    assert derivation_for(load_scenario("shefex3_ampi"), Ampi).spec.database == "shefex3"  # its own settings
    with pytest.raises(CannotFly, match="box asks alpha 0 \\+- 2 deg"):
        derivation_for(load_scenario("marv_guidance"), Ampi)


def test_derived_ld_nodes_resolve_a_planned_bank_reversal():
    """Paper 004's CAV-H: a planned reversal (0.9 x 85 deg each side at a quarter of 20 deg/s)
    takes 30.6 s; the flight ~2420 s (11 369 km at the mean of 7400 and 2000 m/s); the widest LGL
    interval of the derived nodes is half a reversal at most, and one node fewer would not do.
    SHEFEX-3's-length flights keep paper 003's 60."""
    from drake_entry.guidance.ampi.derive import LD_NODES_RANGE, ld_nodes
    from drake_entry.guidance.derivation import terminal_interface
    from drake_entry.planning.pseudospectral import lgl_nodes

    scenario, d = _derived("cav_h_paper004")
    n, duration, reversal = ld_nodes(scenario, terminal_interface(scenario))
    assert reversal == pytest.approx(2 * 0.9 * 85.0 / (0.25 * 20.0), rel=1e-9)
    assert duration == pytest.approx(2419.0, abs=5.0) and d.spec.ld_nodes == n

    def widest(nodes):
        return float(np.max(np.diff(lgl_nodes(nodes)))) * duration / 2.0

    assert widest(n) <= reversal / 2.0 < widest(n - 1)
    capsule, _ = _derived("capsule_lu2008")
    assert ld_nodes(capsule, terminal_interface(capsule))[0] == LD_NODES_RANGE[0]


def test_entry_spread_is_the_three_sigma_reach():
    spread = entry_spread(load_scenario("shefex3_ampi").dispersions)  # Gaussian, sigma = step / 3
    assert spread == pytest.approx([250.0, 0.5, 0.5, 70.0, 0.5, 0.5], rel=1e-4)
    assert entry_spread(load_scenario("horus2b").dispersions) == pytest.approx([250, 0.1, 0.1, 15, 0.01, 0.01])


def test_mission_problem_is_the_mission_with_its_limits_planned_inside(tmp_path):
    """The problem file a mission poses: its entry, target and interface, the vehicle's limits
    planned 7 % inside, its bank bounds; read back by the problem loader to the same problem."""
    scenario, d = _derived("cav_h_fnpeg")
    text, key = fingerprint(d.spec, scenario)
    path = tmp_path / "problem.yaml"
    path.write_text(text)
    problem, solve = load_problem(str(path))
    vehicle = scenario.make_vehicle()
    assert problem.controls == "bank_rate" and problem.alpha_schedule.variable == "velocity"
    assert problem.alpha_schedule(5500.0) == pytest.approx(math.radians(10.5))
    x0 = scenario.initial_state()
    assert [problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")] == pytest.approx(list(x0))
    assert "V" not in problem.final
    assert problem.final["lat"] == pytest.approx(math.radians(scenario.target.latitude_deg))
    energy, altitude = problem.terminal  # the stop's energy, inside half the box's altitude tolerance
    E_f = scenario.guidance_terminal_state()[2]
    assert energy.quantity == "central_energy" and energy.min == energy.max == pytest.approx(E_f)
    x_end = np.array([28e3, 0.0, 0.0, d.spec.terminal_velocity_m_s, 0.0, 0.0])
    assert energy.value(x_end, None, None, problem.planet) == pytest.approx(E_f, rel=1e-12)
    half = ALTITUDE_WINDOW_FRACTION * scenario.terminal.altitude_tolerance_km * 1e3
    # a spherical Earth: the geodetic altitude is the state altitude, a terminal constraint as the
    # matrix's AMPI rows were flown (not a final bound: the solver's path, and its local optima, differ)
    assert altitude.quantity == "geodetic_altitude" and "h" not in problem.final
    assert (altitude.min, altitude.max) == (pytest.approx(28e3 - half), pytest.approx(28e3 + half))
    bounds = {c.quantity: c.max for c in problem.path}
    limits = vehicle.limits
    assert bounds["dynamic_pressure"] == pytest.approx(0.93 * limits.dynamic_pressure_max)
    assert problem.state_bounds["sigma"] == pytest.approx((-0.9 * vehicle.bank_limit, 0.9 * vehicle.bank_limit))
    assert problem.control_bounds["u_sigma"] == pytest.approx((-0.25 * vehicle.bank_rate_limit,
                                                               0.25 * vehicle.bank_rate_limit))
    assert [t.kind for t in problem.objective] == ["bank_effort", "flight_path_effort"]
    assert solve.transcription == "hermite_simpson" and solve.refine
    # the fingerprint follows the content: another grid is another database
    assert fingerprint(dc.replace(d.spec, grid={"V": 10.0}), scenario)[1] != key
    assert fingerprint(d.spec, scenario)[1] == key
    assert problem_from_spec(mission_problem_spec(d.spec, scenario)).final == problem.final


def test_a_change_to_the_build_code_is_another_database(tmp_path, monkeypatch):
    """The fingerprint covers the source of the code that builds the database: a changed rule
    in any file of those packages (not a byte-compiled cache) is a different digest, and a
    different digest is a different database folder."""
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "rules.py").write_text("RESOLVE_WITHIN = 0.02\n")
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "solve.py").write_text("TOL = 1e-6\n")
    folders = [str(tmp_path / "a"), str(tmp_path / "b")]
    before = source_digest(folders)
    (tmp_path / "a" / "__pycache__").mkdir()
    (tmp_path / "a" / "__pycache__" / "rules.cpython-311.pyc").write_bytes(b"\x00compiled")
    (tmp_path / "a" / "notes.txt").write_text("not code")
    assert source_digest(folders) == before
    (tmp_path / "a" / "rules.py").write_text("RESOLVE_WITHIN = 0.03\n")
    assert source_digest(folders) != before
    (tmp_path / "a" / "rules.py").write_text("RESOLVE_WITHIN = 0.02\n")
    assert source_digest(folders) == before
    (tmp_path / "b" / "solve.py").rename(tmp_path / "b" / "solve2.py")  # a renamed module is other code
    assert source_digest(folders) != before
    # the installed build code is what the fingerprint digests
    installed = mission_module.build_source_digest()
    assert len(installed) == 64
    scenario, d = _derived("capsule_lu2008")
    key = fingerprint(d.spec, scenario)[1]
    monkeypatch.setattr(mission_module, "build_source_digest", lambda: "0" * 64)
    assert fingerprint(d.spec, scenario)[1] != key


def test_the_mission_problem_ends_at_the_terminal_altitude_in_the_mission_s_datum():
    """SPHYNX (altitude_datum 'sphere', an oblate Earth): the guidance's terminal altitude is a
    state altitude (3.83 km at the site, 11.5 km geodetic) and bounds the final state altitude;
    SHEFEX-3 (altitude_datum 'ellipsoid'): it is geodetic and a terminal constraint; the capsule
    (a spherical Earth: the two altitudes are one) keeps the terminal constraint its database
    was built with (measured with Drake 1.51.1: that database's first 10 draws fly 10 of 10, the
    final bound's 4)."""
    sphynx, d = _derived("sphynx_paper001")
    p = problem_from_spec(mission_problem_spec(d.spec, sphynx))
    h_f, half = d.spec.terminal_altitude_km * 1e3, 0.5 * sphynx.terminal.geodetic_altitude_tolerance_km * 1e3
    assert 3.5e3 < h_f < 4e3 and p.final["h"] == (pytest.approx(h_f - half), pytest.approx(h_f + half))
    assert [c.quantity for c in p.terminal] == ["central_energy"]
    lat = math.radians(sphynx.target.latitude_deg)
    assert float(p.planet.atmospheric_altitude(h_f, lat)) == pytest.approx(11.5e3, abs=1.0)  # the box's geodetic centre
    shefex = load_scenario("shefex3_ampi")
    spec = dc.replace(_derived("cav_h_fnpeg")[1].spec, terminal_altitude_km=23.5)
    q = problem_from_spec(mission_problem_spec(spec, shefex))
    energy, altitude = q.terminal
    assert altitude.quantity == "geodetic_altitude" and (altitude.min + altitude.max) / 2 == pytest.approx(23.5e3)
    assert "h" not in q.final
    capsule, c = _derived("capsule_lu2008")
    r = problem_from_spec(mission_problem_spec(c.spec, capsule))
    assert [t.quantity for t in r.terminal] == ["central_energy", "geodetic_altitude"] and "h" not in r.final


@pytest.mark.parametrize("change, message", [
    ({"grid": {}}, "guidance.grid: database 'mission' needs the grid"),
    ({"grid": {"speed": 1.0}}, "guidance.grid.speed: not an entry state"),
    ({"grid": {"V": -1.0}}, "guidance.grid.V"),
    ({"grid_levels": 4}, "give an odd number"),
    ({"grid": {n: 1.0 for n in ("h", "lon", "lat", "V", "gamma", "psi")}}, f"allowed up to {MAX_MISSION_CASES}"),
    ({"path_margin": 0.9}, "guidance.path_margin"),
])
def test_mission_database_fields_are_checked(change, message):
    scenario, d = _derived("horus2b")
    scenario.guidance = dc.replace(d.spec, **change)
    with pytest.raises(ScenarioError, match=message):
        scenario.validate()


def test_a_packaged_database_takes_no_grid():
    scenario = load_scenario("shefex3_ampi")
    scenario.guidance = dc.replace(scenario.guidance, grid={"V": 10.0})
    with pytest.raises(ScenarioError, match="guidance.grid: only with database 'mission'"):
        scenario.validate()


def test_mission_database_yaml_names_the_field():
    """A file's ``!Ampi {database: mission}`` without a grid is refused naming the grid."""
    from drake_entry.scenario import load_campaign_scenario

    with pytest.raises(ScenarioError, match="guidance.grid: database 'mission' needs the grid of entry offsets"):
        load_campaign_scenario("horus2b", {"guidance": "!Ampi {database: mission}"})
    flown = load_campaign_scenario("horus2b", {"guidance": "!Ampi {database: mission, grid: {V: 15.0}}"})
    assert flown.guidance.grid == {"V": 15.0}


def _shefex_on_its_own_mission():
    """SHEFEX-3's mission with a database built for it: one grid dimension (3 cases), one fresh
    solve. (Its target is near the end of the vehicle's reach: from 70 m/s faster, paper 003's
    grid step, no flight dissipates the energy down to the stop's over the target.)"""
    scenario = load_scenario("shefex3_ampi")
    scenario.guidance = dc.replace(scenario.guidance, database="mission", grid={"V": 20.0}, accuracy_cases=1)
    return scenario.validate()


def test_the_planner_of_an_unbuilt_mission_database_says_how_to_build_it(tmp_path, monkeypatch):
    from drake_entry.guidance.ampi.method import METHOD

    monkeypatch.setenv("DRAKE_ENTRY_CACHE", str(tmp_path))
    with pytest.raises(ScenarioError, match="is not built: .*prepare\\(scenario\\)"):
        METHOD.make_planner(_shefex_on_its_own_mission(), None)


@pytest.mark.slow
def test_prepare_builds_the_mission_database_once_and_the_planner_flies_it(tmp_path, monkeypatch):
    """prepare() builds the database of the mission (every case verified), checks it against a
    fresh solve, and a second call loads it from the cache; the planner then makes the nominal
    entry's reference, which ends at the spec's terminal speed and within the altitude window."""
    from drake_entry.campaign.preparation import prepare
    from drake_entry.guidance.ampi.method import METHOD

    monkeypatch.setenv("DRAKE_ENTRY_CACHE", str(tmp_path))
    scenario = _shefex_on_its_own_mission()
    first = prepare(scenario, progress=False)
    assert "3/3 cases verified, built in" in first
    assert "loaded from the cache" in prepare(scenario, progress=False)
    planner = METHOD.make_planner(scenario, None)
    assert planner.success, planner.message
    ref = planner.reference(scenario.initial_state())
    end = ref.synthesis.states[-1]  # at the stop's energy, inside half the box's +-2.5 km
    E = 0.5 * end[3] ** 2 - planner.problem.planet.mu / planner.problem.planet.radius(end[0])
    assert E == pytest.approx(scenario.guidance_terminal_state()[2], abs=100.0)
    geodetic = planner.problem.planet.atmospheric_altitude(end[0], end[2])
    assert abs(geodetic - 21.1e3) <= 1250.0 + 1.0
    from drake_entry.guidance.ampi.mission import built_database

    accuracy = built_database(scenario.guidance, scenario).accuracy
    assert accuracy["verified"] == 1  # the fresh solve converged and was verified


def test_flight_path_effort_is_gamma_over_its_scale_squared():
    from drake_entry.planning.ocp import ObjectiveTerm

    problem, _ = load_problem("shefex3")
    p = dc.replace(problem, objective=[ObjectiveTerm("flight_path_effort", weight=2.0, scale=math.radians(1.0))])
    assert p.lagrangian(X, U) == pytest.approx(2.0 * (X[4] / math.radians(1.0)) ** 2, rel=1e-12)
    with pytest.raises(ScenarioError, match="scale = 0.0 must be finite and > 0"):
        ObjectiveTerm("flight_path_effort", scale=0.0)


def test_centred_bank_effort_measures_the_bank_magnitude_from_its_centre():
    """bank_centre c: ((sqrt(sigma^2 + 1 deg^2) - c) / bank_max)^2 + the rate term, the same on
    either side of the plan; c = 0 is paper 003's (sigma / bank_max)^2; its gradient matches
    central differences (the NLP differentiates it); c at or above bank_max is refused."""
    from pydrake.autodiffutils import AutoDiffXd

    from drake_entry.planning.ocp import BANK_SMOOTHING, ObjectiveTerm

    problem, _ = load_problem("shefex3")
    c, bmax, umax = math.radians(30.0), math.radians(60.0), math.radians(5.0)
    p = dc.replace(problem, objective=[ObjectiveTerm("bank_effort", bank_max=bmax, u_sigma_max=umax, bank_centre=c,
                                                     rate_weight=0.1)])
    plain = dc.replace(problem, objective=[ObjectiveTerm("bank_effort", bank_max=bmax, u_sigma_max=umax,
                                                         rate_weight=0.1)])
    rate = 0.1 * (U[0] / umax) ** 2
    for sigma in (0.0, c, -c, math.radians(50.0), -math.radians(50.0)):
        x = np.array(X, float)
        x[6] = sigma
        expected = ((math.sqrt(sigma ** 2 + BANK_SMOOTHING ** 2) - c) / bmax) ** 2 + rate
        assert p.lagrangian(x, U) == pytest.approx(expected, rel=1e-12)
        assert plain.lagrangian(x, U) == pytest.approx((sigma / bmax) ** 2 + rate, rel=1e-12)
    assert p.lagrangian(np.where(np.arange(len(X)) == 6, c, X), U) - rate < 1e-4  # at the centre, nearly free
    x = np.array(X, float)
    x[6] = math.radians(12.0)
    ad = np.array([AutoDiffXd(v, np.eye(len(x))[i]) for i, v in enumerate(x)], dtype=object)
    grad = p.lagrangian(ad, U).derivatives()
    for i in range(len(x)):
        step = np.zeros(len(x))
        step[i] = 1e-6
        fd = (p.lagrangian(x + step, U) - p.lagrangian(x - step, U)) / 2e-6
        assert grad[i] == pytest.approx(fd, rel=1e-5, abs=1e-9)
    with pytest.raises(ScenarioError, match="bank_centre = 60 deg; allowed 0 to below bank_max"):
        ObjectiveTerm("bank_effort", bank_max=bmax, bank_centre=bmax)
