"""Monte-Carlo campaigns: reproducibility, failures recorded, resume, statistics."""
import json
import os

import numpy as np
import pyarrow.parquet as pq
import pytest

from drake_entry.campaign.montecarlo import TIMING_COLUMNS, done_indices, run_campaign, run_sample, sample_seed
from drake_entry.campaign.report import summary_statistics, write_report
from drake_entry.campaign.sample import DETAILED_SAMPLES, DETAILED_STEP_S, EXTREME_COLUMNS, PEAK_COLUMNS
from drake_entry.diagrams.closed_loop import ClosedLoopSetup
from drake_entry.errors import CampaignError
from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner
from drake_entry.scenario import load_scenario


@pytest.fixture(scope="module")
def horus():
    return ClosedLoopSetup.from_scenario(load_scenario("horus2b"))


def test_a_sample_rerun_alone_reproduces_its_row_bit_for_bit(horus):
    a, _ = run_sample(horus, 11, 5, trajectory_step_s=0)
    b, _ = run_sample(horus, 11, 5, trajectory_step_s=0)
    assert a["success"], a["message"]
    for k in a:
        if k not in TIMING_COLUMNS:
            assert a[k] == b[k], k
    assert sample_seed(11, 5) != sample_seed(11, 6) != sample_seed(12, 5)
    _, traj = run_sample(horus, 11, DETAILED_SAMPLES, trajectory_step_s=10.0)
    t = np.asarray(traj["time_s"])
    grid = np.arange(0.0, t[-1], 10.0)  # every 10 s, the final instant, and each flight's peaks (log samples)
    assert np.isin(grid, t).all() and t[-1] > 1000.0 and np.all(np.diff(t) > 0)
    extra = t[~np.isin(t, grid)][:-1]
    assert extra.size <= len(PEAK_COLUMNS) + 2 * len(EXTREME_COLUMNS)


def test_a_failing_sample_is_recorded_with_its_reason(horus):
    class BrokenPlanner(DragEnergyPlanner):
        def plan_from_state(self, x, previous=None, **kw):
            raise RuntimeError("solver library missing")

    broken = DragEnergyPlanner.from_scenario(horus.scenario)
    broken.__class__ = BrokenPlanner
    row, _ = run_sample(ClosedLoopSetup.from_scenario(horus.scenario, broken), 1, 0, trajectory_step_s=0)
    assert row["success"] is False
    assert "guidance never engaged" in row["message"] and "solver library missing" in row["message"]
    assert np.isfinite(row["disp_dh_m"])


def test_campaign_resumes_without_losing_or_repeating_samples(tmp_path):
    out = str(tmp_path / "c")
    run_campaign("horus2b", runs=1, out_dir=out, seed=4, workers=1, progress=False)
    with open(f"{out}/samples.jsonl", "a") as f:
        f.write('{"index": 9, "trunc')  # a line cut by a kill
    run_campaign("horus2b", runs=2, out_dir=out, seed=4, workers=1, progress=False)
    lines = [json.loads(l) for l in open(f"{out}/samples.jsonl") if l.strip().endswith("}")]
    assert sorted(r["index"] for r in lines) == [0, 1]
    assert done_indices(out) == {0, 1}
    with pytest.raises(CampaignError, match="holds a campaign with another seed; extend it"):
        run_campaign("horus2b", runs=2, out_dir=out, seed=5, workers=1, progress=False)
    report = write_report(out)
    text = open(report).read()
    assert "paper 000 Table 3" in text and "Δh" in text
    rows = [json.loads(l) for l in open(f"{out}/samples.jsonl")]
    for r in rows:  # cost accounting: fixed 0.5 s RK3 steps (3 evaluations each) over the flight
        assert r["integration_steps"] >= r["flight_time_s"] / 0.5
        assert r["derivative_evaluations"] >= 3 * r["integration_steps"]
        assert 0.0 < r["planning_wall_s"] < r["wall_time_s"]
    assert "of one core per sample" in text and "re-planning" in text
    traj = pq.read_table(f"{out}/trajectories.parquet").to_pydict()
    t0 = np.array(traj["time_s"])[np.array(traj["sample"]) == 0]
    assert np.allclose(np.diff(t0)[:-1], DETAILED_STEP_S) and t0[-1] > 1000.0  # the first samples: detailed
    assert not os.path.exists(f"{out}/campaign.lock")  # removed by the writer that held it


def test_report_is_self_contained_with_provenance_requirements_and_bounds(tmp_path):
    """Two sessions of a 2-sample campaign: the report states who ran it with what, the
    dispersions with their source, every requirement with its threshold, value, margin and
    verdict, the Clopper-Pearson bound (2 of 2: 0.1^(1/2) = 31.62 % at 90 %), statistics with
    the unresolved percentiles blank, and an HTML copy with every figure inline."""
    out = str(tmp_path / "c")
    run_campaign("horus2b", runs=1, out_dir=out, seed=4, workers=1, progress=False)
    run_campaign("horus2b", runs=2, out_dir=out, seed=4, workers=1, progress=False)
    manifest = json.load(open(f"{out}/campaign.json"))
    assert len(manifest["sessions"]) == 2 and manifest["sessions"][0]["numpy"] == np.__version__
    text = open(write_report(out)).read()
    assert "**2 of 2 samples successful; the success probability is at least 31.62 % at 90 % confidence" in text
    assert "22.36 % at 95 % confidence" in text  # 0.05 ** 0.5
    assert "| seeds | master seed 4; sample i draws" in text and "sha256" in text
    assert "`drake-entry campaign horus2b --runs 2 --seed 4 --trajectory-step 10.0 --out DIR`" in text
    assert "Source: paper 000 Table 2 (entry interface only, uniform)" in text
    assert "| entry altitude (deviation) | 122000 m | uniform | [-250, 250] | m |" in text
    assert "| terminal altitude | in [23, 27] km | largest distance from the centre 25 km of 2 |" in text
    assert "PASS (2 of 2 inside) | paper 000 Table 1 |" in text  # the requirement's source
    assert "PASS (2 of 2 held) | paper 000 Table 1 (530 kW/m^2) |" in text
    assert "| heat_flux | <= 530 kW/m^2 | worst flown sample of 2 |" in text and "PASS (2 of 2 held)" in text
    # the errors against the guidance's aim (26.5 km at its energy stop) and against the box's centre
    assert "The guidance aims at the energy of h_f = 26.5 km, V_f = " in text
    assert "| ΔV (at the energy stop: -g Δh / V, follows Δh) (bound on the absolute value) | m/s | 2 |" in text
    centre = text.split("### Terminal errors against the acceptance box's centre")[1].split("###")[0]
    row = next(line for line in centre.splitlines() if line.startswith("| terminal altitude − box centre"))
    cells = row.split("|")
    min_p50_mean_max = [float(cells[i]) for i in (4, 7, 8, 12)]
    assert all(1.0 < v < 2.0 for v in min_p50_mean_max)  # the flights end about 26.5 km: 1.5 km above the centre
    assert "| peak heat flux | kW/m^2 | 2 |" in text and "— (needs 230 runs)" in text
    assert "| bank reversals | - | 2 |" in text
    assert "Why the figures differ from paper 000 Table 3: This guidance re-plans the drag profile every 20 s" in text
    assert os.path.exists(f"{out}/nominal.json")  # the undispersed flight, overlaid on the envelopes
    assert os.path.getsize(f"{out}/interactive.html") > 1e6  # plotly.js inline: it opens without a network
    assert '<a href="interactive.html">Interactive view</a>' in open(f"{out}/report.html").read()
    assert "the dashed line the nominal flight (the scenario without dispersions)" in text
    figures = [line for line in text.splitlines() if line.startswith("*Figure ")]
    assert len(figures) == 10 and all(len(f) > 120 for f in figures)  # each with its caption (the margin histograms too)
    assert "How the estimates settle as the 2 samples accumulate" in text and os.path.exists(f"{out}/convergence.png")
    html_text = open(f"{out}/report.html").read()
    assert html_text.count("data:image/png;base64,") == 10 and "<table>" in html_text
    summary = json.load(open(f"{out}/summary.json"))
    assert summary["success_lower_bound"]["0.9"] == pytest.approx(0.1 ** 0.5)
    assert summary["distributions"]["err_distance_m"]["n"] == 2
    # resumed at another commit: the report names both, and each run's
    manifest["sessions"][0]["git_commit"] = "0" * 40
    with open(f"{out}/campaign.json", "w") as f:
        json.dump(manifest, f)
    provenance = open(write_report(out)).read().split("## Dispersions")[0]
    assert f"| 0.1.0, commits {'0' * 40}, " in provenance and "resumed at another commit" in provenance
    assert "` at commit 0000000;" in provenance  # the first run's


def test_campaign_without_trajectories_keeps_rows_only(tmp_path):
    out = str(tmp_path / "rows")
    run_campaign("horus2b", runs=1, out_dir=out, seed=4, workers=1, progress=False, trajectory_step_s=0)
    assert os.path.exists(f"{out}/samples.parquet") and not os.path.exists(f"{out}/trajectories.parquet")
    assert "Trajectories were not kept" in open(write_report(out)).read()
    with pytest.raises(ValueError, match=r"trajectory_step_s = -1.0 is out of range; allowed: >= 0 s"):
        run_campaign("horus2b", runs=1, out_dir=out, seed=4, trajectory_step_s=-1.0)


def test_statistics_against_a_hand_computed_case():
    """Errors over the samples that reached the terminal interface (inside the box or not),
    margins over every sample that flew, failures by reason."""
    rows = {"index": [0, 1, 2, 3, 4], "success": [True, True, True, False, False],
            "stop": ["reached energy"] * 3 + [None, "reached energy"],
            "message": ["ok", "ok", "ok", "RuntimeError: boom", "outside the acceptance box: distance +80 km"],
            "err_range_m": [100.0, -200.0, 400.0, None, 700.0],
            "err_distance_m": [1000.0, 30000.0, 60000.0, None, 80000.0],
            "margin_heat_flux": [0.02, -0.01, 0.05, None, 0.01], "inside_distance_box": [True, True, True, None, False]}
    st = summary_statistics(rows)
    assert (st["successful"], st["reached"], st["failed"]) == (3, 4, 2)
    assert st["failure_reasons"] == {"RuntimeError": 1, "outside the acceptance box": 1}
    assert st["errors"]["err_range_m"]["mean"] == pytest.approx(250.0)
    assert st["errors"]["err_range_m"]["std"] == pytest.approx(387.2983346)  # sample std of (100, -200, 400, 700)
    assert st["inside_km"] == {"2": 1, "25": 1, "50": 2, "75": 3}
    assert st["inside_box"] == {"distance": 3}
    assert st["margins"]["margin_heat_flux"] == {"worst": -0.01, "violations": 1, "worst_sample": 1}


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
def test_dask_backend_gives_the_same_rows_as_local_processes(tmp_path):
    """One interface, three backends: the rows depend on (seed, index) only. The local Dask
    cluster says nothing when Dask's default HTTP port (8787) is taken, as it is whenever another
    cluster runs."""
    import socket
    import warnings

    import pyarrow.parquet as pq

    rows = {}
    with socket.socket() as taken, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            taken.bind(("", 8787))
            taken.listen()
        except OSError:  # already taken by something else: the case under test all the same
            pass
        for backend, workers in (("serial", 1), ("dask", 2)):
            out = run_campaign("horus2b", runs=2, out_dir=str(tmp_path / backend), seed=21, workers=workers,
                               progress=False, backend=backend)
            rows[backend] = pq.read_table(f"{out}/samples.parquet").to_pydict()
    assert not [str(w.message) for w in caught if "already in use" in str(w.message)]
    assert rows["dask"]["index"] == [0, 1]
    for col in ("err_range_m", "err_altitude_m", "disp_dh_m", "peak_heat_flux_W_m2"):
        assert rows["dask"][col] == rows["serial"][col], col
    with pytest.raises(ValueError, match="backend 'mpi' is unknown"):
        run_campaign("horus2b", runs=1, out_dir=str(tmp_path / "x"), backend="mpi")


def test_error_table_shows_the_scenario_reference_only_when_it_gives_one():
    from drake_entry.campaign.report import errors_markdown
    from drake_entry.scenario import ReferenceResultsSpec

    stats = {"errors": {"err_altitude_m": {"mean": 30.0, "std": 8.0}, "err_range_m": {"mean": -110.0, "std": 40.0}}}
    alone = errors_markdown(stats).splitlines()
    assert alone[0] == "| variable | this campaign: mean ± 1σ | unit |" and alone[2] == "| Δh | 30.0 ± 8.0 | m |"
    ref = ReferenceResultsSpec("paper 000 Table 3", {"err_altitude_m": [168.6, 1107.3]})
    beside = errors_markdown(stats, ref).splitlines()
    assert beside[0] == "| variable | this campaign: mean ± 1σ | paper 000 Table 3 | unit |"
    assert beside[2] == "| Δh | 30.0 ± 8.0 | 168.6 ± 1107.3 | m |" and beside[3].endswith("| — | m |")
