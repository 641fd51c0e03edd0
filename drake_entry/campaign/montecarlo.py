"""Monte-Carlo campaigns of the closed loop of any guidance method.

``run_campaign`` runs (or resumes) ``runs`` samples of a scenario's dispersions on a
backend as a campaign of cases (campaign.engine: serial, local processes, Dask), each
finished row streamed into the campaign directory (campaign_store); one sample is one
Drake RandomSimulation (campaign.sample). The report is drake_entry.campaign.report.
"""
from __future__ import annotations

import hashlib
import os

from pydrake.common.yaml import yaml_dump_typed

from drake_entry.campaign.arguments import MAX_RUNS, RUNS_NOTE, check_output_dir, check_run_arguments
from drake_entry.campaign.backends import Task
from drake_entry.campaign.engine import SampleCases, run_cases, session, versions
from drake_entry.campaign.preparation import prepare
from drake_entry.campaign.sample import (  # noqa: F401 (API)
    DETAILED_STEP_S,
    TIMING_COLUMNS,
    TRAJECTORY_STEP_S,
    campaign_row,
    downsample,
    run_sample,
    sample_seed,
)
from drake_entry.campaign.store import done_indices, finalise, read_nominal, write_nominal  # noqa: F401 (API)
from drake_entry.errors import ScenarioError
from drake_entry.models.vehicles import PACKAGED_VEHICLES
from drake_entry.scenario import (  # noqa: F401 (API)
    PACKAGED_SCENARIOS,
    apply_overrides,
    load_campaign_scenario,
    scenario_from_dump,
)

__all__ = ["DETAILED_STEP_S", "TIMING_COLUMNS", "TRAJECTORY_STEP_S", "campaign_row", "downsample", "run_sample",
           "sample_seed", "done_indices", "finalise", "read_nominal", "write_nominal", "PACKAGED_SCENARIOS",
           "apply_overrides", "load_campaign_scenario", "MAX_RUNS", "RUNS_NOTE", "campaign_manifest", "run_campaign",
           "fly_nominal", "run_until_confident"]



def _absolute_and_hash(path: str) -> tuple[str, str]:
    """(absolute path, sha256 of the content) of a user file a campaign's samples read."""
    path = os.path.abspath(path)
    with open(path, "rb") as f:
        return path, hashlib.sha256(f.read()).hexdigest()


def campaign_manifest(scenario_path: str, *, seed: int, trajectory_step_s: float, overrides: dict | None,
                      runs: int) -> dict:
    """The manifest of a campaign: the scenario as flown (loaded, overrides applied, a user
    vehicle file and an atmosphere table made absolute and hashed), seed, trajectory step and
    versions. Raises a ScenarioError for a scenario that does not load, before anything is written."""
    scenario = load_campaign_scenario(scenario_path, overrides)
    vehicle_sha = atmosphere_sha = None
    if scenario.vehicle not in PACKAGED_VEHICLES:
        scenario.vehicle, vehicle_sha = _absolute_and_hash(scenario.vehicle)
    if scenario.atmosphere.model == "table":
        scenario.atmosphere.table_csv, atmosphere_sha = _absolute_and_hash(scenario.atmosphere.table_csv)
    name = scenario_path if scenario_path in PACKAGED_SCENARIOS else os.path.abspath(scenario_path)
    return {"scenario": name, "scenario_yaml": yaml_dump_typed(scenario), "vehicle_file_sha256": vehicle_sha,
            "atmosphere_file_sha256": atmosphere_sha,
            "seed": int(seed), "trajectory_step_s": float(trajectory_step_s), "overrides": overrides or {},
            "versions": versions(), "sessions": [session()],
            "runs": int(runs), "dispersion": "scenario dispersions"}


def run_campaign(scenario_path: str, *, runs: int, out_dir: str, seed: int = 0, workers: int | None = None,
                 overrides: dict | None = None, progress: bool = True, backend: str = "processes",
                 scheduler: str | None = None, trajectory_step_s: float = TRAJECTORY_STEP_S,
                 nominal_setup=None) -> str:
    """Run (or resume, or extend) a campaign of ``runs`` samples; returns out_dir.

    backend: 'serial', 'processes' (``workers`` local processes, default all cores) or
    'dask' (``scheduler`` address of a running Dask cluster, or a LocalCluster of
    ``workers`` single-threaded processes when None).

    trajectory_step_s: spacing [s] of the down-sampled trajectories kept per sample (0 keeps
    none: the smallest output for large campaigns; the report then omits the envelopes).

    nominal_setup: the ClosedLoopSetup of this very scenario, already built by the caller (its
    preparation and pre-flight planning done), flown for the nominal trajectory instead of
    planning again. Without it the method's preparation (campaign.preparation) runs here,
    before any worker starts.

    The directory's manifest fingerprints the scenario content, seed, trajectory step and
    versions: a directory holding another campaign is refused (CampaignError); a larger
    ``runs`` with the same settings extends it. Rows stream to out_dir/samples.jsonl,
    trajectories to trajectories.jsonl; at the end both are converted to Parquet.
    """
    check_run_arguments(runs=runs, seed=seed, trajectory_step_s=trajectory_step_s, workers=workers, backend=backend,
                        scheduler=scheduler)
    if not isinstance(scenario_path, (str, os.PathLike)):
        raise ScenarioError(f"scenario_path must be a path (text); got {type(scenario_path).__name__}")
    scenario_path, out_dir = os.fspath(scenario_path), check_output_dir(out_dir, "out_dir")
    manifest = campaign_manifest(scenario_path, seed=seed, trajectory_step_s=trajectory_step_s, overrides=overrides,
                                 runs=runs)
    task = Task("drake_entry.campaign.sample:setup_worker", "drake_entry.campaign.sample:run_case",
                {"scenario_yaml": manifest["scenario_yaml"], "seed": int(seed),
                 "trajectory_step_s": float(trajectory_step_s)})
    if nominal_setup is None:  # a built setup has had its preparation: its planner loads what it made
        prepared = prepare(scenario_from_dump(manifest["scenario_yaml"]), progress=progress)  # before any worker
        if prepared and progress:
            print(f"drake-entry: {prepared}", flush=True)
    cases = SampleCases(runs, lambda i: sample_seed(seed, i))
    run_cases(task, cases, out_dir, manifest, backend=backend, workers=workers, scheduler=scheduler,
              progress=progress, desc="campaign")
    if trajectory_step_s > 0 and read_nominal(out_dir) is None:
        fly_nominal(out_dir, manifest["scenario_yaml"], setup=nominal_setup)
    return out_dir


def fly_nominal(out_dir: str, scenario_yaml: str, *, setup=None) -> None:
    """Fly the campaign's scenario once without dispersions and keep its trajectory every
    DETAILED_STEP_S (``nominal.json``: the report overlays it on the campaign's envelopes).
    ``setup``: that scenario's ClosedLoopSetup when the caller has built it (else built here).
    A flight that raises is not kept: the report then shows the campaign alone."""
    from drake_entry.diagrams.closed_loop import fly
    from drake_entry.errors import DrakeEntryError
    from drake_entry.scenario import scenario_from_dump

    try:
        flown = setup if setup is not None else scenario_from_dump(scenario_yaml)
        tr = fly(flown).trajectory
    except (DrakeEntryError, RuntimeError) as e:
        print(f"drake-entry: the nominal flight of the campaign failed ({e}); the report shows the campaign alone")
        return
    write_nominal(out_dir, downsample(tr, -1, DETAILED_STEP_S))


def run_until_confident(scenario_path: str, *, runs: int, max_runs: int, out_dir: str, overrides: dict | None = None,
                        progress: bool = True, **campaign_args):
    """Run the campaign (run_campaign's arguments) in batches until the scenario's success
    requirement (``success_requirement``; campaign.success_requirement) is shown (PASS) or shown
    not met (FAIL), or ``max_runs`` samples are done: ``runs`` first, then each time the further
    runs that would show it were every one successful, at most as many as are done. Returns
    (out_dir, the SuccessVerdict on every sample done)."""
    from drake_entry.campaign.rows import row_problem
    from drake_entry.campaign.store import coverage
    from drake_entry.campaign.success_requirement import success_verdict

    req = load_campaign_scenario(scenario_path, overrides).success_requirement
    if req.probability is None:
        raise ScenarioError(f"{scenario_path}: running until confident needs the scenario's "
                            f"success_requirement.probability (e.g. 0.9973 for 3 sigma; confidence {req.confidence:g})")
    if not (isinstance(max_runs, int) and runs <= max_runs <= MAX_RUNS):
        raise ScenarioError(f"max_runs = {max_runs}: allowed an integer from runs ({runs}) to {MAX_RUNS}")
    target = runs
    while True:
        run_campaign(scenario_path, runs=target, out_dir=out_dir, overrides=overrides, progress=progress,
                     **campaign_args)
        rows = coverage(out_dir, row_problem)["rows"]
        verdict = success_verdict(sum(bool(r.get("success")) for r in rows.values()), len(rows), req.probability,
                                  req.confidence)
        if progress:
            print(f"drake-entry: {verdict.text()}", flush=True)
        if verdict.status != "OPEN" or verdict.more_runs is None or len(rows) >= max_runs:
            return out_dir, verdict
        target = min(max_runs, len(rows) + min(verdict.more_runs, len(rows)))
