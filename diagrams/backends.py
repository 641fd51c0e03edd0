"""Where campaign samples run: 'serial' (this process), 'processes' (local worker
processes, spawn) or 'dask' (Dask distributed: the cluster at ``scheduler`` or a
LocalCluster). Each worker builds the campaign's ClosedLoopSetup (models, guidance method
and its planner) once, from the scenario YAML the manifest fingerprinted, and runs
samples with it; results come back as (row, trajectory). A worker whose set-up fails
returns that failure as each sample's row instead of dying (a dying pool initializer is
respawned for ever).
"""
from __future__ import annotations

import hashlib
import multiprocessing as mp

from drake_entry.diagrams.closed_loop import ClosedLoopSetup
from drake_entry.diagrams.sample import TRAJECTORY_STEP_S, run_sample, sample_seed
from drake_entry.errors import load_yaml_typed
from drake_entry.scenario import Scenario

BACKENDS = ("serial", "processes", "dask")

# Dask settings for CPU-bound pure-Python tasks (see run_dask)
DASK_QUIET_WORKERS = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1000ms",
    "distributed.admin.system-monitor.interval": "5000ms",
    "distributed.worker.memory.monitor-interval": "1000ms",
}

_WORKER = {}


def init_worker(scenario_yaml: str, trajectory_step_s: float = TRAJECTORY_STEP_S):
    """Build this process's ClosedLoopSetup once (the planner and its corridor included)."""
    _WORKER.update(trajectory_step_s=trajectory_step_s, setup=None, error=None)
    try:
        scenario = load_yaml_typed(Scenario, text=scenario_yaml, where="campaign scenario").validate()
        _WORKER["setup"] = ClosedLoopSetup.from_scenario(scenario)
    except Exception as e:  # reported per sample by work()
        _WORKER["error"] = f"worker set-up failed: {type(e).__name__}: {e}".splitlines()[0][:500]


def work(args):
    seed, index = args
    if _WORKER.get("setup") is None:
        return {"index": int(index), "seed": sample_seed(seed, index), "success": False,
                "message": _WORKER.get("error") or "worker not initialised"}, None
    return run_sample(_WORKER["setup"], seed, index, trajectory_step_s=_WORKER["trajectory_step_s"])


def run_serial(todo, record, scenario_yaml, seed, trajectory_step_s):
    init_worker(scenario_yaml, trajectory_step_s)
    for i in todo:
        record(*work((seed, i)))


def run_processes(todo, record, scenario_yaml, seed, workers, trajectory_step_s):
    ctx = mp.get_context("spawn")
    with ctx.Pool(workers, initializer=init_worker, initargs=(scenario_yaml, trajectory_step_s)) as pool:
        for row, traj in pool.imap_unordered(work, [(seed, i) for i in todo], chunksize=1):
            record(row, traj)


def _dask_task(scenario_yaml: str, seed: int, index: int, trajectory_step_s: float):
    """One sample on a Dask worker; the setup is built once per worker process."""
    key = (hashlib.sha256(scenario_yaml.encode()).hexdigest(), trajectory_step_s)
    if _WORKER.get("key") != key:
        init_worker(scenario_yaml, trajectory_step_s)
        _WORKER["key"] = key
    return work((seed, index))


def run_dask(todo, record, scenario_yaml, seed, workers, scheduler, trajectory_step_s):
    """Submit the samples to a Dask cluster. A LocalCluster is started with DASK_QUIET_WORKERS:
    the workers' statistical profiler and the event loop's 20 ms tick take the GIL from the
    CPU-bound Python samples (the profiler cost 18 % of throughput; with it off, the tick and
    monitors still cost 15-18 %, and 3-5 % at the intervals below). Start external workers
    with the same settings as environment variables (README)."""
    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        with dask.config.set(DASK_QUIET_WORKERS):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        futures = {client.submit(_dask_task, scenario_yaml, seed, i, trajectory_step_s, pure=False): i for i in todo}
        for fut in as_completed(futures):
            i = futures[fut]
            try:
                row, traj = fut.result()
            except Exception as e:  # the worker itself died: record and go on
                row, traj = {"index": i, "seed": sample_seed(seed, i), "success": False,
                             "message": f"worker failure: {type(e).__name__}: {e}"[:500]}, None
            record(row, traj)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
