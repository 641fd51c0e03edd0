"""Bad database files, damaged campaign manifests, impossible dispersions and searches, API
arguments of the wrong type: each is one ScenarioError / CampaignError line, before any work."""
import json
import os
import shutil
import time

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from drake_entry.campaign.store import MANIFEST_COPY, read_manifest  # noqa: E402
from drake_entry.cli import main  # noqa: E402
from drake_entry.errors import CampaignError, DrakeEntryError, ScenarioError  # noqa: E402
from drake_entry.guidance.ampi.database import TrajectoryDatabase  # noqa: E402
from drake_entry.guidance.ampi.spec import database_path  # noqa: E402
from drake_entry.scenario import apply_overrides, load_scenario  # noqa: E402


# -- AMPI database files --------------------------------------------------------------------
@pytest.fixture(scope="module")
def packaged_database():
    return TrajectoryDatabase.load(database_path("shefex3"))


def test_a_saved_database_reads_back_exactly(tmp_path, packaged_database):
    path = str(tmp_path / "db.npz")
    packaged_database.save(path)
    again = TrajectoryDatabase.load(path)
    assert np.array_equal(again.values, packaged_database.values)
    assert np.array_equal(again.verified, packaged_database.verified)
    assert again.grid.as_dict() == packaged_database.grid.as_dict()


def _npz(path, **arrays):
    np.savez(path, **arrays)
    return str(path)


@pytest.mark.parametrize("make, needle", [
    (lambda d: str(d), "is a directory, not a database file"),
    (lambda d: str(d / "missing.npz"), "file not found"),
    (lambda d: (d / "g.npz").write_bytes(b"garbage" * 100) and str(d / "g.npz"), "is not a database file"),
    (lambda d: _npz(d / "x.npz", x=np.zeros(3)), "lacks the array(s) values, final_time, objective, verified, meta"),
    (lambda d: (np.save(d / "a.npy", np.zeros(3)), str(d / "a.npy"))[1], "is a single array (.npy)"),
    (lambda d: _npz(d / "m.npz", values=np.zeros(3), final_time=0, objective=0, verified=0, meta=np.array("[")),
     "its layout is not a database's (JSONDecodeError"),
    (lambda d: _npz(d / "f.npz", values=np.zeros(3), final_time=0, objective=0, verified=0,
                    meta=np.array(json.dumps({"format": "other"}))), "is a 'other' file, not an AMPI trajectory database"),
    (lambda d: _npz(d / "v.npz", values=np.zeros(3), final_time=0, objective=0, verified=0,
                    meta=np.array(json.dumps({"version": 99}))), "has format version 99; this drake_entry reads versions 1 to 1"),
    (lambda d: (d / "p.pkl").write_bytes(b"\x80\x04K\x01.") and str(d / "p.pkl"), "holds pickled Python objects"),
])
def test_a_bad_database_file_is_one_line(tmp_path, make, needle):
    path = make(tmp_path)
    with pytest.raises(ScenarioError) as e:
        TrajectoryDatabase.load(path)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_a_database_with_arrays_of_the_wrong_shape_is_refused(tmp_path, packaged_database):
    path = str(tmp_path / "db.npz")
    db = packaged_database
    bad = TrajectoryDatabase(db.grid, db.state_names, db.control_names, db.values[:-1], db.final_time[:-1],
                             db.objective[:-1], db.verified[:-1], db.provenance)
    bad.save(path)
    with pytest.raises(ScenarioError, match=r"values has shape \(728, 60, 9\); its grid and layout need \(729, nodes, 9\)"):
        TrajectoryDatabase.load(path)


@settings(max_examples=40, deadline=None, derandomize=True, database=None)
@given(data=st.binary(max_size=400), cut=st.integers(min_value=0, max_value=4000))
def test_fuzzed_database_bytes_never_give_a_traceback(tmp_path_factory, packaged_database, data, cut):
    """Random bytes, and a real database file cut anywhere or with random bytes spliced in."""
    d = tmp_path_factory.mktemp("fuzz")
    whole = d / "whole.npz"
    if not whole.exists():
        packaged_database.save(str(whole))
    raw = whole.read_bytes()
    for content in (data, raw[:cut], raw[:cut] + data + raw[cut + len(data):]):
        path = d / "f.npz"
        path.write_bytes(content)
        try:
            TrajectoryDatabase.load(str(path))
        except ScenarioError as e:
            assert "\n" not in str(e)


# -- campaign manifests ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def finished_campaign(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("c") / "c")
    assert main(["campaign", "horus2b", "--runs", "1", "--workers", "1", "--trajectory-step", "0", "--out", out]) == 0
    return out


def test_a_damaged_manifest_is_restored_from_its_copy(tmp_path, finished_campaign):
    out = str(tmp_path / "c")
    shutil.copytree(finished_campaign, out)
    sound = read_manifest(out)
    text = open(os.path.join(out, "campaign.json")).read()
    open(os.path.join(out, "campaign.json"), "w").write(text[: len(text) // 2])
    assert read_manifest(out) == sound
    assert json.load(open(os.path.join(out, "campaign.json"))) == sound  # rewritten from the copy
    assert main(["report", out]) == 0


@pytest.mark.parametrize("field, value", [("runs", "many"), ("runs", -3), ("seed", 1.5), ("scenario_yaml", 7)])
def test_a_manifest_field_of_the_wrong_type_is_one_line(tmp_path, finished_campaign, capsys, field, value):
    out = str(tmp_path / "c")
    shutil.copytree(finished_campaign, out)
    os.remove(os.path.join(out, MANIFEST_COPY))
    manifest = json.load(open(os.path.join(out, "campaign.json")))
    manifest[field] = value
    json.dump(manifest, open(os.path.join(out, "campaign.json"), "w"))
    with pytest.raises(CampaignError, match=f"is not a campaign manifest \\(its '{field}' is"):
        read_manifest(out)
    assert main(["report", out]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


# -- settings refused before any work ------------------------------------------------------
@pytest.mark.parametrize("field, value, needle", [
    ("dispersions.mass_scale", "0.0", "dispersions.mass_scale reaches 0; a scale must stay > 0"),
    ("dispersions.drag_scale", "!Uniform {min: -0.1, max: 1.1}", "dispersions.drag_scale reaches -0.1"),
    ("dispersions.lift_scale", "!Gaussian {mean: 1.0, stddev: 0.25}", "dispersions.lift_scale reaches -0.25"),
    ("dispersions.density_wave_amplitude", "!Uniform {min: -1.2, max: 0.1}",
     "dispersions.density_wave_amplitude reaches 1.2; allowed: |amplitude| < 1"),
])
def test_a_dispersion_that_draws_an_impossible_scale_is_refused_up_front(field, value, needle):
    scenario = load_scenario("horus2b")
    with pytest.raises(ScenarioError, match=needle.replace("|", r"\|").replace(".", r"\.")):
        apply_overrides(scenario, {field: value})


def test_a_narrow_gaussian_scale_is_accepted():
    scenario = load_scenario("horus2b")
    apply_overrides(scenario, {"dispersions.mass_scale": "!Gaussian {mean: 1.0, stddev: 0.05}"})


@pytest.mark.parametrize("overrides, needle", [
    ({"guidance.seed": "-1"}, r"guidance\.seed = -1 is out of range"),
    ({"guidance.population": "10000", "guidance.iterations": "10000"},
     r"guidance\.population x \(guidance\.iterations \+ 1\) = 100,010,000 trajectories"),
])
def test_a_swarm_search_that_cannot_run_is_refused_up_front(overrides, needle):
    scenario = load_scenario("cav_h_paper004")
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match=needle):
        apply_overrides(scenario, overrides)
    assert time.perf_counter() - t0 < 5.0


def test_optimize_refuses_a_node_cap_below_the_nodes_before_solving(capsys):
    t0 = time.perf_counter()
    assert main(["optimize", "marv", "--refine", "--max-nodes", "2"]) == 2
    assert "max_nodes = 2 is out of range; allowed: an integer >= nodes (125)" in capsys.readouterr().err
    assert time.perf_counter() - t0 < 10.0  # no coarse solve first (27 s)


@pytest.mark.parametrize("call", [
    lambda: __import__("drake_entry.campaign.montecarlo", fromlist=["x"]).run_campaign("horus2b", runs=1, out_dir=None),
    lambda: __import__("drake_entry.campaign.montecarlo", fromlist=["x"]).run_campaign(None, runs=1, out_dir="x"),
    lambda: __import__("drake_entry.campaign.montecarlo", fromlist=["x"]).run_campaign(
        "horus2b", runs=1, out_dir="x", overrides="guidance.period_s=2"),
    lambda: __import__("drake_entry.diagrams.closed_loop", fromlist=["x"]).ClosedLoopSetup.from_scenario(3),
    lambda: load_scenario(None),
    lambda: apply_overrides("horus2b", {}),
    lambda: TrajectoryDatabase.load(None),
])
def test_api_arguments_of_the_wrong_type_are_one_line(call, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(DrakeEntryError) as e:
        call()
    assert "\n" not in str(e.value) and "got" in str(e.value)
    assert not (tmp_path / "x").exists()


def test_a_scenario_name_is_enough_for_a_closed_loop_setup():
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup

    assert ClosedLoopSetup.from_scenario("horus2b").scenario.name == load_scenario("horus2b").name
