"""A campaign on a real Dask cluster: a ``dask scheduler`` and ``dask worker`` processes on
localhost (separate processes, as on a cluster: campaign.cluster.ProcessCluster), one worker
SIGKILLed mid-campaign and another started: every row once, each equal to the same campaign
run locally."""
import json
import os
import threading
import time

import pytest

from drake_entry.campaign.cluster import ProcessCluster, worker_environment
from drake_entry.campaign.montecarlo import TIMING_COLUMNS, run_campaign

pytest.importorskip("dask.distributed")

RUNS, SEED = 10, 13


def _rows(out_dir):
    path = os.path.join(out_dir, "samples.jsonl")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


@pytest.mark.slow  # a scheduler, three workers and two campaigns: CI's slow set
def test_a_killed_worker_loses_no_sample_and_changes_no_row(tmp_path):
    out, log = str(tmp_path / "cluster"), str(tmp_path / "cluster.log")
    with ProcessCluster(2, log=log) as cluster:
        done = {}
        campaign = threading.Thread(target=lambda: done.setdefault("out", run_campaign(
            "horus2b", runs=RUNS, seed=SEED, out_dir=out, progress=False, backend="dask", scheduler=cluster.address)))
        campaign.start()
        deadline = time.monotonic() + 300
        while len(_rows(out)) < 2:
            assert time.monotonic() < deadline and campaign.is_alive(), "the campaign did not start on the cluster"
            time.sleep(0.1)
        finished_before_kill = len(_rows(out))
        cluster.kill_worker("worker-0")  # dies holding cases; returns once the scheduler has removed it
        assert cluster.worker_names() == {"worker-1"} and campaign.is_alive()
        cluster.add_worker()
        campaign.join(timeout=600)
        assert not campaign.is_alive() and "out" in done
    assert finished_before_kill < RUNS
    cluster_rows = _rows(out)
    assert sorted(r["index"] for r in cluster_rows) == list(range(RUNS))  # every row once
    local = str(tmp_path / "local")
    run_campaign("horus2b", runs=RUNS, seed=SEED, out_dir=local, progress=False, backend="serial")
    local_rows = {r["index"]: r for r in _rows(local)}
    for r in cluster_rows:
        want = local_rows[r["index"]]
        assert set(r) == set(want)
        differ = [k for k in r if k not in TIMING_COLUMNS and r[k] != want[k]]
        assert not differ, (r["index"], differ[:5])


def test_the_worker_settings_reach_dask_through_the_environment(monkeypatch):
    """The quiet-worker settings, as environment variables, are what Dask's config reads."""
    import dask

    for key, value in worker_environment().items():
        monkeypatch.setenv(key, value)
    dask.config.refresh()
    try:
        assert dask.config.get("distributed.worker.profile.enabled") is False
        assert dask.config.get("distributed.admin.tick.interval") == "1000ms"
    finally:
        monkeypatch.undo()
        dask.config.refresh()


def test_a_cluster_needs_a_worker():
    with pytest.raises(ValueError, match="workers = 0; allowed >= 1"):
        ProcessCluster(0)
