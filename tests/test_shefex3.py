"""Paper 003 (SHEFEX-3) mission and optimal-control problem: geodetic altitudes, alpha
scheduled in time with the bank as a state, eq. 1's objective and the packaged problem
(docs/methods/ampi.md gives the figures checked here)."""
import dataclasses as dc
import math

import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd

from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.models.planet import Earth
from drake_entry.models.schedules import Schedule
from drake_entry.planning.ocp import ObjectiveTerm, OptimalControlProblem, PathConstraint
from drake_entry.planning.ocp_yaml import load_problem
from drake_entry.scenario import load_scenario

ALPHA_LAW = Schedule.ramp(58.0, 88.0, math.radians(42.0), math.radians(17.5))  # paper 003 Table 2


def test_state_altitude_inverts_the_geodetic_altitude_of_the_atmosphere():
    planet = Earth(flattening=1 / 298.257223563)
    for lat_deg in (0.0, 30.0, 66.4, 71.89, -80.0):
        lat = math.radians(lat_deg)
        h = planet.state_altitude(100.1e3, lat)
        assert planet.atmospheric_altitude(h, lat) == pytest.approx(100.1e3, abs=1e-6)
    # at 71.89 N the ellipsoid lies a f sin^2(lat) = 19.3 km inside the equatorial sphere
    assert 100.1e3 - planet.state_altitude(100.1e3, math.radians(71.89)) == pytest.approx(19.3e3, abs=0.1e3)


def test_shefex3_entry_is_geodetic_and_bank_zero_flies_about_600_s_with_a_dip_below_40_km():
    """Paper 003 Sec. III: 'during the first 70 s the altitude decreases almost linearly to less
    than 40 km', about 600 s per trajectory; a pre-implementation prototype measured 604 s, first dip 37 km, q 43 kPa,
    Q 5.9 MW/m^2, n_z 8.2 with bank 0 and the representative aerodynamics."""
    from drake_entry.diagrams.open_loop import simulate

    scenario = load_scenario("shefex3")
    planet = scenario.make_planet()
    x0 = scenario.initial_state()
    assert planet.atmospheric_altitude(x0[0], x0[2]) == pytest.approx(100.1e3, abs=1e-6)
    tr = simulate(dc.replace(scenario, bank=dc.replace(scenario.bank, values_deg=[0.0])))
    h = planet.atmospheric_altitude(tr.state[:, 0], tr.state[:, 2])
    dip = int(np.argmax(np.diff(np.sign(np.diff(h))) > 0)) + 1
    assert 590.0 < tr.time[-1] < 620.0
    assert 60.0 < tr.time[dip] < 90.0 and 30e3 < h[dip] < 40e3
    assert h[-1] == pytest.approx(23.5e3, abs=1.0)  # stopped at the geodetic terminal altitude
    assert tr.column("dynamic_pressure").max() < 50e3 and tr.column("heat_flux").max() < 6.5e6
    assert tr.column("normal_load").max() < 10.0


def test_altitude_datum_is_checked():
    scenario = load_scenario("shefex3")
    with pytest.raises(ScenarioError, match="altitude_datum = 'geoid' is unknown; allowed: sphere, ellipsoid"):
        dc.replace(scenario, altitude_datum="geoid").validate()
    with pytest.raises(ScenarioError, match="needs planet.model 'oblate'"):
        dc.replace(scenario, planet=dc.replace(scenario.planet, model="spherical")).validate()


def _bank_rate_problem(**kw):
    problem, _ = load_problem("shefex3")
    return dc.replace(problem, **kw) if kw else problem


def test_alpha_schedule_in_time_with_bank_and_clock_states():
    """controls='bank_rate': alpha = Table 2 law at the clock state, sigma' = u_sigma, t' = 1;
    the same derivatives with AutoDiffXd (the chain rule through the schedule's slope) as by
    central differences."""
    problem = _bank_rate_problem()
    assert problem.state_names[6:] == ("sigma", "t") and problem.control_names == ("u_sigma",)
    x = np.array([40e3, -0.3, 1.2, 4000.0, -0.05, -1.5, math.radians(-20.0), 70.0])
    u = np.array([math.radians(2.0)])
    alpha, sigma = problem.alpha_sigma(x, u)
    assert alpha == pytest.approx(math.radians(42.0 - 24.5 * 12.0 / 30.0), rel=1e-12) and sigma == x[6]
    f = problem.dynamics(x, u)
    assert f[6] == u[0] and f[7] == 1.0
    # derivative with respect to the clock: the schedule's slope carried through the dynamics
    xa = np.array([AutoDiffXd(v, np.eye(8)[i]) for i, v in enumerate(x)], dtype=object)
    fa = problem.dynamics(xa, u)
    dfdt = np.array([v.derivatives()[7] if isinstance(v, AutoDiffXd) else 0.0 for v in fa])
    e = 1e-4
    fd = (problem.dynamics(x + e * np.eye(8)[7], u) - problem.dynamics(x - e * np.eye(8)[7], u)) / (2 * e)
    assert dfdt == pytest.approx(fd, rel=1e-6, abs=1e-12)
    assert np.abs(dfdt[3:6]).max() > 0  # alpha changes V', gamma', psi'


def test_bank_rate_layout_errors_name_the_field():
    problem = _bank_rate_problem()
    with pytest.raises(ScenarioError, match="alpha_schedule is given exactly with controls='bank_rate'"):
        dc.replace(problem, controls="rates", alpha_schedule=ALPHA_LAW)
    with pytest.raises(ScenarioError, match="'bank_effort' needs the bank as a state"):
        dc.replace(problem, controls="direct", alpha_schedule=None, initial={}, state_bounds={}, control_bounds={})


def test_packaged_problem_is_paper_003_with_labelled_substitutes():
    problem, solve = load_problem("shefex3")
    planet = problem.planet
    assert planet.atmospheric_altitude(problem.initial["h"], problem.initial["lat"]) == pytest.approx(100.1e3)
    assert math.degrees(problem.initial["lon"]) == pytest.approx(-11.60)
    assert problem.initial["t"] == 0.0 and problem.alpha_schedule.breakpoints == (58.0, 88.0)
    assert problem.final["V"] == (570.0, 620.0)
    geodetic = problem.terminal[0]
    assert geodetic.quantity == "geodetic_altitude" and (geodetic.min, geodetic.max) == (21e3, 26e3)
    x = np.zeros(8)
    x[0], x[2] = planet.state_altitude(23.5e3, math.radians(66.4)), math.radians(66.4)
    assert problem.terminal_values(x, np.zeros(1))[0] == pytest.approx(23.5e3)
    assert {c.quantity: c.max for c in problem.path} == {"dynamic_pressure": 50e3, "heat_flux": 6.5e6,
                                                          "normal_load": 10.0}
    assert (solve.transcription, solve.nodes) == ("dircol", 100)


def test_terminal_deviation_is_paper_003_eq_1():
    """J = sum w (x_f - x_ref)^2: SI units (rad, m, m/s) or canonical (h / R, V / sqrt(mu / R))."""
    problem = _bank_rate_problem()
    ref = {"lon": -0.8, "lat": 1.17, "h": 23.5e3, "V": 595.0}
    weights = {"lon": 1.0, "lat": 1.0, "h": 1e-4, "V": 1e-4}
    xf = np.array([24.0e3, -0.79, 1.18, 600.0, 0.0, 0.0, 0.0, 600.0])
    si = ObjectiveTerm("terminal_deviation", reference=ref, weights=weights)
    expected = 0.01 ** 2 + 0.01 ** 2 + 1e-4 * 500.0 ** 2 + 1e-4 * 5.0 ** 2
    assert dc.replace(problem, objective=[si]).mayer(xf, 600.0) == pytest.approx(expected, rel=1e-12)
    R, mu = problem.planet.reference_radius, problem.planet.mu
    canonical = dc.replace(si, units="canonical")
    expected = 0.01 ** 2 + 0.01 ** 2 + 1e-4 * (500.0 / R) ** 2 + 1e-4 * (5.0 / math.sqrt(mu / R)) ** 2
    assert dc.replace(problem, objective=[canonical]).mayer(xf, 600.0) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ScenarioError, match="weights.q is not a state"):
        ObjectiveTerm("terminal_deviation", reference=ref, weights={"q": 1.0})
    with pytest.raises(ScenarioError, match="weights.gamma has no reference.gamma"):
        ObjectiveTerm("terminal_deviation", reference=ref, weights={"gamma": 1.0})


def test_bank_effort_is_the_integrand_of_the_well_posed_objective():
    problem = _bank_rate_problem()
    x = np.zeros(8)
    x[6] = math.radians(30.0)
    u = np.array([math.radians(2.5)])
    assert problem.lagrangian(x, u) == pytest.approx(0.5 ** 2 + 0.1 * 0.5 ** 2, rel=1e-12)
    assert isinstance(problem, OptimalControlProblem) and isinstance(problem.terminal[0], PathConstraint)


def test_entry_guess_turns_towards_the_target_and_ends_in_the_geodetic_window():
    from drake_entry.planning import nlp

    problem, _ = load_problem("shefex3")
    t, X, U = nlp.initial_guess(problem)
    h_end = problem.planet.atmospheric_altitude(X[-1, 0], X[-1, 2])
    assert 21e3 <= h_end <= 26e3
    assert X[0, 6] < 0  # the target lies left of the entry heading: a left bank
    assert np.degrees(X[-1, 1]) == pytest.approx(-44.60) and np.degrees(X[-1, 2]) == pytest.approx(68.10)
    assert 570.0 <= X[-1, 3] <= 620.0 and np.all(U == 0.0)


def test_packaged_problem_solves_verified_within_the_limits():
    """The packaged settings (Hermite-Simpson, 100 samples) from the built-in guess: verified
    (between nodes < 1e-3, the flown bank ends within 1e-2), t_f about 600 s as the paper's
    database, the path limits held between the nodes and the terminal windows met."""
    from drake_entry.planning import nlp

    problem, settings = load_problem("shefex3")
    r = nlp.solve(problem, transcription=settings.transcription, nodes=settings.nodes,
                  tolerance=settings.tolerance, verifier=fly_controls)
    assert r.success, r.message
    assert 550.0 < r.final_time < 630.0 and 0.0 < r.objective < 100.0
    x = r.states[-1]
    assert problem.planet.atmospheric_altitude(x[0], x[2]) == pytest.approx(23.5e3, abs=2.5e3 + 1.0)
    assert 570.0 - 1e-3 <= x[3] <= 620.0 + 1e-3
    assert math.degrees(x[2]) == pytest.approx(68.10, abs=1e-6) and math.degrees(x[1]) == pytest.approx(-44.60, abs=1e-6)
    assert np.abs(np.degrees(r.states[:, 6])).max() <= 60.0 + 1e-6
    assert np.abs(np.degrees(r.controls[:, 0])).max() <= 5.0 + 1e-6
    assert r.verification.path_violation < 1e-2
    assert r.verification.propagation["position_m"] < 2e3  # the flown bank ends within 2 km of the plan


@pytest.mark.slow  # a reproduction (a verified NLP solve): CI's -m "slow and not long" set
def test_table_1_target_lies_outside_the_representative_vehicles_footprint():
    """Why the packaged problem aims elsewhere (a labelled substitute): with the representative
    aerodynamics and the Table 1 windows hard, the least miss of the Table 1 target (66.40 N,
    45.75 W) is 31 km (verified solve; a pre-implementation prototype found 54 km)."""
    from drake_entry.planning import nlp

    problem, settings = load_problem("shefex3")
    target = (math.radians(-45.75), math.radians(66.40))
    nearest = dc.replace(problem, objective=[ObjectiveTerm("miss_distance", target=target, scale=1e8)],
                         final={k: v for k, v in problem.final.items() if k not in ("lon", "lat")})
    r = nlp.solve(nearest, transcription=settings.transcription, nodes=settings.nodes, tolerance=settings.tolerance,
                  verifier=fly_controls)
    assert r.success, r.message
    miss = problem.planet.great_circle_distance(r.states[-1, 1], r.states[-1, 2], *target)
    # outside: the least miss is many times the solve's verified accuracy (the flown controls end
    # within 2 km of the plan, the packaged problem's test); 31 km measured (a regression pin)
    assert miss > 5 * r.verification.propagation["position_m"] and miss > 10e3
    assert miss == pytest.approx(31e3, abs=3e3)


def test_problem_yaml_reads_eq_1_and_names_bad_fields(tmp_path):
    from importlib import resources

    text = resources.files("drake_entry").joinpath("problems/shefex3.yaml").read_text()
    eq1 = ("objective:\n  - {kind: terminal_deviation, units: si, reference: {longitude_deg: -44.60, latitude_deg: 68.10, "
           "velocity_m_s: 595.0}, weights: {longitude_deg: 1.0, latitude_deg: 1.0, velocity_m_s: 1.0e-4}}\nsolve:")
    start, end = text.index("objective:"), text.index("solve:")
    path = tmp_path / "eq1.yaml"
    path.write_text(text[:start] + eq1 + text[end + len("solve:"):])
    problem, _ = load_problem(str(path))
    term = problem.objective[0]
    assert term.reference == pytest.approx({"lon": math.radians(-44.60), "lat": math.radians(68.10), "V": 595.0})
    assert term.weights == {"lon": 1.0, "lat": 1.0, "V": 1e-4}
    bad = tmp_path / "bad.yaml"
    bad.write_text(text[:start] + eq1.replace("velocity_m_s: 1.0e-4", "mach: 1.0") + text[end + len("solve:"):])
    with pytest.raises(ScenarioError, match=r"objective\[0\].weights.mach: unknown field; allowed: altitude_km"):
        load_problem(str(bad))
