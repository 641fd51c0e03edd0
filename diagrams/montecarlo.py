"""Monte-Carlo campaigns of the closed loop of any guidance method.

``run_campaign`` runs (or resumes) ``runs`` samples of a scenario's dispersions on a
backend (diagrams.backends: serial, local processes, Dask) and streams each finished row
into the campaign directory (diagrams.campaign_store); one sample is one Drake
RandomSimulation (diagrams.sample). The report is drake_entry.report.
"""
from __future__ import annotations

import os

from drake_entry.diagrams.backends import BACKENDS, run_dask, run_processes, run_serial
from drake_entry.diagrams.campaign_store import CampaignStore, done_indices, finalise  # noqa: F401 (API)
from drake_entry.diagrams.sample import TIMING_COLUMNS, TRAJECTORY_STEP_S, campaign_row, run_sample, sample_seed  # noqa: F401 (API)

from drake_entry.errors import ScenarioError
from drake_entry.scenario import apply_overrides, load_campaign_scenario  # noqa: F401 (API)


def run_campaign(scenario_path: str, *, runs: int, out_dir: str, seed: int = 0, workers: int | None = None,
                 overrides: dict | None = None, progress: bool = True, backend: str = "processes",
                 scheduler: str | None = None, trajectory_step_s: float = TRAJECTORY_STEP_S) -> str:
    """Run (or resume) a campaign of ``runs`` samples; returns out_dir.

    backend: 'serial', 'processes' (``workers`` local processes, default all cores) or
    'dask' (``scheduler`` address of a running Dask cluster, or a LocalCluster of
    ``workers`` single-threaded processes when None).

    trajectory_step_s: spacing [s] of the down-sampled trajectories kept per sample (0 keeps
    none: the smallest output for large campaigns; the report then omits the envelopes).

    Rows stream to out_dir/samples.jsonl; trajectories to trajectories.jsonl; at the end
    both are converted to Parquet and campaign.json records the settings.
    """
    if backend not in BACKENDS:
        raise ScenarioError(f"backend '{backend}' is unknown; allowed: {', '.join(BACKENDS)}")
    if not runs >= 1:
        raise ScenarioError(f"runs must be >= 1, got {runs}")
    if not trajectory_step_s >= 0:
        raise ScenarioError(f"trajectory_step_s must be >= 0 s (0 = no trajectories), got {trajectory_step_s}")
    store = CampaignStore(out_dir, {"scenario": scenario_path, "runs": runs, "seed": seed,
                                    "overrides": overrides or {}, "trajectory_step_s": trajectory_step_s,
                                    "dispersion": "scenario dispersions"})
    done = store.done_indices()
    todo = [i for i in range(runs) if i not in done]
    workers = workers or os.cpu_count() or 1
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=runs, initial=runs - len(todo), unit="run", desc="campaign", smoothing=0.05)
    failed = 0
    with store:
        def record(row, traj):
            nonlocal failed
            store.record(row, traj)
            if bar is not None:
                bar.update(1)
                if not row.get("success"):
                    failed += 1
                    bar.set_postfix(failed=failed)

        if backend == "serial" or (backend == "processes" and workers == 1):
            run_serial(todo, record, scenario_path, overrides, seed, trajectory_step_s)
        elif backend == "processes":
            run_processes(todo, record, scenario_path, overrides, seed, workers, trajectory_step_s)
        else:
            run_dask(todo, record, scenario_path, overrides, seed, workers, scheduler, trajectory_step_s)
    if bar is not None:
        bar.close()
    store.finalise()
    return out_dir
