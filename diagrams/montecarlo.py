"""Monte-Carlo campaigns of the closed-loop diagram through Drake's RandomSimulation.

Backends behind one interface (``run_campaign(backend=...)``): 'serial', 'processes'
(local worker processes, the default, every core) and 'dask' (Dask distributed: the
cluster at ``scheduler`` or a LocalCluster of ``workers`` processes).

Each sample is one ``pydrake.systems.analysis.RandomSimulation`` whose RandomGenerator is
seeded from (campaign seed, sample index) only, so any sample re-runs alone and
reproduces its row. Inside ``make_simulator`` the sample's dispersions are drawn from that
generator and built into the diagram's defaults (Drake's SetRandomContext then keeps
them; DESIGN.md). Samples run in worker processes (one planner and corridor per worker);
each finished row is appended to ``samples.jsonl`` at once, so an interrupted campaign
resumes without losing or repeating a sample, and a sample that raises is recorded with
its reason. ``samples.parquet`` and down-sampled ``trajectories.parquet`` are written at
the end.
"""
from __future__ import annotations

import json
import math
import multiprocessing as mp
import os
import time
import traceback

import numpy as np
from pydrake.common import RandomGenerator
from pydrake.systems.analysis import RandomSimulation

from drake_entry.diagrams.closed_loop import SOURCES, build_closed_loop, summarise
from drake_entry.diagrams.common import collect_trajectory, make_simulator
from drake_entry.dispersions import draw
from drake_entry.planning.drag_energy import DragEnergyPlanner
from drake_entry.scenario import Scenario, load_scenario

TRAJECTORY_STEP_S = 10.0  # default spacing of the down-sampled trajectory table [s]
# row columns that measure this machine's wall-clock time (excluded from reproducibility)
TIMING_COLUMNS = ("wall_time_s", "planning_wall_s")


def sample_seed(campaign_seed: int, index: int) -> int:
    """The RandomGenerator seed of sample ``index`` (independent streams per sample)."""
    return int(np.random.SeedSequence([int(campaign_seed), int(index)]).generate_state(1)[0])


def run_sample(scenario: Scenario, planner: DragEnergyPlanner, campaign_seed: int, index: int, *,
               trajectory_step_s: float = TRAJECTORY_STEP_S) -> tuple[dict, dict | None]:
    """One Monte-Carlo sample of ``scenario.dispersions``: (row, trajectory columns every
    ``trajectory_step_s`` seconds plus the final instant, or None when it is 0)."""
    seed = sample_seed(campaign_seed, index)
    t_wall = time.perf_counter()
    row = {"index": int(index), "seed": seed}
    box = {}

    def make(generator: RandomGenerator):
        box["draw"] = d = draw(scenario.dispersions, generator)
        diagram, loggers, _ = build_closed_loop(scenario, planner, draw=d)
        box["diagram"], box["loggers"] = diagram, loggers
        simulator = make_simulator(diagram, scenario, closed_loop=True)
        box["simulator"] = simulator
        return simulator

    def output(system, context):
        box["context"] = context
        x = system.GetSubsystemByName("vehicle").GetOutputPort("state").Eval(
            system.GetSubsystemByName("vehicle").GetMyContextFromRoot(context))
        return float(x[0])

    try:
        RandomSimulation(make, output, scenario.simulation.max_time_s, RandomGenerator(seed))
        diagram, ctx = box["diagram"], box["context"]
        reason = diagram.GetSubsystemByName("termination").reason
        reason = f"reached {reason}" if reason else "max_time"
        tr = collect_trajectory(diagram, box["loggers"], ctx, sources=SOURCES, reason=reason,
                                wall_time=time.perf_counter() - t_wall)
        res = summarise(diagram, ctx, tr, scenario, planner)
        row.update(box["draw"].columns())
        row.update(_row(res, planner))
        integrator = box["simulator"].get_integrator()
        row.update({"planning_wall_s": res.planning_wall_s, "integration_steps": integrator.get_num_steps_taken(),
                    "derivative_evaluations": integrator.get_num_derivative_evaluations()})
        traj = _downsample(tr, index, trajectory_step_s) if trajectory_step_s > 0 else None
    except Exception as e:  # one failed sample never stops the campaign
        row.update(box["draw"].columns() if "draw" in box else {})
        row.update({"success": False, "message": f"{type(e).__name__}: {e}".splitlines()[0][:500],
                    "traceback": traceback.format_exc(limit=3)[-2000:]})
        traj = None
    row["wall_time_s"] = time.perf_counter() - t_wall
    return row, traj


def _row(res, planner: DragEnergyPlanner) -> dict:
    tr = res.trajectory
    limits = planner.vehicle.limits
    peak_q = float(tr.column("dynamic_pressure").max())
    peak_heat = float(tr.column("heat_flux").max())
    peak_nz = float(tr.column("normal_load").max())
    row = {
        "success": bool(res.success), "message": res.message, "stop": tr.reason,
        "flight_time_s": float(tr.time[-1]), "engaged_at_s": res.engaged_at if res.engaged_at is not None else np.nan,
        "plans": int(res.plans), "planning_failures": len(res.planning_failures), "reversals": int(res.reversals),
        "final_altitude_m": float(tr.state[-1, 0]), "final_velocity_m_s": float(tr.state[-1, 3]),
        "final_longitude_deg": math.degrees(tr.state[-1, 1]), "final_latitude_deg": math.degrees(tr.state[-1, 2]),
        "err_altitude_m": res.errors["altitude_m"], "err_longitude_deg": res.errors["longitude_deg"],
        "err_latitude_deg": res.errors["latitude_deg"], "err_velocity_m_s": res.errors["velocity_m_s"],
        "err_range_m": res.errors["range_to_go_m"], "err_crossrange_m": res.errors["crossrange_m"],
        "err_distance_m": res.errors["distance_m"],
        "peak_heat_flux_W_m2": peak_heat, "peak_dynamic_pressure_Pa": peak_q, "peak_normal_load_g": peak_nz,
        "margin_heat_flux": 1.0 - peak_heat / limits.heat_flux_max,
        "margin_dynamic_pressure": 1.0 - peak_q / limits.dynamic_pressure_max,
        "margin_normal_load": 1.0 - peak_nz / limits.normal_load_max,
    }
    return row


def _downsample(tr, index: int, step_s: float) -> dict:
    t = tr.time
    keep = np.unique(np.append(np.searchsorted(t, np.arange(0.0, t[-1], step_s)), len(t) - 1))
    out = {"sample": np.full(keep.size, index), **{k: np.asarray(v)[keep] for k, v in tr.table().items()}}
    ref = tr.extra.get("reference")
    if ref is not None:
        out["reference_drag_m_s2"] = ref[keep, 0]
    return {k: np.asarray(v).tolist() for k, v in out.items()}


# ---------------------------------------------------------------------------------------
# campaign
# ---------------------------------------------------------------------------------------
_WORKER = {}


def _init_worker(scenario_path: str, overrides: dict, trajectory_step_s: float = TRAJECTORY_STEP_S):
    _WORKER["trajectory_step_s"] = trajectory_step_s
    scenario = load_scenario(scenario_path)
    apply_overrides(scenario, overrides)
    _WORKER["scenario"] = scenario
    _WORKER["planner"] = DragEnergyPlanner.from_scenario(scenario)


def _work(args):
    seed, index = args
    return run_sample(_WORKER["scenario"], _WORKER["planner"], seed, index,
                      trajectory_step_s=_WORKER["trajectory_step_s"])


def _dask_task(scenario_path: str, overrides: dict, seed: int, index: int, trajectory_step_s: float):
    """One sample on a Dask worker; the scenario and planner are built once per worker process."""
    key = (scenario_path, json.dumps(overrides or {}, sort_keys=True), trajectory_step_s)
    if _WORKER.get("key") != key:
        _init_worker(scenario_path, overrides, trajectory_step_s)
        _WORKER["key"] = key
    return _work((seed, index))


BACKENDS = ("serial", "processes", "dask")

# Dask settings for CPU-bound pure-Python tasks (see _run_dask)
DASK_QUIET_WORKERS = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1000ms",
    "distributed.admin.system-monitor.interval": "5000ms",
    "distributed.worker.memory.monitor-interval": "1000ms",
}


def apply_overrides(scenario: Scenario, overrides: dict):
    """Set dotted fields, e.g. {'guidance.replan_period_s': 0}."""
    for key, value in (overrides or {}).items():
        obj = scenario
        *path, last = key.split(".")
        for p in path:
            obj = getattr(obj, p)
        if not hasattr(obj, last):
            raise ValueError(f"override '{key}': no such field")
        setattr(obj, last, value)
    scenario.validate()


def _trim_partial_line(path: str):
    """Drop a last line cut by an interruption, so appended rows start on a fresh line."""
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return
    with open(path, "rb+") as f:
        data = f.read()
        if data.endswith(b"\n"):
            return
        f.truncate(data.rfind(b"\n") + 1)


def done_indices(out_dir: str) -> set:
    path = os.path.join(out_dir, "samples.jsonl")
    if not os.path.exists(path):
        return set()
    done = set()
    with open(path) as f:
        for line in f:
            try:
                done.add(json.loads(line)["index"])
            except (json.JSONDecodeError, KeyError):
                continue  # a line cut by an interruption: that sample runs again
    return done


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
        raise ValueError(f"backend '{backend}' is unknown; allowed: {', '.join(BACKENDS)}")
    if not runs >= 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if not trajectory_step_s >= 0:
        raise ValueError(f"trajectory_step_s must be >= 0 s (0 = no trajectories), got {trajectory_step_s}")
    os.makedirs(out_dir, exist_ok=True)
    meta_path = os.path.join(out_dir, "campaign.json")
    meta = {"scenario": scenario_path, "runs": runs, "seed": seed, "overrides": overrides or {},
            "trajectory_step_s": trajectory_step_s,
            "dispersion": "scenario dispersions"}
    if os.path.exists(meta_path):
        old = json.load(open(meta_path))
        if {k: old.get(k) for k in ("scenario", "seed", "overrides")} != {k: meta[k] for k in
                                                                        ("scenario", "seed", "overrides")}:
            raise ValueError(f"{out_dir} holds a campaign with other settings ({old}); use another --out")
    json.dump(meta, open(meta_path, "w"), indent=2)
    for name in ("samples.jsonl", "trajectories.jsonl"):
        _trim_partial_line(os.path.join(out_dir, name))
    todo = [i for i in range(runs) if i not in done_indices(out_dir)]
    workers = workers or os.cpu_count() or 1
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=runs, initial=runs - len(todo), unit="run", desc="campaign", smoothing=0.05)
    with open(os.path.join(out_dir, "samples.jsonl"), "a") as rows_f, \
            open(os.path.join(out_dir, "trajectories.jsonl"), "a") as traj_f:
        failed = 0

        def record(row, traj):
            nonlocal failed
            rows_f.write(json.dumps(row, default=float) + "\n")
            rows_f.flush()
            if traj is not None:
                traj_f.write(json.dumps(traj) + "\n")
                traj_f.flush()
            if bar is not None:
                bar.update(1)
                if not row.get("success"):
                    failed += 1
                    bar.set_postfix(failed=failed)

        if backend == "serial" or (backend == "processes" and workers == 1):
            _init_worker(scenario_path, overrides, trajectory_step_s)
            for i in todo:
                record(*_work((seed, i)))
        elif backend == "processes":
            ctx = mp.get_context("spawn")
            with ctx.Pool(workers, initializer=_init_worker,
                          initargs=(scenario_path, overrides, trajectory_step_s)) as pool:
                for row, traj in pool.imap_unordered(_work, [(seed, i) for i in todo], chunksize=1):
                    record(row, traj)
        else:
            _run_dask(todo, record, scenario_path, overrides, seed, workers, scheduler, trajectory_step_s)
    if bar is not None:
        bar.close()
    finalise(out_dir)
    return out_dir


def _run_dask(todo, record, scenario_path, overrides, seed, workers, scheduler, trajectory_step_s):
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
        futures = {client.submit(_dask_task, scenario_path, overrides, seed, i, trajectory_step_s, pure=False): i for i in todo}
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


def finalise(out_dir: str):
    """Convert the JSONL streams to Parquet tables (sorted by sample index)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = {}
    with open(os.path.join(out_dir, "samples.jsonl")) as f:
        for line in f:
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue
            rows[r["index"]] = r
    ordered = [rows[k] for k in sorted(rows)]
    keys = sorted({k for r in ordered for k in r if k != "traceback"})
    table = {k: [r.get(k) for r in ordered] for k in keys}
    pq.write_table(pa.table(table), os.path.join(out_dir, "samples.parquet"))
    cols = {}
    path = os.path.join(out_dir, "trajectories.jsonl")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                try:
                    t = json.loads(line)
                except json.JSONDecodeError:
                    continue
                for k, v in t.items():
                    cols.setdefault(k, []).extend(v)
        if cols:
            pq.write_table(pa.table(cols), os.path.join(out_dir, "trajectories.parquet"))
