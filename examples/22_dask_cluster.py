"""Example 22: a campaign on a Dask cluster, and how it scales.

A cluster's nodes run a ``dask scheduler`` and ``dask worker`` processes; a campaign reaches them
only through the scheduler's address (``drake-entry campaign ... --scheduler ADDRESS``, or
``run_campaign(..., backend="dask", scheduler=ADDRESS)``). Here the same processes run on this
machine (``ProcessCluster``): the campaign on one worker, then on two, with the throughput of
each; then, when the ``cluster`` extra is installed (``pip install drake_entry[cluster]``), on
workers submitted as jobs by ``dask-jobqueue`` (its local job runner: the job script SLURM or PBS
would receive is printed). Every way gives the same rows, which depend on (seed, index) only.

    python examples/22_dask_cluster.py [--quick] [--out out/examples/22]
"""
import os
import time

import pandas as pd

from drake_entry.campaign.cluster import ProcessCluster, worker_environment
from drake_entry.campaign.montecarlo import TIMING_COLUMNS, run_campaign
from drake_entry.claims import Claims, run_example

SCENARIO, SEED = "horus2b", 5


def _rows(out_dir: str) -> pd.DataFrame:
    return pd.read_parquet(os.path.join(out_dir, "samples.parquet")).sort_values("index").reset_index(drop=True)


def _timed_campaign(runs: int, out_dir: str, scheduler: str) -> float:
    """Samples per second of wall time of a campaign through the scheduler at ``scheduler``."""
    t0 = time.perf_counter()
    run_campaign(SCENARIO, runs=runs, seed=SEED, out_dir=out_dir, progress=False, backend="dask", scheduler=scheduler)
    return runs / (time.perf_counter() - t0)


def main(quick: bool = False, out_dir: str = "out/examples/22") -> dict:
    runs = 4 if quick else 40
    os.makedirs(out_dir, exist_ok=True)
    result = {"runs": runs, "throughput": {}, "rows": {}}
    # 1. the campaign on one worker process, then on two (a scheduler and workers of their own)
    for workers in (1, 2):
        with ProcessCluster(workers, log=os.path.join(out_dir, "cluster.log")) as cluster:
            label = f"{workers} worker" + ("s" if workers > 1 else "")
            out = os.path.join(out_dir, label.replace(" ", "_"))
            result["throughput"][workers] = _timed_campaign(runs, out, cluster.address)
            result["rows"][label] = _rows(out)
            print(f"{label}: {runs} samples at {result['throughput'][workers]:.2f} samples/s (scheduler "
                  f"{cluster.address})")
    # 2. workers submitted as batch jobs by dask-jobqueue (the 'cluster' extra): its local runner
    #    starts the job script as a process; SLURMCluster or PBSCluster submit the same script
    try:
        from dask_jobqueue.local import LocalCluster as JobCluster
    except ImportError:
        print("dask-jobqueue is not installed (pip install drake_entry[cluster]): the job-queue part is skipped")
    else:
        # the quiet-worker settings: the local runner's jobs inherit this environment; on SLURM or
        # PBS pass them as job_script_prologue=[f"export {k}={v}" for k, v in worker_environment().items()]
        os.environ.update(worker_environment())
        with JobCluster(cores=1, processes=1, memory="2GB") as jobs:
            print("the job script a SLURM or PBS queue would receive:\n" + jobs.job_script())
            jobs.scale(jobs=2)
            out = os.path.join(out_dir, "jobqueue")
            run_campaign(SCENARIO, runs=runs, seed=SEED, out_dir=out, progress=False, backend="dask",
                         scheduler=jobs.scheduler_address)
            result["rows"]["dask-jobqueue"] = _rows(out)
    # 3. a serial run for reference: the rows are the same whatever ran them
    local = os.path.join(out_dir, "serial")
    run_campaign(SCENARIO, runs=runs, seed=SEED, out_dir=local, progress=False, backend="serial")
    result["serial"] = _rows(local)
    speedup = result["throughput"][2] / result["throughput"][1]
    print(f"two workers against one: {speedup:.2f} times the samples per second (2 cores here)")
    return result


def check(result, quick: bool = False) -> Claims:
    c = Claims("example 22: a campaign on a Dask cluster")
    serial = result["serial"]
    flight = [col for col in serial.columns if col not in TIMING_COLUMNS]  # every column but the clock's
    for label, rows in result["rows"].items():
        same = len(rows) == len(serial) and rows[flight].equals(serial[flight])
        c.check(f"{label}: every sample once, each row equal to the serial run's", same, f"{len(rows)} rows")
    speedup = result["throughput"][2] / result["throughput"][1]
    # quick runs (4 samples) are mostly start-up; the full run is where the scaling is measured
    c.check("two workers give more samples per second than one", quick or speedup > 1.3, f"{speedup:.2f} times")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/22",
                                 quick="4 samples per cluster instead of 40"))
