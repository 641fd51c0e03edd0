"""Abort reachability (paper 001 Sec. VI) and the generic campaign of cases it runs on: the EIP
grid and descent-abort cases, feasibility and the Tables 4-7 statistics, a failing case
recorded without losing the others, and one real orbital abort planned and flown by Drake."""
import json
import math
import os

import numpy as np
import pytest

from drake_entry.campaign.backends import Task, run_processes, worker_memory_budget
from drake_entry.campaign.engine import run_cases, task_manifest
from drake_entry.campaign.store import read_rows
from drake_entry.errors import CampaignError, ScenarioError
from drake_entry.guidance.scvx.aborts.cases import (
    PAPER_TABLES,
    abort_statistics,
    case_mission,
    descent_abort_cases,
    feasible,
    heading_offset,
    orbital_abort_cases,
    statistics_markdown,
)
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.models.planet import Earth


# ----- the generic campaign of cases ---------------------------------------------------------
def toy_setup(config):
    return {"scale": config["scale"]}


def toy_run(state, case):
    if case["x"] < 0:
        raise ValueError(f"negative x {case['x']}")
    return {"index": case["index"], "success": True, "y": state["scale"] * case["x"] ** 2}, None


TOY = Task("test_aborts:toy_setup", "test_aborts:toy_run", {"scale": 3.0})


def pid_run(state, case):
    """The toy case, answering with its worker's process id; x = 13 ends its worker abruptly."""
    if case["x"] == 13.0:
        os._exit(3)
    row, traj = toy_run(state, case)
    return {**row, "pid": os.getpid()}, traj


PID_TOY = Task("test_aborts:toy_setup", "test_aborts:pid_run", {"scale": 3.0})


@pytest.mark.parametrize("backend, workers", [("serial", 1), ("processes", 2)])
def test_a_failing_case_is_a_row_with_its_reason_and_the_others_finish(tmp_path, backend, workers):
    cases = [{"index": i, "x": x} for i, x in enumerate([1.0, -2.0, 3.0])]
    run_cases(TOY, cases, str(tmp_path), task_manifest(TOY, cases), backend=backend, workers=workers,
              progress=False)
    rows, _ = read_rows(str(tmp_path))
    assert rows[0]["y"] == 3.0 and rows[2]["y"] == 27.0
    assert rows[1]["success"] is False and "ValueError: negative x -2.0" in rows[1]["message"]
    assert rows[1]["x"] == -2.0  # the case's columns identify it


def test_a_worker_past_its_memory_budget_retires_and_a_new_one_takes_the_rest():
    rows = []
    run_processes(PID_TOY, [{"index": i, "x": float(i)} for i in range(5)], lambda r, t: rows.append(r), workers=2,
                  memory_budget=0)
    assert sorted(r["index"] for r in rows) == list(range(5)) and all(r["success"] for r in rows)
    assert len({r["pid"] for r in rows}) == 5  # every case on a fresh worker: each retired after one
    assert sorted(r["y"] for r in rows) == [3.0 * i ** 2 for i in range(5)]
    rows.clear()  # within the budget one worker runs many cases
    run_processes(PID_TOY, [{"index": i, "x": float(i)} for i in range(6)], lambda r, t: rows.append(r), workers=2,
                  memory_budget=worker_memory_budget(2))
    assert len(rows) == 6 and len({r["pid"] for r in rows}) <= 2


def test_a_serial_campaign_past_its_memory_budget_hands_the_rest_to_a_worker_process():
    """This process runs the cases until it holds more than its budget after one, then one worker
    process (retiring as the pool's do) takes every case left, none lost or repeated."""
    from drake_entry.campaign.backends import run_serial

    rows = []
    cases = iter([{"index": i, "x": float(i)} for i in range(4)])  # a lazy iterable, as a campaign's
    run_serial(PID_TOY, cases, lambda r, t: rows.append(r), memory_budget=0)
    assert [r["index"] for r in rows] == [0, 1, 2, 3] and [r["y"] for r in rows] == [3.0 * i ** 2 for i in range(4)]
    assert rows[0]["pid"] == os.getpid() and all(r["pid"] != os.getpid() for r in rows[1:])
    rows.clear()  # within the budget every case stays here
    run_serial(PID_TOY, [{"index": i, "x": float(i)} for i in range(3)], lambda r, t: rows.append(r))
    assert {r["pid"] for r in rows} == {os.getpid()}


def test_a_worker_that_dies_leaves_its_case_a_failed_row_and_the_campaign_goes_on(tmp_path):
    cases = [{"index": i, "x": x} for i, x in enumerate([1.0, 13.0, 2.0, 3.0])]
    run_cases(PID_TOY, cases, str(tmp_path), task_manifest(PID_TOY, cases), backend="processes", workers=2,
              progress=False)
    rows, _ = read_rows(str(tmp_path))
    assert sorted(rows) == [0, 1, 2, 3]
    assert rows[1]["success"] is False and "worker process died during the case, exit code 3" in rows[1]["message"]
    assert [rows[i]["y"] for i in (0, 2, 3)] == [3.0, 12.0, 27.0]


def test_cases_resume_and_another_case_list_is_refused(tmp_path):
    cases = [{"index": i, "x": float(i)} for i in range(3)]
    out = str(tmp_path)
    run_cases(TOY, cases[:2], out, task_manifest(TOY, cases), backend="serial", progress=False)
    with open(tmp_path / "samples.jsonl") as f:
        assert len(f.readlines()) == 2
    run_cases(TOY, cases, out, task_manifest(TOY, cases), backend="serial", progress=False)
    with open(tmp_path / "samples.jsonl") as f:
        assert [json.loads(line)["index"] for line in f] == [0, 1, 2]  # only the missing case ran
    other = [{"index": 0, "x": 5.0}]
    with pytest.raises(CampaignError, match="case list"):
        run_cases(TOY, other, out, task_manifest(TOY, other), backend="serial", progress=False)
    with pytest.raises(ScenarioError, match="unique integer 'index'"):
        run_cases(TOY, [{"index": 0}, {"index": 0}], str(tmp_path / "x"), {}, backend="serial", progress=False)


def test_a_worker_whose_setup_fails_reports_it_on_every_case(tmp_path):
    bad = Task("test_aborts:no_such_function", "test_aborts:toy_run", {})
    cases = [{"index": 0, "x": 1.0}, {"index": 1, "x": 2.0}]
    run_cases(bad, cases, str(tmp_path), task_manifest(bad, cases), backend="serial", progress=False)
    rows, _ = read_rows(str(tmp_path))
    assert all(not r["success"] and "worker set-up failed: AttributeError" in r["message"] for r in rows.values())


# ----- abort cases ----------------------------------------------------------------------------
def test_orbital_grid_is_centred_on_the_nominal_eip_and_sees_the_site_as_it_does():
    planet, mission = Earth.oblate(), ScvxMission()
    cases = orbital_abort_cases(mission, planet)
    assert len(cases) == 81 and [c["index"] for c in cases] == list(range(81))
    lon = sorted({c["entry_longitude_deg"] for c in cases})
    lat = sorted({c["entry_latitude_deg"] for c in cases})
    assert np.diff(lon) == pytest.approx(np.full(8, 5.0)) and np.diff(lat) == pytest.approx(np.full(8, 5.0))
    centre = cases[40]
    assert (centre["entry_longitude_deg"], centre["entry_latitude_deg"]) == (-115.0, 30.0)
    assert centre["entry_heading_deg"] == pytest.approx(mission.entry_heading_deg, abs=1e-9)
    assert centre["range_km"] == pytest.approx(8076.0, abs=5.0)  # paper 001 Table 1 mission (notes: 8076 km)
    # the offset is Table 1's heading minus the initial great-circle bearing from the EIP to the
    # site, computed here by the spherical-trigonometry formula on the geocentric coordinates
    x0, (lon_s, lat_s) = mission.entry_state(planet), mission.site(planet)
    dlon = lon_s - x0[1]
    bearing = math.degrees(math.atan2(math.sin(dlon) * math.cos(lat_s), math.cos(x0[2]) * math.sin(lat_s)
                                      - math.sin(x0[2]) * math.cos(lat_s) * math.cos(dlon)))
    expected = mission.entry_heading_deg - bearing
    assert heading_offset(mission, planet) == pytest.approx(expected, abs=1e-9)
    assert expected == pytest.approx(-14.05, abs=0.01)  # regression pin of the value
    for c in cases:  # every EIP keeps the nominal's heading offset from the bearing to the site
        assert heading_offset(case_mission(mission, c), planet) == pytest.approx(expected, abs=1e-6)
    with pytest.raises(ScenarioError, match="rows = 0"):
        orbital_abort_cases(mission, planet, shape=(0, 3))
    with pytest.raises(ScenarioError, match="within 80 deg"):
        orbital_abort_cases(mission, planet, shape=(23, 3), spacing_deg=5.0)


def test_descent_abort_cases_start_from_the_flown_state_and_attitude():
    planet = Earth.oblate()
    t = np.linspace(0.0, 400.0, 81)
    x0 = ScvxMission().entry_state(planet)
    states = np.array([x0 + [-100.0 * s, 1e-5 * s, 5e-6 * s, -2.0 * s, 0.0, 1e-4 * s] for s in t])
    bank, alpha = np.radians(30.0 + 0.01 * t), np.radians(np.full(t.size, 38.0))
    cases = descent_abort_cases(t, states, bank, alpha, planet, site=(-7.95, 32.23), spacing_s=100.0)
    assert [c["abort_time_s"] for c in cases] == [100.0, 200.0, 300.0]
    for c in cases:
        mission = case_mission(ScvxMission(), c)
        k = int(np.searchsorted(t, c["abort_time_s"]))
        assert mission.entry_state(planet) == pytest.approx(states[k], rel=1e-9, abs=1e-6)  # geodetic round trip
        assert c["entry_bank_deg"] == pytest.approx(30.0 + 0.01 * c["abort_time_s"])
        assert (mission.site_longitude_deg, mission.site_latitude_deg) == (-7.95, 32.23)


def test_feasibility_and_tables_4_to_7_statistics():
    base = {"plan_success": True, "planned_miss_km": 9.9, **{q: 1.0 for t in PAPER_TABLES.values() for q in t}}
    rows = [dict(base, flown_miss_km=5.0, heat_load_MJ_m2=500.0), dict(base, flown_miss_km=30.0, heat_load_MJ_m2=600.0),
            dict(base, flown_miss_km=50.0), dict(base, plan_success=False, flown_miss_km=1.0),
            dict(base, planned_miss_km=12.0, flown_miss_km=1.0)]
    assert [feasible(r, 10e3) for r in rows] == [True, False, False, False, False]
    assert [feasible(r, 40e3) for r in rows] == [True, True, False, False, False]
    stats = abort_statistics(rows, 40e3)
    assert stats["Table 4"]["heat_load_MJ_m2"] == pytest.approx((550.0, 50.0, 600.0, 500.0))
    text = statistics_markdown(stats)
    assert "550 / 564.9" in text and "Table 7 form" in text  # 564.9 MJ/m^2: paper 001 Table 4 mean heat load
    assert all(math.isnan(v) for v in abort_statistics(rows[3:], 40e3)["Table 5"]["drs_mach"])


def test_one_orbital_abort_is_planned_flown_and_reported(tmp_path):
    """The nominal EIP as a 1 x 1 map through the campaign engine: the plan succeeds and its
    Drake flight ends inside the 10-km radius (measured 9.97 km flown, 476 MJ/m^2); the report
    carries the Tables 4-7 form and the maps."""
    from drake_entry.guidance.scvx.aborts.report import write_abort_report
    from drake_entry.guidance.scvx.aborts.study import run_orbital_aborts

    out = run_orbital_aborts(str(tmp_path), shape=(1, 1), backend="serial", progress=False)
    rows, _ = read_rows(out)
    row = rows[0]
    assert row["plan_success"], row["message"]
    assert row["feasible_10km"] and row["feasible_40km"] and row["success"]
    assert 460.0 < row["heat_load_MJ_m2"] < 500.0
    assert row["flown_from_plan_km"] < 5.0 and row["max_heat_flux_kW_m2"] <= 670.0 * (1 + 1e-6)
    assert row["mean_socp_iterations"] > 5 and row["iterations"] <= 60
    report = open(write_abort_report(out)).read()
    assert "Feasible at 10 km" in report and "**Table 4 form**" in report
    assert (tmp_path / "reachability_map.png").exists() and (tmp_path / "attitude.png").exists()


def test_descent_aborts_stop_where_the_planner_cannot_start():
    """A flown descent slowing from 7000 m/s to 300 m/s at 1500 s: of the triggers every 100 s the
    one at 1500 s (300 m/s, below the planner's 500 m/s) is not a case (the last three of the
    nominal's 33 used to raise 'entry_speed_m_s out of range')."""
    import numpy as np

    from drake_entry.guidance.scvx.aborts.cases import descent_abort_cases
    from drake_entry.models.planet import Earth

    t = np.linspace(0.0, 1600.0, 161)
    states = np.zeros((t.size, 6))
    states[:, 0], states[:, 3] = 60e3, np.maximum(7000.0 - 6700.0 * t / 1500.0, 300.0)
    cases = descent_abort_cases(t, states, np.zeros(t.size), np.radians(np.full(t.size, 30.0)), Earth.oblate(),
                                site=(-7.95, 32.23), spacing_s=100.0)
    speeds = [c["entry_speed_m_s"] for c in cases]
    assert min(speeds) >= 500.0 and [c["abort_time_s"] for c in cases] == [100.0 * k for k in range(1, 15)]
