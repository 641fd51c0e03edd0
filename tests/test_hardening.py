"""Hardening: no hang, no traceback, no false success, no silently mixed campaign. Each test
reproduces one finding from the packaged horus2b scenario or the API."""
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from drake_entry.cli import main
from drake_entry.errors import CampaignError, DrakeEntryError, ScenarioError
from drake_entry.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
HORUS = (ROOT / "drake_entry/scenarios/horus2b.yaml").read_text()


def _scenario_file(tmp_path, old: str, new: str, name: str = "s.yaml") -> str:
    assert old in HORUS, old
    path = tmp_path / name
    path.write_text(HORUS.replace(old, new))
    return str(path)


def _one_line_error(capsys, argv) -> str:
    """Run the CLI; it must exit 2 with one line on stderr and no traceback."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, (argv, code, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


# -- hangs ----------------------------------------------------------------------------------
def test_campaign_of_an_unloadable_scenario_fails_at_once_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "x"
    t0 = time.perf_counter()
    err = _one_line_error(capsys, ["campaign", "horus2", "--runs", "4", "--workers", "2", "--out", str(out)])
    assert "horus2" in err and time.perf_counter() - t0 < 30
    assert not (out / "campaign.json").exists()


def test_a_nan_in_a_schedule_is_refused_and_a_nan_command_stops_the_run(tmp_path):
    bad = _scenario_file(tmp_path, "values_deg: [0.0, 0.0, 60.0]", "values_deg: [0.0, 0.0, .nan]")
    with pytest.raises(ScenarioError, match=r"bank.values_deg\[2\] = nan is not a finite number"):
        load_scenario(bad)
    # the guard behind the validation: NaN derivatives stop the integrator with a reason
    from drake_entry.diagrams.open_loop import simulate
    from drake_entry.models.schedules import Schedule

    s = load_scenario("horus2b")
    s.schedule = lambda which: (Schedule((0.0, 100.0), (0.0, math.nan), "time") if which == "bank"
                                else type(s).schedule(s, which))
    # the Python plant stops inside the derivative; the native one (no Python there) at the end of
    # the step, in the termination monitor's witness
    for plant, reason in (("python", "non-finite state derivative at h = "), ("native", "non-finite vehicle state at t = ")):
        s.simulation.plant = plant
        t0 = time.perf_counter()
        tr = simulate(s)
        assert time.perf_counter() - t0 < 20
        assert tr.reason.startswith("stopped at t = ") and reason in tr.reason, (plant, tr.reason)
        assert np.isfinite(tr.state).all()


# -- false success --------------------------------------------------------------------------
def test_a_flight_outside_the_acceptance_box_is_not_a_success(tmp_path, capsys):
    moved = _scenario_file(tmp_path, "  latitude_deg: 5.0\n", "  latitude_deg: 25.0\n")
    assert main(["fly", moved, "--out", str(tmp_path / "fly")]) == 1
    s = json.loads((tmp_path / "fly" / "summary.json").read_text())
    assert not s["success"] and s["message"].startswith("outside the acceptance box: distance")
    assert s["err_distance_m"] > 100e3 and s["inside_distance_box"] is False


# -- extreme physics ends with a named reason -----------------------------------------------
def test_skip_out_and_ground_impact_end_with_a_terminal_reason():
    from drake_entry.diagrams.open_loop import simulate

    s = load_scenario("horus2b")
    s.entry.velocity_m_s, s.entry.flight_path_deg = 11500.0, 2.0
    tr = simulate(s)
    assert tr.reason.startswith("skipped out above the atmosphere"), tr.reason
    s = load_scenario("horus2b")
    s.terminal.altitude_km, s.terminal.mach = None, None
    s.terminal.velocity_m_s = 1.0  # never reached: the vehicle meets the ground first
    s.entry.flight_path_deg = -30.0
    tr = simulate(s)
    assert tr.reason.startswith("reached the surface"), tr.reason
    assert tr.state[-1, 0] == pytest.approx(0.0, abs=1.0)


# -- campaign store -------------------------------------------------------------------------
def _run(tmp_path, scenario="horus2b", runs=2, out="c", **kw):
    from drake_entry.campaign.montecarlo import run_campaign

    kw.setdefault("workers", 1)
    return run_campaign(scenario, runs=runs, out_dir=str(tmp_path / out), seed=kw.pop("seed", 3), progress=False,
                        trajectory_step_s=kw.pop("trajectory_step_s", 100.0), **kw)


def test_a_campaign_refuses_other_settings_and_extends_with_more_runs(tmp_path):
    path = _scenario_file(tmp_path, "replan_until_e: 0.99", "replan_until_e: 0.99")
    out = _run(tmp_path, path, runs=1)
    Path(path).write_text(HORUS.replace("replan_until_e: 0.99", "replan_until_e: 0.95"))
    with pytest.raises(CampaignError, match="another scenario content; extend it with the same settings"):
        _run(tmp_path, path, runs=2)
    Path(path).write_text(HORUS)
    with pytest.raises(CampaignError, match="another trajectory step"):
        _run(tmp_path, path, runs=2, trajectory_step_s=1.0)
    os.chdir(tmp_path)  # ./s.yaml and s.yaml and the absolute path are the same campaign
    _run(tmp_path, "./s.yaml", runs=2)
    _run(tmp_path, "s.yaml", runs=1)  # fewer runs than done: nothing to do, nothing forgotten
    manifest = json.loads((Path(out) / "campaign.json").read_text())
    assert manifest["runs"] == 2 and manifest["scenario"] == str(tmp_path / "s.yaml")
    assert len((Path(out) / "samples.jsonl").read_text().splitlines()) == 2


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
def test_report_covers_partial_killed_and_all_failed_campaigns(tmp_path, capsys):
    from drake_entry.campaign.report import write_report

    assert "is not a directory: no campaign" in _one_line_error(capsys, ["report", str(tmp_path / "missing")])
    assert "holds no campaign" in _one_line_error(capsys, ["report", str(tmp_path)])
    # every sample failed (an engagement that never comes): a report that says so
    path = _scenario_file(tmp_path, "pre_guidance_min_s: 100.0", "pre_guidance_min_s: 99999.0")
    out = _run(tmp_path, path, runs=2, out="failed")
    text = Path(write_report(out)).read_text()
    assert "Covers 2 of 2 requested samples: 0 successful" in text
    assert "guidance never engaged" in text
    # a killed extension: the report counts the rows on disk, not the old Parquet
    out = _run(tmp_path, runs=2, out="ext")
    manifest = json.loads((Path(out) / "campaign.json").read_text())
    (Path(out) / "campaign.json").write_text(json.dumps(dict(manifest, runs=5)))
    with open(Path(out) / "samples.jsonl", "a") as f:
        f.write('{"index": 2, "succ')
    text = Path(write_report(out)).read_text()
    assert "Covers 2 of 5 requested samples (**incomplete**: 3 not run" in text
    assert "1 cut last line(s)" in text
    os.chdir(tmp_path / "failed")  # the report reads the scenario as flown from the manifest, anywhere
    assert main(["report", str(Path(out).resolve())]) == 0
    assert "2/5 samples done" in capsys.readouterr().out


def test_a_campaign_of_the_previous_format_is_reported_but_not_extended(tmp_path, capsys):
    old = tmp_path / "old"
    old.mkdir()
    row = {"index": 0, "seed": 1, "success": True, "stop": "reached energy", "message": "ok", "err_distance_m": 10.0,
           "reached_terminal": True, "inside_box": True, "within_limits": True, "flight_time_s": 1500.0}
    (old / "samples.jsonl").write_text(json.dumps(row) + "\n")
    (old / "campaign.json").write_text(json.dumps({"scenario": "horus2b", "runs": 1, "seed": 0, "overrides": {}}))
    assert "written by an older drake_entry (format 1)" in _one_line_error(
        capsys, ["campaign", "horus2b", "--runs", "2", "--out", str(old)])
    assert main(["report", str(old)]) == 0 and "1/1 samples done" in capsys.readouterr().out


def test_lines_that_are_not_rows_are_quarantined_and_cut_rows_do_not_duplicate_trajectories(tmp_path):
    from drake_entry.campaign.store import read_rows

    out = Path(_run(tmp_path, runs=2))
    rows = (out / "samples.jsonl").read_text().splitlines()
    traj = (out / "trajectories.jsonl").read_text().splitlines()
    assert len(rows) == len(traj) == 2
    # a kill after sample 1's trajectory line but inside its row line; and two foreign lines
    (out / "samples.jsonl").write_text(rows[0] + "\n42\n{\"foo\": 1}\n" + rows[1][:25])
    _run(tmp_path, runs=3)
    done, counts = read_rows(str(out))
    assert sorted(done) == [0, 1, 2] and counts == {"cut": 0, "invalid": 0, "duplicates": 0}
    quarantined = [json.loads(line) for line in (out / "quarantine.jsonl").read_text().splitlines()]
    assert [q["line"] for q in quarantined] == ["42", '{"foo": 1}']
    import pyarrow.parquet as pq

    t = pq.read_table(out / "trajectories.parquet").to_pydict()
    assert sorted(set(t["sample"])) == [0, 1, 2]
    times_1 = [time for s, time in zip(t["sample"], t["time_s"]) if s == 1]
    assert len(times_1) > 100 and all(b > a for a, b in zip(times_1, times_1[1:]))  # sample 1 kept once, not twice


def test_a_second_writer_is_refused(tmp_path):
    out = tmp_path / "busy"
    code = ("import sys, time; from drake_entry.campaign.store import CampaignStore; "
            f"s = CampaignStore({str(out)!r}, {{'runs': 1, 'seed': 0}}); print('locked', flush=True); time.sleep(60)")
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert holder.stdout.readline().strip() == "locked"
        from drake_entry.campaign.store import CampaignStore

        with pytest.raises(CampaignError, match="is being written by another campaign process"):
            CampaignStore(str(out), {"runs": 1, "seed": 0})
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    CampaignStore(str(out), {"runs": 1, "seed": 0}).close()  # a killed writer's lock is gone with it


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
def test_repeated_kills_lose_and_repeat_no_sample(tmp_path):
    """SIGKILL three times, each once the campaign has written 1, 3 and 4 rows (asserted: every
    kill landed mid-campaign), then resume: every sample once, each trajectory once."""
    out = tmp_path / "killed"
    code = ("from drake_entry.campaign.montecarlo import run_campaign; "
            f"run_campaign('horus2b', runs=6, out_dir={str(out)!r}, seed=5, workers=1, progress=False)")
    def rows_done() -> int:
        try:
            return sum(1 for line in (out / "samples.jsonl").read_text().splitlines() if line.endswith("}"))
        except FileNotFoundError:
            return 0

    killed_at = []
    for target in (1, 3, 4):  # each kill lands once the campaign has this many rows, mid-run
        p = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path)
        deadline = time.monotonic() + 300
        while rows_done() < target and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert p.poll() is None, f"the campaign ended before the kill at {target} rows"
        p.send_signal(signal.SIGKILL)
        p.wait()
        killed_at.append(rows_done())
    assert all(0 < k < 6 for k in killed_at) and killed_at == sorted(killed_at), killed_at
    subprocess.run([sys.executable, "-c", code], cwd=tmp_path, check=True, timeout=300)
    rows = [json.loads(line) for line in (out / "samples.jsonl").read_text().splitlines()]
    assert sorted(r["index"] for r in rows) == list(range(6))
    import pyarrow.parquet as pq

    t = pq.read_table(out / "trajectories.parquet").to_pydict()
    assert sorted(set(t["sample"])) == list(range(6))
    for s in range(6):  # no sample's trajectory appended twice: each one's times strictly increase
        times = [time for k, time in zip(t["sample"], t["time_s"]) if k == s]
        assert len(times) > 100 and all(b > a for a, b in zip(times, times[1:])), s


# -- one line where a traceback was --------------------------------------------------------
@pytest.mark.parametrize("argv, needle", [
    (["campaign", "horus2b", "--runs", "0"], "runs = 0"),
    (["campaign", "horus2b", "--trajectory-step", "-1"], "trajectory_step_s = -1.0"),
    (["campaign", "horus2b", "--seed", "-1"], "seed = -1"),
    (["campaign", "horus2b", "--workers", "-2"], "workers = -2"),
    (["optimize", "marv", "--nodes", "1"], "nodes"),
    (["optimize", "marv", "--nodes", "0"], "nodes"),
    (["optimize", "marv", "--tolerance", "0"], "tolerance"),
    (["optimize", "marv", "--segments", "0"], "segments = 0"),
    (["optimize", "marv", "--segments", "3"], "nodes = 125 with segments = 3"),
    (["optimize", "marv", "--transcription", "dircol", "--segments", "4"], "lgl transcription only"),
    (["simulate", "/"], "directory"),
])
def test_cli_bad_arguments_are_one_line(argv, needle, capsys, tmp_path):
    argv = [a if a != "/" else str(tmp_path) for a in argv]
    assert needle in _one_line_error(capsys, argv + (["--out", str(tmp_path / "o")] if argv[0] != "report" else []))


def test_out_naming_a_file_and_bad_scenario_files_are_one_line(tmp_path, capsys):
    f = tmp_path / "afile"
    f.write_text("x")
    for command in ("campaign", "simulate", "fly", "plan"):
        assert "is a file" in _one_line_error(capsys, [command, "horus2b", "--out", str(f)])
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    _one_line_error(capsys, ["simulate", str(empty), "--out", str(tmp_path / "o")])
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(bytes(range(256)))
    _one_line_error(capsys, ["simulate", str(binary), "--out", str(tmp_path / "o")])


def _vehicle_file(tmp_path, **changes) -> str:
    text = (ROOT / "drake_entry/vehicles/horus2b.yaml").read_text()
    for old, new in changes.items():
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "v.yaml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("old, new, needle", [
    ("  latitude_deg: 5.0\n", "  latitude_deg: .nan\n", "target.latitude_deg = nan"),
    ("reversal_heading_deg: [5.0, 15.0]", "reversal_heading_deg: [.nan, 15.0]", "reversal_heading_deg"),
    ("pre_guidance_bank_deg: 0.0", "pre_guidance_bank_deg: .nan", "pre_guidance_bank_deg = nan"),
    ("pre_guidance_min_s: 100.0", "pre_guidance_min_s: .nan", "pre_guidance_min_s = nan"),
    ("values_deg: [40.0, 15.0]", "values_deg: [.nan, 15.0]", "alpha.values_deg[0] = nan"),
    ("values_deg: [40.0, 15.0]", "values_deg: [1e6, 15.0]", "alpha.values_deg[0] = 1000000.0 is out of range"),
    ("breakpoints: [0.87, 0.98]", "breakpoints: [0.87, 1e6]", "alpha.breakpoints[1] (normalized_energy)"),
    ("  period_s: 1.0", "  period_s: 0.0", "guidance.period_s = 0.0"),
    ("  period_s: 1.0", "  period_s: .nan", "guidance.period_s = nan"),
    ("  corridor_points: 300", "  corridor_points: 1", "corridor_points = 1"),
    ("  mach_tolerance: 0.5", "  mach_tolerance: -0.5", "terminal.mach_tolerance = -0.5"),
    ("  mach: 2.5\n", "  mach: 2.5\n  velocity_m_s: .nan\n", "terminal.velocity_m_s = nan"),
    ("  mach: 2.5\n", "  mach: 2.5\n  energy_MJ_kg: 5.0\n", "terminal.energy_MJ_kg = 5.0"),
    ("altitude_m: !Uniform {min: -250.0, max: 250.0}", "altitude_m: !Uniform {min: 250.0, max: -250.0}",
     "dispersions.entry.altitude_m"),
    ("altitude_m: !Uniform {min: -250.0, max: 250.0}", "altitude_m: !Gaussian {mean: 0.0, stddev: -1.0}",
     "dispersions.entry.altitude_m"),
])
def test_bad_scenario_values_are_one_line_naming_the_field(tmp_path, capsys, old, new, needle):
    if "corridor_points" in old:
        old, new = "  corridor_margin: 0.05", "  corridor_margin: 0.05\n  corridor_points: 1"
    path = _scenario_file(tmp_path, old, new)
    err = _one_line_error(capsys, ["simulate", path, "--out", str(tmp_path / "o")])
    assert needle in err, err


@pytest.mark.parametrize("old, new, needle", [
    ("bank_rate_limit_deg_s: 20.0", "bank_rate_limit_deg_s: 0.0", "bank_rate_limit_deg_s = 0.0"),
    ("mach_min: 1.2", "mach_min: 40.0", "mach_min"),
])
def test_bad_vehicle_values_are_one_line(tmp_path, capsys, old, new, needle):
    vehicle = _vehicle_file(tmp_path, **{old: new}) if old in (ROOT / "drake_entry/vehicles/horus2b.yaml").read_text() \
        else _vehicle_file(tmp_path, **{"mass_kg:": f"{old}\nmass_kg:"}).replace(old, new)
    path = _scenario_file(tmp_path, "vehicle: horus2b", f"vehicle: {vehicle}")
    err = _one_line_error(capsys, ["simulate", path, "--out", str(tmp_path / "o")])
    assert needle in err, err


@pytest.mark.parametrize("csv_text", ["coefficient,alpha_deg,M2.0,M4.0\n",
                                      "coefficient,alpha_deg,M2.0,M4.0\nCX,10,0.1,0.2\nCD,20,0.1,0.2\n",
                                      "coefficient,alpha_deg,Mfoo,M4.0\nCL,10,0.1,0.2\nCD,20,0.1,0.2\n",
                                      "coefficient,alpha_deg,M2.0,M4.0\nCL,ten,0.1,0.2\nCD,20,0.1,0.2\n",
                                      "coefficient,alpha_deg,M2.0,M4.0\nCL,10,0.1,0.2\nCL,20,0.3,0.4\nCL,10,0.5,0.6\n"
                                      "CD,10,0.1,0.2\nCD,20,0.1,0.2\n"])
def test_bad_aero_tables_are_one_line(tmp_path, capsys, csv_text):
    (tmp_path / "aero.csv").write_text(csv_text)
    text = (ROOT / "drake_entry/vehicles/horus2b.yaml").read_text().replace(
        "table_csv: horus2b_clean_aero_m692.csv", f"table_csv: {tmp_path / 'aero.csv'}").replace(
        "    fill_csv: horus2b_clean_aero_fill_2024.csv\n", "").replace("default_aero: fit", "default_aero: table")
    (tmp_path / "v.yaml").write_text(text)
    path = _scenario_file(tmp_path, "vehicle: horus2b\naero: fit", f"vehicle: {tmp_path / 'v.yaml'}\naero: table")
    err = _one_line_error(capsys, ["simulate", path, "--out", str(tmp_path / "o")])
    assert "aero table" in err
    if "CL,10,0.5" in csv_text:  # a repeated row was kept silently (the later one) before
        assert "row 4: CL at alpha 10 deg is given twice (row 2 too)" in err, err


def test_bad_problem_files_are_one_line(tmp_path, capsys):
    text = (ROOT / "drake_entry/problems/marv.yaml").read_text()
    for old, new, needle in (("solver: snopt", "solver: minos", "solve.solver = 'minos'"),
                             ("nodes: 125", "nodes: 1", "solve.nodes = 1"),
                             ("max_iterations: 3000", "max_iterations: -1", "solve.max_iterations = -1"),
                             ("tolerance: 1.0e-7", "tolerance: .nan", "solve.tolerance = nan"),
                             ("coarse_nodes: 60", "coarse_nodes: -60", "solve.coarse_nodes = -60"),
                             ("altitude_km: {value: 0.0}", "altitude_km: {value: .nan}", "value = nan")):
        assert old in text, old
        path = tmp_path / "p.yaml"
        path.write_text(text.replace(old, new))
        assert needle in _one_line_error(capsys, ["optimize", str(path), "--out", str(tmp_path / "o")])


def test_api_inputs_are_checked():
    from drake_entry.models.aerodynamics import HorusFitAero
    from drake_entry.models.atmosphere import ExponentialAtmosphere
    from drake_entry.models.dynamics import state_derivatives
    from drake_entry.models.planet import Earth
    from drake_entry.models.vehicles import Vehicle, load_vehicle

    v = load_vehicle("horus2b")
    x = np.array([70e3, 0.1, 0.2, 6500.0, -0.01, 1.0])
    with pytest.raises(DrakeEntryError, match="non-finite"):
        state_derivatives(np.where(np.arange(6) == 3, np.nan, x), 0.3, 0.6, v, Earth.spherical(),
                          ExponentialAtmosphere())
    with pytest.raises(ScenarioError, match="mach"):
        v.aero.coefficients(0.5, -1.0)
    with pytest.raises(ScenarioError, match="alpha"):
        v.aero.coefficients(math.nan, 5.0)
    with pytest.raises(ScenarioError, match="mach_min"):
        HorusFitAero(v.aero.aD, v.aero.aL, mach_min=30.0, mach_max=2.0)
    exp = ExponentialAtmosphere()
    with pytest.raises(ScenarioError, match="exponential"):
        exp.density(math.nan)
    assert Vehicle("f32", mass=np.float32(1.0), reference_area=1.0, nose_radius=0.1, aero=v.aero).mass == 1.0
    with pytest.raises(ScenarioError, match="bank_rate_limit"):
        Vehicle("r", mass=1.0, reference_area=1.0, nose_radius=0.1, aero=v.aero, bank_rate_limit=0.0)


def test_nlp_rejects_a_wrong_shape_guess_and_bad_iterations():
    from drake_entry.planning import nlp
    from drake_entry.planning.ocp_yaml import load_problem

    problem, _ = load_problem("marv")
    with pytest.raises(ScenarioError, match="guess"):
        nlp.solve(problem, nodes=10, guess=(np.linspace(0, 100, 5), np.zeros((5, 3)), np.zeros((5, 2))))
    with pytest.raises(ScenarioError, match="max_iterations"):
        nlp.solve(problem, nodes=10, max_iterations=-1)
