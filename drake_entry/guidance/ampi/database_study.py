"""Paper 003's trajectory database solved through the campaign engine: every grid case is
an NLP solve (planning.nlp, verified) of the problem with its entry state offset (eq. 6),
stored at the LD nodes (guidance.ampi.TrajectoryDatabase).

Continuation: the cases run in waves of growing grid distance from the nominal
(ParameterGrid.waves), each wave on any backend (serial, processes, Dask) through
``campaign.run_cases``, each case warm-started from its parent (the neighbour one step
closer to the nominal) or, when that failed, from its best verified neighbour. Then every
case is checked against its neighbours (TrajectoryDatabase.inconsistent: a worse branch,
a jump in t_f or bank) and outliers are re-solved from their best neighbour, up to
``resolve_rounds`` times. Resumable: a rerun with the same settings skips every case done.

    db, report = build_database(out_dir, DatabaseStudy(problem="shefex3"))
"""
from __future__ import annotations

import dataclasses as dc
import math
import os
import time

import numpy as np

from drake_entry.campaign.backends import Task
from drake_entry.campaign.engine import run_cases, task_manifest
from drake_entry.campaign.store import read_rows, read_trajectories
from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.database import TrajectoryDatabase
from drake_entry.guidance.ampi.grid import ParameterGrid
from drake_entry.planning import nlp
from drake_entry.planning.ocp_yaml import load_problem
from drake_entry.planning.pseudospectral import lgl_nodes

__all__ = ["DATABASE_FILE", "DatabaseStudy", "setup_worker", "case_problem", "offset_problem", "solve_case",
           "build_database"]

DATABASE_FILE = "database.npz"


@dc.dataclass(frozen=True)
class DatabaseStudy:
    """What every case shares (JSON-able: the campaign's identity).

    Attributes:
      problem: packaged problem name or YAML path (its initial state is the nominal entry).
      grid: ParameterGrid.as_dict() (default: paper 003 eq. 5, 3^6 cases).
      ld_nodes: LGL nodes each solution is stored at (paper eq. 11's N_LD).
      transcription, nodes, tolerance: the NLP settings (None: the problem YAML's solve:).
      max_iterations: the solver's (major) iteration limit per case: a warm-started case needs
        tens, and a case that wanders must not hold a worker for minutes (the reduced 3 x 3
        grid: one cold case ran SNOPT for over 11 min at the library's 3000); it fails and is
        re-solved from another neighbour.
    """

    problem: str = "shefex3"
    grid: dict = dc.field(default_factory=lambda: ParameterGrid.paper_003().as_dict())
    ld_nodes: int = 60
    transcription: str | None = None
    nodes: int | None = None
    tolerance: float | None = None
    max_iterations: int = 300

    def config(self) -> dict:
        """The settings as a plain dict, checked by building the problem and grid once."""
        setup_worker(dc.asdict(self))
        return dc.asdict(self)


def setup_worker(config: dict) -> dict:
    """A worker's state: the nominal problem, the grid and the solve settings (nlp.solve's keywords)."""
    problem, solve = load_problem(config["problem"])
    grid = ParameterGrid.from_dict(config["grid"])
    if not 3 <= int(config["ld_nodes"]) <= 400:
        raise ScenarioError(f"ld_nodes = {config['ld_nodes']}: allowed 3..400")
    settings = {"transcription": config.get("transcription") or solve.transcription,
                "nodes": int(config.get("nodes") or solve.nodes),
                "tolerance": float(config.get("tolerance") or solve.tolerance),
                "max_iterations": int(config.get("max_iterations") or solve.max_iterations),
                "dynamics_tolerance": solve.dynamics_tolerance, "propagation_tolerance": solve.propagation_tolerance,
                "refine": bool(solve.refine), "max_nodes": int(solve.max_nodes) or None}
    for name in grid.names:
        if not isinstance(problem.initial.get(name), float):
            raise ScenarioError(f"grid offsets '{name}' but the problem's initial {name} is not fixed")
    return {"problem": problem, "grid": grid, "ld_nodes": int(config["ld_nodes"]), "settings": settings}


def case_problem(problem, grid: ParameterGrid, index: int):
    """The problem of case ``index``: the nominal entry state plus the case's offsets (eq. 6)."""
    return offset_problem(problem, grid.offsets(index))


def offset_problem(problem, offsets: dict):
    """The problem with its entry state offset by ``offsets`` ({state name: offset}, SI /
    rad; eq. 6). An altitude offset is geodetic, and the geodetic entry altitude is kept when
    the latitude is offset (on an oblate planet the state altitude is converted at the new
    latitude)."""
    initial = dict(problem.initial)
    planet = problem.planet
    geodetic = planet.atmospheric_altitude(initial["h"], initial["lat"])
    for name, offset in offsets.items():
        initial[name] = initial[name] + offset
    initial["h"] = float(planet.state_altitude(geodetic + offsets.get("h", 0.0), initial["lat"]))
    return dc.replace(problem, initial=initial)


def solve_case(state: dict, case: dict):
    """One database case: (row, its LD samples as trajectory columns)."""
    problem, grid, s = state["problem"], state["grid"], state["settings"]
    index = case["index"]
    guess = None
    if case.get("guess") is not None:
        g = case["guess"]
        guess = (np.asarray(g["t"]), np.asarray(g["states"]), np.asarray(g["controls"]))
    t0 = time.perf_counter()
    r = nlp.solve(case_problem(problem, grid, index), guess=guess, verifier=fly_controls, **s)
    wall = time.perf_counter() - t0
    t = 0.5 * (lgl_nodes(state["ld_nodes"]) + 1.0) * r.final_time  # the LD times
    X, U = r.state_function()(t), r.control_function()(t)
    row = {"index": index, "success": bool(r.success), "converged": bool(r.converged), "message": r.message[:300],
           "objective": float(r.objective), "final_time_s": float(r.final_time), "wall_s": wall,
           "guess_from": case.get("guess_from", -1), "attempt": case.get("attempt", 0),
           "dynamics_error": float(r.verification.dynamics_error) if r.verification is not None else math.nan}
    cols = {"sample": [index] * t.size, "time": t.tolist()}
    cols.update({n: X[:, i].tolist() for i, n in enumerate(problem.state_names)})
    cols.update({n: U[:, j].tolist() for j, n in enumerate(problem.control_names)})
    return row, cols


def _arrays(traj: dict, problem) -> tuple[np.ndarray, np.ndarray]:
    """(states, controls) of a stored case's trajectory columns."""
    return (np.column_stack([traj[n] for n in problem.state_names]),
            np.column_stack([traj[n] for n in problem.control_names]))


def _guess(traj: dict, problem) -> dict:
    X, U = _arrays(traj, problem)
    return {"t": traj["time"], "states": X.tolist(), "controls": U.tolist()}


def _read(out_dir: str):
    rows, _ = read_rows(out_dir) if os.path.isdir(out_dir) else ({}, None)
    return rows, (read_trajectories(out_dir, set(rows)) if rows else {})


def _start(grid, index, rows, trajs, problem):
    """(guess dict or None, where from): the parent if verified, else the verified neighbour
    with the least objective, else the built-in guess."""
    parent = grid.parent(index)
    ok = [j for j in ([parent] if parent is not None else []) if rows.get(j, {}).get("success") and j in trajs]
    if not ok:
        nb = [j for j in grid.neighbours(index) if rows.get(j, {}).get("success") and j in trajs]
        ok = sorted(nb, key=lambda j: rows[j]["objective"])[:1]
    return (_guess(trajs[ok[0]], problem), ok[0]) if ok else (None, -1)


def build_database(out_dir: str, study: DatabaseStudy | None = None, *, backend: str = "processes",
                   workers: int | None = None, scheduler: str | None = None, progress: bool = True,
                   resolve_rounds: int = 2) -> tuple[TrajectoryDatabase, dict]:
    """Solve every case of ``study`` (module docstring) into ``out_dir`` (resumable), write
    ``out_dir/database.npz``; returns (the database, a report: counts, outliers left, times)."""
    study = study or DatabaseStudy()
    config = study.config()
    state = setup_worker(config)
    problem, grid = state["problem"], state["grid"]
    task = Task("drake_entry.guidance.ampi.database_study:setup_worker", "drake_entry.guidance.ampi.database_study:solve_case",
                config)
    manifest = task_manifest(task, [{"index": i} for i in range(grid.size)], kind="ampi_database")
    campaign = dict(backend=backend, workers=workers, scheduler=scheduler, progress=progress)
    t0 = time.perf_counter()
    for k, wave in enumerate(grid.waves()):
        rows, trajs = _read(out_dir)
        cases = []
        for i in wave:
            if i in rows:
                continue
            guess, src = _start(grid, i, rows, trajs, problem)
            cases.append({"index": i, "guess": guess, "guess_from": src})
        if cases:
            run_cases(task, cases, out_dir, manifest, desc=f"database wave {k}", **campaign)
    rows, trajs = _read(out_dir)
    db = _assemble(grid, problem, state["ld_nodes"], rows, trajs, config)
    resolved = 0
    for r in range(1, resolve_rounds + 1):
        bad = db.inconsistent()
        if not bad:
            break
        sub = os.path.join(out_dir, f"resolve_{r}")
        cases = []
        for i in sorted(bad):  # from the best neighbour that is itself in line
            nb = [j for j in grid.neighbours(i) if rows.get(j, {}).get("success") and j in trajs and j not in bad]
            if nb:
                src = min(nb, key=lambda j: rows[j]["objective"])
                cases.append({"index": i, "guess": _guess(trajs[src], problem), "guess_from": src, "attempt": r})
        if not cases:
            break
        sub_manifest = task_manifest(task, [{"index": c["index"]} for c in cases], kind=f"ampi_database_resolve_{r}")
        run_cases(task, cases, sub, sub_manifest, desc=f"re-solve round {r}", **campaign)
        new_rows, new_trajs = _read(sub)
        for i, row in new_rows.items():  # keep a re-solve when it is verified and better
            old = rows.get(i, {})
            if row.get("success") and (not old.get("success") or row["objective"] < old["objective"]):
                rows[i], trajs[i] = row, new_trajs[i]
                resolved += 1
        db = _assemble(grid, problem, state["ld_nodes"], rows, trajs, config)
    db.save(os.path.join(out_dir, DATABASE_FILE))
    left = db.inconsistent()
    report = {"cases": grid.size, "verified": int(db.verified.sum()), "re_solved": resolved,
              "inconsistent": {int(k): v for k, v in left.items()}, "storage_MB": db.storage_bytes / 1e6,
              "wall_s": time.perf_counter() - t0,
              "solve_s": {"mean": float(np.mean([r["wall_s"] for r in rows.values()])) if rows else math.nan,
                          "max": float(np.max([r["wall_s"] for r in rows.values()])) if rows else math.nan}}
    return db, report


def _assemble(grid, problem, ld_nodes, rows, trajs, study: dict) -> TrajectoryDatabase:
    db = TrajectoryDatabase.empty(grid, ld_nodes, problem.state_names, problem.control_names, {"study": study})
    for i, row in rows.items():
        if i in trajs and math.isfinite(row.get("objective", math.nan)):
            X, U = _arrays(trajs[i], problem)
            db.set_case(i, X, U, row["final_time_s"], row["objective"], row["success"])
    return db
