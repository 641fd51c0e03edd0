"""Every report kept in docs/results names the commit that made it, and that commit is in the
repository's history, with no '+changes' (drake-entry publish refuses a tree with uncommitted
changes). The reports made before that rule are listed in STALE, each with why; the test fails
when a new report breaks the rule and when a listed one is made right (take it off the list), so
the list only shrinks as `drake-entry publish` regenerates them."""
import re
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "docs" / "results"

#: reports made before results were published from a committed tree: path below docs/results -> why
STALE: dict = {}

COMMIT = re.compile(r"commit ([0-9a-f]{7,40})(\+changes)?")


def _in_history(commit: str) -> bool:
    out = subprocess.run(["git", "-C", str(REPO), "cat-file", "-e", f"{commit}^{{commit}}"], capture_output=True)
    return out.returncode == 0


def _problem(report: Path) -> str:
    """'' when the report's provenance names commits all in the history and none with changes."""
    text = report.read_text()
    found = COMMIT.findall(text.split("## Dispersions")[0] if "## Dispersions" in text else text)
    if not found:
        return "names no commit"
    dirty = sorted({c for c, changes in found if changes})
    if dirty:
        return f"made with uncommitted changes on {', '.join(c[:7] for c in dirty)}"
    missing = sorted({c for c, _ in found if not _in_history(c)})
    return f"commit {', '.join(c[:7] for c in missing)} is not in the history" if missing else ""


@pytest.mark.skipif(not (REPO / ".git").exists(), reason="the repository's history is not here")
def test_every_report_in_docs_results_names_a_committed_version():
    reports = sorted(RESULTS.rglob("report.md"))
    assert len(reports) >= 10
    problems = {str(r.relative_to(RESULTS)): _problem(r) for r in reports}
    broken = {k: v for k, v in problems.items() if v}
    new = {k: v for k, v in broken.items() if k not in STALE}
    assert not new, f"reports that do not name a committed version: {new}"
    fixed = sorted(k for k in STALE if problems.get(k, "gone") == "" or k not in problems)
    assert not fixed, f"made right (or removed): take them off STALE: {fixed}"


def test_the_check_tells_a_committed_report_from_a_dirty_and_an_unknown_one(tmp_path):
    head = subprocess.run(["git", "-C", str(REPO), "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    if not head:
        pytest.skip("the repository's history is not here")
    report = tmp_path / "report.md"
    report.write_text(f"| drake_entry | 0.1.0, commit {head} |\n\n## Dispersions\n")
    assert _problem(report) == ""
    report.write_text(f"| drake_entry | 0.1.0, commit {head}+changes |\n")
    assert _problem(report).startswith("made with uncommitted changes")
    report.write_text("| drake_entry | 0.1.0, commit 0123456789abcdef0123456789abcdef01234567 |\n")
    assert _problem(report) == "commit 0123456 is not in the history"
    report.write_text("| drake_entry | 0.1.0, commit not recorded |\n")
    assert _problem(report) == "names no commit"


def test_publish_refuses_a_tree_with_uncommitted_changes_and_names_the_way_out(monkeypatch):
    from drake_entry.campaign import engine
    from drake_entry.cli.publish import committed_source
    from drake_entry.errors import DrakeEntryError

    monkeypatch.setattr(engine, "source_commit", lambda: "abc1234+changes")
    with pytest.raises(DrakeEntryError, match=r"has uncommitted changes \(abc1234\+changes\); commit first.*--allow-changes"):
        committed_source(False)
    assert committed_source(True) == "abc1234+changes"
    monkeypatch.setattr(engine, "source_commit", lambda: None)
    with pytest.raises(DrakeEntryError, match="is not a git checkout"):
        committed_source(False)
    monkeypatch.setattr(engine, "source_commit", lambda: "0123456789abcdef0123456789abcdef01234567")
    assert committed_source(False) == "0123456789abcdef0123456789abcdef01234567"


def test_systems_and_diagrams_from_another_checkout_are_not_this_commit(tmp_path, monkeypatch):
    """drake_entry imported from one checkout while another checkout's editable install supplies
    systems/ and diagrams/ (a worktree on PYTHONPATH): foreign_sources names both, the commit
    is marked '+changes' and publish refuses, naming the directories and the way out. This
    checkout's own install has none foreign."""
    import os

    import drake_entry
    import drake_entry.diagrams
    import drake_entry.systems
    from drake_entry.campaign import engine
    from drake_entry.cli.publish import committed_source
    from drake_entry.errors import DrakeEntryError

    top = os.path.dirname(os.path.dirname(os.path.abspath(drake_entry.__file__)))
    assert engine.foreign_sources(top) == []  # a checkout (top/systems) or an installed wheel (inside drake_entry/)
    systems, diagrams = (os.path.dirname(os.path.abspath(m.__file__)) for m in (drake_entry.systems, drake_entry.diagrams))
    assert engine.foreign_sources(str(tmp_path)) == [f"drake_entry.systems from {systems}",
                                                     f"drake_entry.diagrams from {diagrams}"]
    checkout = engine.source_commit() is not None  # an installed wheel (CI's run) names no commit at all
    monkeypatch.setattr(engine, "foreign_sources", lambda _: ["drake_entry.systems from /elsewhere/systems"])
    if checkout:  # an editable install of a checkout (the developers' set-up) holds source_commit to it
        assert engine.source_commit().endswith("+changes")
    monkeypatch.setattr(engine, "source_commit", lambda: "abc1234+changes")
    with pytest.raises(DrakeEntryError, match=r"drake_entry is imported from .* but drake_entry.systems from "
                                              r"/elsewhere/systems \(another checkout's install\).*pip install -e"):
        committed_source(False)


def test_publish_writes_each_campaign_its_index_and_the_record_of_the_run(tmp_path):
    """A reduced publish (one scenario, two runs, no mission): the campaign with its report, the
    index and published.json with the commit, sizes, seeds and wall times; a bad name is refused
    with the allowed ones."""
    import json

    from drake_entry.cli.publish import CAMPAIGN_SEED, publish_results
    from drake_entry.errors import DrakeEntryError

    with pytest.raises(DrakeEntryError, match="--campaigns horus: not one of .*horus2b"):
        publish_results(str(tmp_path), runs=2, comparison_runs=1, campaigns=["horus"], missions=[], allow_changes=True)
    record = publish_results(str(tmp_path), runs=2, comparison_runs=1, campaigns=["horus2b"], missions=[], workers=1,
                             allow_changes=True)
    assert record["campaigns"]["horus2b"]["runs"] == 2 and record["campaign_seed"] == CAMPAIGN_SEED
    assert record["comparisons"] == {} and "matrix" not in record and record["wall_s"] > 0
    assert json.loads((tmp_path / "published.json").read_text())["commit"] == record["commit"]
    assert f"| `horus2b` | 2 | 2 | 31.62 % | 99.73 % at 90 % | OPEN: 850 more successful runs would show it | {CAMPAIGN_SEED} |" \
        in (tmp_path / "campaigns" / "index.md").read_text()
    report = (tmp_path / "campaigns" / "horus2b" / "report.md").read_text()
    assert f"--runs 2 --seed {CAMPAIGN_SEED}" in report


def test_publish_flies_its_samples_on_a_dask_cluster_given_its_scheduler(tmp_path):
    """`drake-entry publish --scheduler ADDRESS` (a dask-jobqueue cluster's, here a LocalCluster's):
    the samples fly on the cluster's workers, with the rows a local run gives (they depend on
    (seed, index) only), and published.json says where they flew."""
    import json

    import pyarrow.parquet as pq
    from dask.distributed import LocalCluster

    from drake_entry.campaign.montecarlo import run_campaign
    from drake_entry.cli.publish import CAMPAIGN_SEED, publish_results

    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster:
        record = publish_results(str(tmp_path / "pub"), runs=2, comparison_runs=1, campaigns=["horus2b"], missions=[],
                                 allow_changes=True, scheduler=cluster.scheduler_address, trajectory_step_s=0.0)
    assert record["samples_flown_on"] == f"Dask cluster {cluster.scheduler_address}"
    assert json.loads((tmp_path / "pub" / "published.json").read_text())["samples_flown_on"].startswith("Dask cluster")
    flown = pq.read_table(tmp_path / "pub" / "campaigns" / "horus2b" / "samples.parquet").to_pydict()
    here = run_campaign("horus2b", runs=2, out_dir=str(tmp_path / "local"), seed=CAMPAIGN_SEED, workers=1,
                        progress=False, backend="serial", trajectory_step_s=0.0)
    local = pq.read_table(f"{here}/samples.parquet").to_pydict()
    assert flown["index"] == [0, 1]
    for col in ("err_range_m", "err_altitude_m", "peak_heat_flux_W_m2"):
        assert flown[col] == local[col], col
