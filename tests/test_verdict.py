"""The one verdict of a flight (drake_entry.models.verdict): reached, inside the acceptance box and
every path limit held at every flown sample, log and integrator steps alike."""
import dataclasses as dc
import math

import numpy as np
import pytest

from drake_entry.models.constraints import PathLimits
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.models.trajectory import Trajectory, control_activity, metrics
from drake_entry.models.verdict import (
    PathLimit,
    check_limits,
    failure_clauses,
    failure_message,
    judge,
    vehicle_path_limits,
)

Q = FLIGHT_CONDITION_NAMES.index("heat_flux")
HEAT_BREACH = "heat_flux 540 kW/m^2 at t = 700.0 s (limit <= 530 kW/m^2, margin -1.89 %)"


def _trajectory(time, heat_flux, gamma=None, bank=None) -> Trajectory:
    n = len(time)
    state = np.zeros((n, 6))
    state[:, 4] = 0.0 if gamma is None else gamma
    conditions = np.zeros((n, len(FLIGHT_CONDITION_NAMES)))
    conditions[:, Q] = heat_flux
    return Trajectory(time=np.asarray(time, float), state=state, conditions=conditions,
                      bank=np.zeros(n) if bank is None else np.asarray(bank, float), alpha=np.zeros(n),
                      reason="reached energy", wall_time=0.0)


def test_a_peak_between_two_log_samples_is_caught_at_the_integrator_steps():
    """A heat-flux pulse of peak 1.02 q_max at t = 10.5 s (sin^40 in time) logged every 1 s looks
    held (the samples at 10 and 11 s are 0.90 q_max); the integrator's 0.25-s steps see the
    breach with its peak, time and margin, and so does the peak column of the row."""
    q_max = 500e3
    pulse = lambda t: 1.02 * q_max * np.sin(np.clip(t - 0.5, 0, 20) / 20 * np.pi) ** 40  # noqa: E731
    log_t = np.arange(0.0, 22.0, 1.0)
    step_t = np.arange(0.0, 22.0, 0.25)
    tr = _trajectory(log_t, pulse(log_t))
    limits = vehicle_path_limits(PathLimits(heat_flux_max=q_max))
    assert judge(tr, limits, reached=True, inside_box=True).within_limits  # the log alone misses it
    tr.steps = _trajectory(step_t, pulse(step_t))
    v = judge(tr, limits, reached=True, inside_box=True)
    assert not v.within_limits and not v.success and v.inside_box and v.reached
    (c,) = v.violations
    assert c.limit.name == "heat_flux" and c.time == pytest.approx(10.5)
    assert c.peak == pytest.approx(1.02 * q_max) and c.margin == pytest.approx(-0.02)
    assert "heat_flux 510 kW/m^2 at t = 10.5 s (limit <= 500 kW/m^2, margin -2.00 %)" == c.text()
    assert metrics(tr)["peak_heat_flux_W_m2"] == pytest.approx(1.02 * q_max)


def test_tolerance_widens_every_bound_by_its_fraction():
    """A 1 % breach fails at tolerance 0, holds at 0.011, fails at 0.009; a bound held exactly
    (a clamp at the bank limit) holds at tolerance 0."""
    tr = _trajectory([0.0, 1.0, 2.0], [0.0, 101.0, 0.0], bank=[0.0, math.radians(80.0), 0.0])
    limits = [PathLimit("heat_flux", "heat_flux", upper=100.0), PathLimit("bank", "bank", upper=math.radians(80.0),
                                                                         absolute=True)]
    assert [c.held for c in check_limits(tr.time, tr.column, limits, 0.0)] == [False, True]
    assert [c.held for c in check_limits(tr.time, tr.column, limits, 0.011)] == [True, True]
    assert [c.held for c in check_limits(tr.time, tr.column, limits, 0.009)] == [False, True]
    with pytest.raises(ValueError, match="tolerance must be >= 0"):
        check_limits(tr.time, tr.column, limits, -0.1)


def test_two_sided_limit_reports_the_binding_side():
    """gamma in [-30, 0.5] deg: a flight from -31 to 0.2 deg breaches the lower bound by 1 deg
    (margin -1/30); one from -20 to 0.6 deg the upper by 0.1 deg (margin -0.2)."""
    lim = [PathLimit("flight_path", "gamma", upper=math.radians(0.5), lower=math.radians(-30.0))]
    low = _trajectory([0, 1, 2], [0, 0, 0], gamma=np.radians([0.2, -10.0, -31.0]))
    (c,) = check_limits(low.time, low.column, lim)
    assert not c.held and c.peak == pytest.approx(math.radians(-31.0)) and c.margin == pytest.approx(-1 / 30)
    high = _trajectory([0, 1, 2], [0, 0, 0], gamma=np.radians([0.6, -10.0, -20.0]))
    (c,) = check_limits(high.time, high.column, lim)
    assert not c.held and c.time == 0.0 and c.margin == pytest.approx(-0.2)


def test_a_closed_loop_flight_that_breaks_a_limit_is_not_a_success():
    """HORUS-2B nominal (peak heat flux 517 kW/m^2 measured) flown with a vehicle whose heat-flux
    limit is 500 kW/m^2: it reaches E_f inside the acceptance box, but the verdict says breached,
    with the peak and margin in the row and the message; with a 4 % tolerance in the scenario it
    is a success again. (At 3dec588 the box alone made ``success``.)"""
    from drake_entry.campaign.sample import campaign_row
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
    from drake_entry.scenario import load_scenario

    scenario = load_scenario("horus2b")
    setup = ClosedLoopSetup.from_scenario(scenario)
    setup = dc.replace(setup, vehicle=dc.replace(setup.vehicle, limits=dc.replace(setup.vehicle.limits,
                                                                                  heat_flux_max=500e3)))
    res = fly(setup)
    assert res.reached and res.verdict.inside_box and not res.verdict.within_limits and not res.success
    row = campaign_row(res, setup)
    assert row["success"] is False and row["inside_box"] is True and row["within_limits"] is False
    assert row["violations"].startswith("heat_flux 51") and "limit <= 500 kW/m^2" in row["violations"]
    assert row["margin_heat_flux"] == pytest.approx(1.0 - row["peak_heat_flux_W_m2"] / 500e3)
    assert "path limits breached: heat_flux" in res.message
    tolerant = dc.replace(setup, scenario=dc.replace(scenario, terminal=dc.replace(scenario.terminal,
                                                                                  path_limit_tolerance=0.04)))
    assert fly(tolerant).success


def test_the_report_counts_success_box_and_limits_separately():
    """Rows: 2 successes, 1 inside the box breaching q, 1 outside the box within limits, 1 that
    never reached (and breached nothing, so it is within the limits): the counts and reasons say so."""
    from drake_entry.campaign.report import summary_statistics

    rows = {"index": [0, 1, 2, 3, 4], "success": [True, True, False, False, False],
            "reached_terminal": [True, True, True, True, False], "inside_box": [True, True, True, False, False],
            "within_limits": [True, True, False, True, True], "err_distance_m": [1.0, 2.0, 3.0, 9e4, math.nan],
            "violations": ["", "", HEAT_BREACH, "", ""],
            "message": ["ok", "ok", failure_message([], HEAT_BREACH, "reached E_f at t = 900.0 s"),
                        failure_message(["distance error +90.000 km outside +-2.5 km"], "", "reached E_f"),
                        "stopped before E_f: altitude floor"]}
    st = summary_statistics(rows)
    assert (st["successful"], st["reached"], st["inside_acceptance_box"], st["within_limits"], st["failed"]) == \
        (2, 4, 3, 4, 3)
    assert st["failure_reasons"] == {"heat_flux limit breached": 1, "outside the acceptance box": 1,
                                     "stopped before E_f": 1}
    assert st["inside_box"] == {}  # per criterion (inside_<criterion>_box): none given here


def test_a_verdict_message_reads_back_its_missed_criteria_and_breached_limits():
    """failure_clauses inverts failure_message: the box criteria and limits by name, in order;
    a message of a flight that did not reach (or a success) has neither, only its first clause."""
    missed = ["altitude error -3.721 km outside +-3 km", "distance error +4.000 km outside +-2.5 km"]
    breaches = HEAT_BREACH + "; dynamic_pressure 31.2 kPa at t = 470.0 s (limit <= 30 kPa, margin -4.00 %)"
    where = "reached E_f at t = 520.0 s, 4.000 km from the target"
    message = failure_message(missed, breaches, where)
    assert failure_clauses(message) == (["altitude", "distance"], ["heat_flux", "dynamic_pressure"],
                                        "outside the acceptance box")
    assert failure_clauses(failure_message([], breaches, where))[:2] == ([], ["heat_flux", "dynamic_pressure"])
    assert failure_message([], "", where) == where
    assert failure_clauses(where) == ([], [], where.split(":")[0])
    assert failure_clauses("stopped before E_f: altitude floor") == ([], [], "stopped before E_f")


def test_control_activity_counts_reversals_travel_rate_and_time_at_the_limits():
    """A bank held at +60 deg, reversed to -60 deg at 10 deg/s (12 s), held at the -60 deg limit
    for 50 s, reversed back: 2 reversals, 240 deg of travel, a 10 deg/s peak rate with 24 s at
    it (the rate limit), 100 s at the bank limit; the log samples alone (every 5 s) would
    miss where the ramps start and end, so the integrator steps (0.1 s) are used."""
    def bank(t):
        up = np.clip(60.0 - 10.0 * (t - 20.0), -60.0, 60.0)
        back = np.clip(-60.0 + 10.0 * (t - 82.0), -60.0, 60.0)
        return np.radians(np.where(t < 82.0, up, back))
    steps = np.arange(0.0, 150.0 + 1e-9, 0.1)
    logs = np.arange(0.0, 150.0 + 1e-9, 5.0)
    tr = _trajectory(logs, np.zeros(logs.size), bank=bank(logs))
    tr.steps = _trajectory(steps, np.zeros(steps.size), bank=bank(steps))
    a = control_activity(tr, bank_limit=math.radians(60.0), bank_rate_limit=math.radians(10.0))
    assert a["bank_reversals"] == 2
    assert a["bank_travel_deg"] == pytest.approx(240.0, rel=1e-9)
    assert a["peak_bank_rate_deg_s"] == pytest.approx(10.0, rel=1e-6)
    assert a["time_at_bank_rate_limit_s"] == pytest.approx(24.0, abs=0.11)
    assert a["time_at_bank_limit_s"] == pytest.approx(150.0 - 24.0, abs=0.11)  # +60 and -60 are both the limit


def _terminal(**kw):
    from types import SimpleNamespace

    from drake_entry.scenario import TerminalSpec

    base = {f.name: None for f in dc.fields(TerminalSpec)}
    return SimpleNamespace(**{**base, **kw})


def test_acceptance_box_has_each_criterion_given_in_km_and_is_closed():
    """A criterion is in the box only with its centre and tolerance; km become m; an error equal
    to its tolerance is inside (a closed box), a hair beyond is not."""
    from drake_entry.models.verdict import acceptance_box

    full = _terminal(altitude_km=30.0, altitude_tolerance_km=2.0, mach=0.75, mach_tolerance=0.25,
                     distance_tolerance_km=50.0)
    b = acceptance_box(full, altitude_m=32_000.0, mach=0.5, distance_m=50_000.0)
    assert b == {"altitude": {"error": 2000.0, "tolerance": 2000.0, "inside": True},
                 "mach": {"error": -0.25, "tolerance": 0.25, "inside": True},
                 "distance": {"error": 50_000.0, "tolerance": 50_000.0, "inside": True}}
    out = acceptance_box(full, altitude_m=27_999.0, mach=1.01, distance_m=50_001.0)
    assert [v["inside"] for v in out.values()] == [False, False, False]
    assert acceptance_box(_terminal(altitude_km=30.0, mach=0.8), altitude_m=0.0, mach=5.0, distance_m=1e9) == {}
    assert acceptance_box(_terminal(altitude_tolerance_km=1.0, mach_tolerance=0.1), altitude_m=0.0, mach=5.0,
                          distance_m=1e9) == {}
    assert list(acceptance_box(_terminal(distance_tolerance_km=2.0), altitude_m=0.0, mach=0.0,
                               distance_m=1999.0)) == ["distance"]


def test_impact_criteria_speed_flight_path_and_alpha_are_windows_about_their_values_in_si():
    """Speed, flight-path angle and angle of attack are windows about the spec's values: degrees
    become radians (an error of exactly the tolerance inside, 1e-9 rad beyond outside), a value
    not measured (nan) is never inside, and the missed criterion prints in the spec's units."""
    from drake_entry.models.verdict import acceptance_box, box_text

    spec = _terminal(velocity_m_s=1219.0, velocity_tolerance_m_s=50.0, flight_path_deg=-80.0,
                     flight_path_tolerance_deg=5.0, alpha_deg=0.0, alpha_tolerance_deg=1.0)
    b = acceptance_box(spec, altitude_m=0.0, mach=3.6, distance_m=0.0, velocity_m_s=1169.0,
                       flight_path_rad=math.radians(-85.0), alpha_rad=math.radians(1.0))
    assert list(b) == ["velocity", "flight_path", "alpha"] and all(v["inside"] for v in b.values())
    assert b["velocity"]["error"] == pytest.approx(-50.0) and b["flight_path"]["tolerance"] == pytest.approx(math.radians(5.0))
    out = acceptance_box(spec, altitude_m=0.0, mach=3.6, distance_m=0.0, velocity_m_s=1269.001,
                         flight_path_rad=math.radians(-75.0) + 1e-9, alpha_rad=math.nan)
    assert [v["inside"] for v in out.values()] == [False, False, False]
    assert box_text("flight_path", out["flight_path"]) == "error +5.00 deg outside +-5 deg"
    assert box_text("velocity", out["velocity"]) == "error +50.00 m/s outside +-50 m/s"


def test_limit_checks_with_nan_samples_absolute_and_lower_bounds():
    """NaN samples are skipped (the peak is the finite maximum), a limit with no finite sample
    does not hold and does not stop the next one being checked; an absolute limit reads |bank|
    (-85 deg breaks an 80 deg limit); a lower bound met exactly holds, a 1 % breach of it holds
    only with a tolerance above 1 %."""
    t = np.array([0.0, 1.0, 2.0])
    cols = {"heat_flux": np.array([1.0, np.nan, 3.0]), "q": np.full(3, np.nan), "bank": np.radians([0.0, -85.0, 10.0]),
            "gamma": np.array([-0.5, -0.3, -0.4]), "g2": np.array([-0.505, -0.3, -0.4])}
    limits = [PathLimit("heat_flux", "heat_flux", upper=10.0), PathLimit("q", "q", upper=1.0),
              PathLimit("bank", "bank", upper=math.radians(80.0), absolute=True),
              PathLimit("gamma", "gamma", lower=-0.5), PathLimit("g2", "g2", lower=-0.5)]
    heat, q, bank, gamma, g2 = check_limits(t, cols.__getitem__, limits)
    assert heat.held and heat.peak == 3.0 and heat.time == 2.0 and heat.margin == pytest.approx(0.7)
    assert not q.held and math.isnan(q.peak) and math.isnan(q.margin) and q.limit.name == "q"
    assert not bank.held and bank.peak == pytest.approx(math.radians(85.0)) and bank.time == 1.0
    assert gamma.held and gamma.margin == 0.0 and not g2.held and g2.margin == pytest.approx(-0.01)
    widened = check_limits(t, cols.__getitem__, limits[3:], tolerance=0.011)
    assert [c.held for c in widened] == [True, True]
    assert [c.held for c in check_limits(t, cols.__getitem__, limits[3:], tolerance=0.009)] == [True, False]


def test_vehicle_limits_name_their_columns_units_and_print_their_bounds():
    """Every finite vehicle limit becomes a PathLimit on its own Trajectory column, printed in
    its display unit; the bank limit is on |bank| in degrees; two-sided and lower bounds print
    as intervals and '>='."""
    lims = vehicle_path_limits(PathLimits(heat_flux_max=500e3, dynamic_pressure_max=40e3, normal_load_max=2.5,
                                          total_load_max=3.0), bank_limit=math.radians(80.0))
    assert [(x.name, x.column, x.unit) for x in lims] == [
        ("heat_flux", "heat_flux", "kW/m^2"), ("dynamic_pressure", "dynamic_pressure", "kPa"),
        ("normal_load", "normal_load", "g"), ("total_load", "total_load", "g"), ("bank", "bank", "deg")]
    assert [x.bound_text() for x in lims] == ["<= 500 kW/m^2", "<= 40 kPa", "<= 2.5 g", "<= 3 g", "|.| <= 80 deg"]
    assert lims[-1].absolute and not any(x.absolute for x in lims[:-1])
    assert [x.name for x in vehicle_path_limits(PathLimits(heat_flux_max=1.0))] == ["heat_flux"]
    gamma = PathLimit("flight_path", "gamma", upper=math.radians(0.5), lower=math.radians(-30.0), unit="deg",
                      scale=180.0 / math.pi)
    assert gamma.bound_text() == "in [-30, 0.5] deg"
    assert PathLimit("h", "h", lower=20e3, unit="km", scale=1e-3).bound_text() == ">= 20 km"
    assert PathLimit("x", "x", lower=-1.0).bound_text() == ">= -1"


def test_texts_zero_bounds_and_the_recorded_tolerance():
    """A limit at 0 takes its margin in absolute terms (flight-path angle <= 0: a peak of 0.25
    rad is a margin of -0.25); a missed criterion reads in km (Mach as a number); breaches are
    joined by '; '; bounds without a unit print without a trailing space; the verdict records
    the tolerance it judged with; a limit without finite samples is not held, with no time."""
    from drake_entry.models.verdict import box_text, breaches_text

    t = np.array([0.0, 1.0])
    cols = {"gamma": np.array([-0.1, 0.25]), "q": np.array([np.nan, np.nan])}
    zero, q = check_limits(t, cols.__getitem__, [PathLimit("gamma", "gamma", upper=0.0), PathLimit("q", "q", upper=1.0)])
    assert zero.margin == pytest.approx(-0.25) and not zero.held
    assert q.held is False and math.isnan(q.time)
    assert breaches_text([zero, q]) == zero.text() + "; " + q.text() and breaches_text([zero]).startswith("gamma 0.25")
    assert box_text("distance", {"error": 2500.0, "tolerance": 2000.0}) == "error +2.500 km outside +-2 km"
    assert box_text("altitude", {"error": -1500.0, "tolerance": 1000.0}) == "error -1.500 km outside +-1 km"
    assert box_text("mach", {"error": 0.3, "tolerance": 0.2}) == "error +0.300 outside +-0.2"
    assert PathLimit("x", "x", lower=-1.0, upper=1.0).bound_text() == "in [-1, 1]"
    assert PathLimit("x", "x", upper=3.0).bound_text() == "<= 3"
    tr = _trajectory([0.0, 1.0], [1.0, 2.0])
    assert judge(tr, [], reached=True, inside_box=True, tolerance=0.02).tolerance == 0.02


def test_vertical_speed_and_geodetic_altitude_criteria_are_windows_about_their_values():
    """Paper 001's DRS box: V sin(gamma) in [-140, 0] m/s (eq. 65) and 10-13 km geodetic (eq. 64),
    each closed at its edges and missed just beyond them or when not measured."""
    from drake_entry.models.verdict import acceptance_box

    term = _terminal(mach=0.5, mach_tolerance=0.5, vertical_speed_m_s=-70.0, vertical_speed_tolerance_m_s=70.0,
                     geodetic_altitude_km=11.5, geodetic_altitude_tolerance_km=1.5)
    box = acceptance_box(term, altitude_m=2.5e3, mach=0.6, distance_m=0.0, vertical_speed_m_s=-140.0,
                         geodetic_altitude_m=10.0e3)
    assert box["vertical_speed"]["inside"] and box["geodetic_altitude"]["inside"]
    assert box["vertical_speed"]["error"] == pytest.approx(-70.0) and box["geodetic_altitude"]["error"] == -1.5e3
    box = acceptance_box(term, altitude_m=2.5e3, mach=0.6, distance_m=0.0, vertical_speed_m_s=-140.01,
                         geodetic_altitude_m=13.001e3)
    assert not box["vertical_speed"]["inside"] and not box["geodetic_altitude"]["inside"]
    box = acceptance_box(term, altitude_m=2.5e3, mach=0.6, distance_m=0.0)
    assert not box["vertical_speed"]["inside"] and not box["geodetic_altitude"]["inside"]


def test_a_scenario_box_measures_vertical_speed_and_geodetic_altitude_from_the_state():
    """Scenario.acceptance_box: V sin(gamma) from the state, the geodetic altitude on the oblate
    Earth at the state's latitude (the sphere-datum SPHYNX scenario: 2.5 km state = 10.17 km
    geodetic at the Azores site)."""
    from drake_entry.scenario import load_scenario

    s = load_scenario("sphynx_paper001")
    planet = s.make_planet()
    lat = math.radians(s.target.latitude_deg)
    x = np.array([2.5e3, math.radians(s.target.longitude_deg), lat, 200.0, math.radians(-15.0), 0.0])
    box = s.acceptance_box(planet, x, mach=0.6, distance_m=1e3)
    assert box["vertical_speed"]["error"] == pytest.approx(200.0 * math.sin(math.radians(-15.0)) + 70.0)
    geodetic = box["geodetic_altitude"]["error"] + 11.5e3
    assert geodetic == pytest.approx(float(planet.atmospheric_altitude(2.5e3, lat))) and 10.1e3 < geodetic < 10.25e3
    assert all(b["inside"] for b in box.values())


@pytest.mark.parametrize("terminal, needle", [
    ({"requirement_sources": {"altitud": "paper 000 Table 1"}},
     r"terminal.requirement_sources: 'altitud' names no requirement of this scenario; allowed: altitude, mach, "),
    ({"requirement_sources": {"heat_flux_limit": " "}}, r"terminal.requirement_sources.heat_flux_limit is empty"),
    ({"vertical_speed_tolerance_m_s": 70.0},
     r"terminal.vertical_speed_tolerance_m_s is given without terminal.vertical_speed_m_s"),
    ({"geodetic_altitude_km": 11.5, "geodetic_altitude_tolerance_km": -1.0},
     r"terminal.geodetic_altitude_tolerance_km = -1.0 is out of range"),
])
def test_a_bad_requirement_field_names_itself_and_what_is_allowed(terminal, needle):
    """Requirement sources name a box criterion or a path limit ('<limit>_limit') of the
    scenario; a window's tolerance needs its centre and is >= 0."""
    from drake_entry.errors import ScenarioError
    from drake_entry.scenario import load_scenario

    s = load_scenario("horus2b")
    s = dc.replace(s, terminal=dc.replace(s.terminal, **terminal))
    with pytest.raises(ScenarioError, match=needle):
        s.validate()


def test_the_requirement_table_names_each_source_and_lists_the_departures_not_judged():
    """shefex3_ampi: Table 1's altitude window judged with its source, the substitute target's
    25-km ring marked as a departure, Table 1's speed window listed NOT JUDGED with why."""
    from drake_entry.campaign.report import _requirements
    from drake_entry.scenario import load_scenario

    rows = {"index": [0, 1], "inside_altitude_box": [True, False], "box_altitude_error": [100.0, -2600.0],
            "inside_distance_box": [True, True], "box_distance_error": [1e3, 2e3]}
    text = _requirements(rows, np.array([True, True]), {"margins": {}}, load_scenario("shefex3_ampi"))
    assert ("| terminal altitude | in [21, 26] km | largest distance from the centre 23.5 km of 2 | 2.6 km | -0.1 km | "
            "FAIL (1 of 2 inside) | paper 003 Table 1 |") in text
    assert "| distance to the target | ≤ 25 km | largest value of 2 | 2 km | 23 km | PASS (2 of 2 inside) | departure: " in text
    assert ("| terminal speed in [570, 620] m/s (paper 003 Table 1) | not judged | — | — | — | NOT JUDGED | departure: "
            "the packaged database's references end at the window's 620 m/s corner") in text


def test_the_stored_trajectory_keeps_each_flights_peaks_between_its_storage_points():
    """A campaign stores a flight every 10 s (campaign.sample.downsample); a heat-flux pulse
    peaking at t = 13 s and a flight-path dip to -31 deg at t = 27 s, both between storage points,
    are kept at their log samples, so the path figure's line reaches them; without them the
    stored maxima would be 0.5 q_max and -5 deg."""
    from drake_entry.campaign.sample import downsample

    t = np.arange(0.0, 41.0, 1.0)
    heat = 1e5 * (1.0 + 0.5 * (t == 13.0)) * np.where(t == 13.0, 2.0, 0.5)
    gamma = np.radians(np.where(t == 27.0, -31.0, -5.0))
    stored = downsample(_trajectory(t, heat, gamma=gamma), 7, 10.0)
    assert stored["time_s"] == [0.0, 10.0, 13.0, 20.0, 27.0, 30.0, 40.0]
    assert max(stored["heat_flux_W_m2"]) == pytest.approx(3e5) and min(stored["flight_path_deg"]) == pytest.approx(-31.0)
    assert set(stored["sample"]) == {7}
    plain = downsample(_trajectory(t, np.full(t.size, 1e5), gamma=np.full(t.size, -0.1)), 0, 10.0)
    assert plain["time_s"][:2] == [0.0, 10.0] and plain["time_s"][-1] == 40.0  # nothing added when flat: ties at 0


def test_a_bank_clamped_at_its_limit_holds_in_the_verdict_and_in_every_report_count():
    """A margin of -1e-16 (a clamp at the bound, rounded) holds; -1e-9 breaches; the campaign's
    and the comparison's breach counts use the verdict's test, with the scenario's tolerance."""
    from drake_entry.campaign.report import summary_statistics
    from drake_entry.comparison.report import method_summary
    from drake_entry.models.verdict import margin_breached

    bank = PathLimit("bank", "bank", upper=math.radians(60.0), absolute=True)
    clamped = math.radians(60.0) * (1.0 + 1e-16)
    (c,) = check_limits([0.0, 1.0], lambda _: np.array([0.1, clamped]), [bank])
    assert c.held and c.margin <= 0.0
    (c,) = check_limits([0.0, 1.0], lambda _: np.array([0.1, math.radians(60.0) * (1.0 + 1e-9)]), [bank])
    assert not c.held
    assert list(margin_breached([-1e-16, -1e-9, 0.0, 0.01])) == [False, True, False, False]
    assert list(margin_breached([-1e-9, -0.02], tolerance=0.01)) == [False, True]
    rows = {"index": [0, 1, 2], "success": [True, True, False], "reached_terminal": [True] * 3,
            "inside_box": [True] * 3, "within_limits": [True, True, False], "err_distance_m": [1.0, 2.0, 3.0],
            "message": ["ok", "ok", "path limits breached: bank"], "margin_bank": [-1e-16, 0.2, -1e-9]}
    assert summary_statistics(rows)["margins"]["margin_bank"]["violations"] == 1
    assert summary_statistics(rows, tolerance=0.01)["margins"]["margin_bank"]["violations"] == 0
    assert method_summary(rows)["margins"]["margin_bank"]["breached"] == 1
