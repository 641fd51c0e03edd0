"""Abort reachability campaigns of paper 001 Sec. VI through the campaign engine: every
case is an SCvx plan (``guidance.scvx.plan_entry``) whose verdict is its controls flown by
the Drake Simulator through the closed loop's actuators (``verification.fly_controls``), one
row per case (``abort_row``), run on any backend (``campaign.run_cases``: serial, processes,
Dask), resumable.

    run_orbital_aborts(out_dir)   the EIP grid (9 x 9 at 5 deg by default)
    run_descent_aborts(out_dir)   the nominal flown, re-planned to an alternative site every 50 s

The cases and the Tables 4-7 statistics are ``guidance.scvx.aborts``; the report and
figures ``guidance.scvx.aborts.report``.
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np

from drake_entry.campaign.backends import Task
from drake_entry.campaign.engine import run_cases, task_manifest
from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.aborts.cases import (
    ALTERNATIVE_SITES,
    DESCENT_ABORT_SPACING_S,
    FEASIBLE_RADII_M,
    GRID_SHAPE,
    GRID_SPACING_DEG,
    OPEN_SITE_RADIUS_M,
    case_mission,
    descent_abort_cases,
    feasible,
    orbital_abort_cases,
)
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.planner import plan_entry
from drake_entry.guidance.scvx.settings import EntryProblemSettings, ScvxSettings
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle

__all__ = ["TRAJECTORY_STEP_S", "AbortStudy", "setup_worker", "abort_row", "plan_trajectory", "run_case",
           "run_orbital_aborts", "fly_nominal", "run_descent_aborts"]

#: spacing [s] of the planned trajectory kept per case for the figures
TRAJECTORY_STEP_S = 20.0


@dc.dataclass(frozen=True)
class AbortStudy:
    """What every case of an abort campaign shares (JSON-able: it is the campaign's identity).

    Attributes:
      vehicle: packaged vehicle name or YAML path (paper 001: 'sphynx').
      mission: ScvxMission fields of the nominal mission (the cases change the entry and site).
      problem: EntryProblemSettings fields (default: the direct formulation, minimum heat load).
      scvx: ScvxSettings fields.
    """

    vehicle: str = "sphynx"
    mission: dict = dc.field(default_factory=dict)
    problem: dict = dc.field(default_factory=dict)
    scvx: dict = dc.field(default_factory=dict)

    def config(self) -> dict:
        """The settings as a plain dict (validated by building them once)."""
        self.models()
        return dc.asdict(self)

    def models(self):
        """(vehicle, planet, atmosphere, mission, problem settings, SCvx settings): the oblate
        J2 Earth and US76 of the paper's case."""
        return (load_vehicle(self.vehicle), Earth.oblate(), US76Atmosphere(), ScvxMission(**self.mission),
                EntryProblemSettings(**self.problem), ScvxSettings(**self.scvx))


def setup_worker(config: dict) -> tuple:
    """A worker's models, built once (backends.Task.setup)."""
    return AbortStudy(**config).models()


def abort_row(case: dict, plan, wall_s: float) -> dict:
    """One case's row: the case, the plan's figures (Tables 4-7 quantities), its flown miss
    (``plan.flown``: the Drake flight of its controls; inf when it stopped early; flown_drs_ok:
    inside the case's DRS box) and the feasibility at 10 and 40 km
    (``guidance.scvx.aborts.feasible``)."""
    flight = plan.flown
    history = plan.history
    socp = [r.solver_iterations for r in history]
    row = {**case, "plan_success": bool(plan.success), "message": plan.message, "iterations": int(plan.iterations),
           "plan_wall_s": float(wall_s), "mean_socp_iterations": float(np.mean(socp)) if socp else math.nan,
           "rejected_steps": int(sum(not r.accepted for r in history)), "objective": float(plan.objective),
           **{k: float(v) for k, v in plan.metrics.items()},
           "planned_miss_km": plan.miss_m / 1e3, "drs_altitude_km": plan.drs["altitude_m"] / 1e3,
           "drs_mach": plan.drs["mach"], "drs_vertical_speed_m_s": plan.drs["vertical_speed_m_s"],
           "propagated_error_km": plan.propagated_error_m / 1e3, "max_defect": plan.max_defect,
           "flown_miss_km": flight.from_site_m / 1e3, "flown_from_plan_km": flight.from_plan_m / 1e3,
           "flown_drs_ok": flight.drs_ok}
    for radius in FEASIBLE_RADII_M:
        row[f"feasible_{radius / 1e3:g}km"] = feasible(row, radius)
    row["success"] = row[f"feasible_{FEASIBLE_RADII_M[-1] / 1e3:g}km"]
    return row


def plan_trajectory(plan, index: int, step_s: float = TRAJECTORY_STEP_S) -> dict:
    """The planned trajectory every ``step_s`` seconds and at t_f, as campaign columns."""
    t = np.append(np.arange(0.0, plan.final_time, step_s), plan.final_time)
    ev = plan.evaluate(t)
    cols = {"sample": [index] * t.size, "time": t}
    cols.update({k: ev[k] for k in ("h", "lon", "lat", "V", "gamma", "psi", "bank", "alpha")})
    return {k: np.asarray(v).tolist() for k, v in cols.items()}


def run_case(models: tuple, case: dict):
    """Plan one abort case and fly it (backends.Task.run): (row, planned trajectory)."""
    vehicle, planet, atmosphere, mission, problem, scvx = models
    t0 = time.perf_counter()
    plan = plan_entry(vehicle, planet, atmosphere, case_mission(mission, case), problem_settings=problem,
                      settings=scvx, verifier=fly_controls)
    wall = time.perf_counter() - t0
    return abort_row(case, plan, wall), plan_trajectory(plan, case["index"])


def _run(study: AbortStudy, cases: list, out_dir: str, kind: str, extra: dict, **campaign) -> str:
    task = Task("drake_entry.guidance.scvx.aborts.study:setup_worker", "drake_entry.guidance.scvx.aborts.study:run_case", study.config())
    manifest = task_manifest(task, cases, kind=kind, **extra)
    return run_cases(task, cases, out_dir, manifest, desc=kind.replace("_", " "), **campaign)


def run_orbital_aborts(out_dir: str, *, study: AbortStudy | None = None, shape: tuple = GRID_SHAPE,
                       spacing_deg: float = GRID_SPACING_DEG, backend: str = "processes", workers: int | None = None,
                       scheduler: str | None = None, progress: bool = True) -> str:
    """The orbital-abort map (paper 001 Sec. VI.A): one plan from each EIP of
    ``orbital_abort_cases`` (``shape`` rows of latitude x columns of longitude, ``spacing_deg``
    apart, centred on the mission's EIP) to the mission's site, each flown. Resumable; returns out_dir."""
    study = study or AbortStudy()
    _, planet, _, mission, _, _ = study.models()
    cases = orbital_abort_cases(mission, planet, shape=shape, spacing_deg=spacing_deg)
    extra = {"shape": list(shape), "spacing_deg": spacing_deg, "site": [mission.site_longitude_deg,
                                                                         mission.site_latitude_deg]}
    return _run(study, cases, out_dir, "orbital_aborts", extra, backend=backend, workers=workers,
                scheduler=scheduler, progress=progress)


def fly_nominal(study: AbortStudy):
    """The nominal plan and its Drake flight (the trajectory the descent aborts leave)."""
    vehicle, planet, atmosphere, mission, problem, scvx = study.models()
    plan = plan_entry(vehicle, planet, atmosphere, mission, problem_settings=problem, settings=scvx,
                      verifier=fly_controls)
    if not plan.success:
        raise ScenarioError(f"the nominal plan of the descent aborts failed: {plan.message}")
    return plan, plan.flown


def run_descent_aborts(out_dir: str, *, study: AbortStudy | None = None, site: str = "ben_guerir",
                       spacing_s: float = DESCENT_ABORT_SPACING_S, objective: str = "miss",
                       last_abort_s: float | None = None, backend: str = "processes", workers: int | None = None,
                       scheduler: str | None = None, progress: bool = True) -> str:
    """Descent aborts (paper 001 Sec. VI.B): the nominal plan flown by the Drake Simulator
    through the actuators, and every ``spacing_s`` seconds (up to ``last_abort_s``, default the whole flight) a new
    plan from the flown state and attitude to ``site`` (a key of ALTERNATIVE_SITES) with
    ``objective`` ('miss' as the paper: its hard 10-km cone made early aborts artificially
    infeasible; the cone is then opened to 5000 km and the 10 km counted afterwards), each
    flown. Resumable; returns out_dir."""
    if site not in ALTERNATIVE_SITES:
        raise ScenarioError(f"descent abort site '{site}' is unknown; allowed: {', '.join(ALTERNATIVE_SITES)}")
    study = study or AbortStudy()
    plan, flight = fly_nominal(study)
    planet = plan.problem.planet
    radius = OPEN_SITE_RADIUS_M if objective == "miss" else plan.problem.mission.site_radius_m
    # the attitude being flown: the actuators' outputs (inside their bounds; the plan's own
    # polynomials overshoot alpha's 45-deg bound by 0.02 deg between nodes)
    flown = flight.trajectory
    cases = descent_abort_cases(flown.time, flown.state, flown.bank, flown.alpha, planet,
                                site=ALTERNATIVE_SITES[site], spacing_s=spacing_s, site_radius_m=radius,
                                flight_path_bounds_deg=plan.problem.mission.flight_path_bounds_deg)
    if last_abort_s is not None:
        cases = [c for c in cases if c["abort_time_s"] <= last_abort_s]
    abort_study = dc.replace(study, problem={**study.problem, "objective": objective})
    extra = {"site": list(ALTERNATIVE_SITES[site]), "site_name": site, "spacing_s": spacing_s,
             "nominal": {"final_time_s": plan.final_time, "heat_load_MJ_m2": plan.metrics["heat_load_MJ_m2"],
                         "flown_lon_deg": np.degrees(flown.state[:, 1]).tolist()[::20],
                         "flown_lat_deg": np.degrees(flown.state[:, 2]).tolist()[::20]}}
    return _run(abort_study, cases, out_dir, "descent_aborts", extra, backend=backend, workers=workers,
                scheduler=scheduler, progress=progress)
