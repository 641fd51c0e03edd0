"""One Monte-Carlo sample of a closed loop through Drake's RandomSimulation, and its row.

Each sample is one ``pydrake.systems.analysis.RandomSimulation`` whose RandomGenerator is
seeded from (campaign seed, sample index) only, so any sample re-runs alone and
reproduces its row. Inside ``make_simulator`` the sample's dispersions are drawn from that
generator and built into the diagram's defaults (Drake's SetRandomContext then keeps
them; docs/architecture.md, "Integration"). A sample that raises returns a row with its reason instead.
"""
from __future__ import annotations

import math
import time
import traceback

import numpy as np
from pydrake.common import RandomGenerator
from pydrake.systems.analysis import RandomSimulation

from drake_entry.diagrams.closed_loop import ClosedLoopResult, ClosedLoopSetup, build_closed_loop, summarise
from drake_entry.diagrams.common import collect_trajectory, make_simulator
from drake_entry.models.dispersions import draw
from drake_entry.models.trajectory import control_activity, metrics, navigation_errors
from drake_entry.scenario import scenario_from_dump
from drake_entry.systems.lifetime import release_system
from drake_entry.systems.native_plant import as_flight_error

__all__ = ["TRAJECTORY_STEP_S", "DETAILED_SAMPLES", "DETAILED_STEP_S", "TIMING_COLUMNS", "sample_seed",
           "setup_worker", "run_case", "run_sample", "campaign_row", "downsample", "PEAK_COLUMNS",
           "EXTREME_COLUMNS"]

TRAJECTORY_STEP_S = 10.0  # default spacing of the down-sampled trajectory table [s]
#: the first samples are stored at this finer step [s] (the report's bank histories), when the
#: campaign keeps trajectories at all
DETAILED_SAMPLES, DETAILED_STEP_S = 5, 1.0
# row columns that measure this machine's wall-clock time (excluded from reproducibility)
TIMING_COLUMNS = ("wall_time_s", "planning_wall_s")


def sample_seed(campaign_seed: int, index: int) -> int:
    """The RandomGenerator seed of sample ``index`` (independent streams per sample)."""
    return int(np.random.SeedSequence([int(campaign_seed), int(index)]).generate_state(1)[0])


def setup_worker(config: dict) -> dict:
    """A campaign worker's state (backends.Task.setup): the ClosedLoopSetup (models, guidance
    method and its planner) built once from config['scenario_yaml'], the campaign seed and
    the trajectory step."""
    scenario = scenario_from_dump(config["scenario_yaml"])  # validated once, when the campaign began
    return {"setup": ClosedLoopSetup.from_scenario(scenario), "seed": int(config["seed"]),
            "trajectory_step_s": float(config["trajectory_step_s"])}


def run_case(state: dict, case: dict):
    """Sample case['index'] of the campaign (backends.Task.run)."""
    return run_sample(state["setup"], state["seed"], case["index"], trajectory_step_s=state["trajectory_step_s"])


def run_sample(setup: ClosedLoopSetup, campaign_seed: int, index: int, *,
               trajectory_step_s: float = TRAJECTORY_STEP_S) -> tuple[dict, dict | None]:
    """One Monte-Carlo sample of ``setup.scenario.dispersions``: (row, trajectory columns every
    ``trajectory_step_s`` seconds (the first DETAILED_SAMPLES samples every DETAILED_STEP_S)
    plus the final instant, or None when it is 0)."""
    scenario = setup.scenario
    seed = sample_seed(campaign_seed, index)
    t_wall = time.perf_counter()
    row = {"index": int(index), "seed": seed}
    box = {}

    def make(generator: RandomGenerator):
        box["draw"] = d = draw(scenario.dispersions, generator)
        box["built"] = built = build_closed_loop(setup, draw=d)
        box["simulator"] = simulator = make_simulator(built.diagram, scenario, closed_loop=True)
        return simulator

    def output(system, context):
        box["context"] = context
        vehicle = system.GetSubsystemByName("vehicle")
        return float(vehicle.GetOutputPort("state").Eval(vehicle.GetMyContextFromRoot(context))[0])

    try:
        RandomSimulation(make, output, scenario.simulation.max_time_s, RandomGenerator(seed))
        built, ctx = box["built"], box["context"]
        reason = built.diagram.GetSubsystemByName("termination").reason or "max_time"
        tr = collect_trajectory(built.diagram, built.loggers, ctx, sources=built.sources, reason=reason,
                                wall_time=time.perf_counter() - t_wall, columns=built.columns,
                                step_loggers=built.step_loggers)
        res = summarise(setup, built.diagram, ctx, tr)
        row.update(box["draw"].columns())
        row.update(campaign_row(res, setup))
        integrator = box["simulator"].get_integrator()
        row.update({"plant": built.plant, "integration_steps": integrator.get_num_steps_taken(),
                    "derivative_evaluations": integrator.get_num_derivative_evaluations()})
        step = min(trajectory_step_s, DETAILED_STEP_S) if index < DETAILED_SAMPLES else trajectory_step_s
        traj = downsample(tr, index, step) if trajectory_step_s > 0 else None
    except Exception as raised:  # one failed sample never stops the campaign
        e = as_flight_error(raised)
        row.update(box["draw"].columns() if "draw" in box else {})
        row.update({"success": False, "message": f"{type(e).__name__}: {e}".splitlines()[0][:500],
                    "traceback": traceback.format_exc(limit=3)[-2000:]})
        traj = None
    finally:
        if "built" in box:  # everything wanted from the flight is read: let its diagram be freed
            release_system(box["built"].diagram)
    row["wall_time_s"] = time.perf_counter() - t_wall
    return row, traj


def campaign_row(res: ClosedLoopResult, setup: ClosedLoopSetup) -> dict:
    """The row of one flight: the verdict (success = reached, inside_box and within_limits;
    violations: each breached path limit with its peak, time and margin, '' when none), the
    method's fields, final state, terminal errors, peak path quantities
    (drake_entry.models.trajectory.metrics), the bank's activity (``control_activity``), the
    margin of every path limit (drake_entry.models.verdict), and each acceptance criterion's
    inside flag and error (``box_<criterion>_error``: SI, m, m/s, rad, or Mach)."""
    tr, x = res.trajectory, res.trajectory.state[-1]
    g, v = res.guidance, res.verdict
    return {
        "success": bool(res.success), "inside_box": v.inside_box, "within_limits": v.within_limits,
        "violations": v.violations_text(), "message": res.message, "stop": tr.reason,
        "reached_terminal": bool(res.reached), "method": res.method,
        "flight_time_s": float(tr.time[-1]), "plans": int(g.plans), "planning_wall_s": g.planning_wall_s, **g.fields,
        "final_altitude_m": float(x[0]), "final_velocity_m_s": float(x[3]),
        "final_longitude_deg": math.degrees(x[1]), "final_latitude_deg": math.degrees(x[2]),
        "err_altitude_m": res.errors["altitude_m"], "err_longitude_deg": res.errors["longitude_deg"],
        "err_latitude_deg": res.errors["latitude_deg"], "err_velocity_m_s": res.errors["velocity_m_s"],
        "err_range_m": res.errors["range_to_go_m"], "err_crossrange_m": res.errors["crossrange_m"],
        "err_distance_m": res.errors["distance_m"],
        **metrics(tr), **navigation_errors(tr), **v.margins(),
        **control_activity(tr, setup.vehicle.bank_limit, setup.vehicle.bank_rate_limit),
        **{f"inside_{k}_box": b["inside"] for k, b in res.box.items()},
        **{f"box_{k}_error": b["error"] for k, b in res.box.items()},
    }


#: trajectory columns whose per-flight largest value ``downsample`` keeps (the path limits' quantities)
PEAK_COLUMNS = ("dynamic_pressure_Pa", "heat_flux_W_m2", "normal_load_g", "total_load_g")
#: trajectory columns whose per-flight smallest and largest values it keeps (a mission's state bounds)
EXTREME_COLUMNS = ("flight_path_deg",)


def downsample(tr, index: int, step_s: float) -> dict:
    """Trajectory columns of ``tr`` every ``step_s`` [s], at its final instant and at the log
    samples where each PEAK_COLUMNS column is largest and each EXTREME_COLUMNS column smallest
    and largest (so a stored line reaches its flight's peaks at the log period, not only the
    peaks that fall on the ``step_s`` grid), tagged ``sample`` = index."""
    t, table = tr.time, tr.table()
    picks = [np.searchsorted(t, np.arange(0.0, t[-1], step_s)), [len(t) - 1]]
    for name in PEAK_COLUMNS + EXTREME_COLUMNS:
        v = np.asarray(table.get(name, ()), float)
        if v.size and np.isfinite(v).any():
            picks.append([np.nanargmax(v)] + ([np.nanargmin(v)] if name in EXTREME_COLUMNS else []))
    keep = np.unique(np.concatenate([np.asarray(p, int) for p in picks]))
    out = {"sample": np.full(keep.size, index), **{k: np.asarray(v)[keep] for k, v in table.items()}}
    return {k: np.asarray(v).tolist() for k, v in out.items()}
