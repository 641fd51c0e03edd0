"""Paper 003 Sec. V: how close the database references are to the optimal trajectory of the
entry state actually met, and what they cost, through the campaign engine.

For each of ``cases`` entry states drawn like the Monte-Carlo campaign's (Gaussian offsets,
sigma = the grid step / 3: eq. 5's ranges as 3 sigma), one case

1. synthesises the AMPI reference (Algorithms 1-2 and eq. 11) and takes the NTT one (the
   nearest entry), timing each;
2. solves the entry's own optimal-control problem (the database's problem and NLP settings,
   warm-started from the AMPI reference, verified by planning.nlp), timing it: the "OCP";
3. compares each reference with the OCP at the same normalised times (eq. 13's max_k over
   N_HD + 1 equally spaced points): max |error| per state and the t_f error;
4. flies each reference's bank open loop from the true entry state with the Drake
   Simulator (nlp.propagate with the plan verifier, diagrams.verification) and measures the
   miss from the target.

``summarise`` gives eq. 13's mean and standard deviation of the per-case maximum errors
(absolute, and relative for h and V as in Fig. 5), the open-loop misses and the CPU times
(Fig. 6). ``reconstruction_error`` measures a stored case's LD->HD reconstruction against the
flight of its own controls.

    rows = accuracy_study(out_dir, AccuracyStudy(cases=100))
    print(format_summary(summarise(rows)))
"""
from __future__ import annotations

import dataclasses as dc
import functools
import math
import time
from types import SimpleNamespace

import numpy as np

from drake_entry.campaign.backends import Task
from drake_entry.campaign.engine import run_cases, task_manifest
from drake_entry.campaign.store import read_rows
from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.database import TrajectoryDatabase
from drake_entry.guidance.ampi.database_study import offset_problem
from drake_entry.guidance.ampi.database_study import setup_worker as database_worker
from drake_entry.guidance.ampi.spec import MODES, database_path
from drake_entry.models.geodesy import central_angle
from drake_entry.planning import nlp
from drake_entry.planning.pseudospectral import LGL

__all__ = ["COMPARED", "UNITS", "AccuracyStudy", "entry_offsets", "setup_worker", "flown_controls", "fly_ld",
           "fly_reference", "reference_errors", "accuracy_case", "accuracy_study", "summarise", "format_summary",
           "reconstruction_error"]

#: the states compared (eq. 13 shows h, lon, lat, V and t_f; gamma, psi and the bank too)
COMPARED = ("h", "lon", "lat", "V", "gamma", "psi", "sigma")
#: display units: factor from SI / rad and name
UNITS = {"h": (1.0, "m"), "V": (1.0, "m/s")}


@dc.dataclass(frozen=True)
class AccuracyStudy:
    """Attributes: database (packaged name or .npz path); cases; seed (of the entry
    offsets); hd_points (eq. 11's N_HD + 1: the comparison points)."""

    database: str = "shefex3"
    cases: int = 100
    seed: int = 0
    hd_points: int = 601

    def config(self) -> dict:
        if not 1 <= self.cases <= 100000:
            raise ScenarioError(f"cases = {self.cases}: allowed 1..100000")
        if not 2 <= self.hd_points <= 100000:
            raise ScenarioError(f"hd_points = {self.hd_points}: allowed 2..100000")
        return {**dc.asdict(self), "database": database_path(self.database)}


def entry_offsets(db: TrajectoryDatabase, cases: int, seed: int) -> np.ndarray:
    """(cases, d) Gaussian entry offsets, sigma = each grid dimension's step / 3."""
    rng = np.random.default_rng(seed)
    sigma = np.array([(lv[-1] - lv[0]) / (len(lv) - 1) / 3.0 for lv in db.grid.levels])
    return rng.normal(size=(cases, sigma.size)) * sigma


def setup_worker(config: dict) -> dict:
    db = TrajectoryDatabase.load(config["database"])
    study = db.provenance.get("study")
    if not study:
        raise ScenarioError(f"database {config['database']} does not record its study (provenance.study)")
    return {**database_worker(study), "database": db, "hd_points": int(config["hd_points"])}


def flown_controls(problem, syn, n_ld: int):
    """The control function that flies a Synthesis at the LD nodes: with controls 'bank_rate'
    the derivative of the bank's LD polynomial (so the plant's bank is that polynomial; the
    stored rate itself is near bang-bang and its LD polynomial is not what the bank did:
    flying it drifts 66 km on the SHEFEX-3 nominal), otherwise the controls' LD polynomial."""
    lgl = LGL(n_ld, 0.0, syn.final_time)
    if problem.controls == "bank_rate":
        nodal = (lgl.D1 @ syn.states[:, problem.state_names.index("sigma")])[:, None]
    else:
        nodal = syn.controls

    def controls(t):
        return lgl.interpolation(np.clip(np.asarray(t, float), 0.0, syn.final_time)) @ nodal
    return controls


def fly_ld(problem, syn, n_ld: int, x0, *, accuracy: float, samples_per_interval: int, log_points: int):
    """nlp.propagate of a Synthesis at the LD nodes (``flown_controls``) from ``x0`` by the
    Drake verifier at ``accuracy`` with ``log_points`` logged: the PropagationCheck."""
    flown = SimpleNamespace(time=syn.time, final_time=syn.final_time, transcription="lgl", controls=syn.controls,
                            states=np.vstack([x0, syn.states[-1]]),
                            control_function=lambda: flown_controls(problem, syn, n_ld))
    return nlp.propagate(problem, flown, functools.partial(fly_controls, accuracy=accuracy, log_points=log_points),
                         samples_per_interval=samples_per_interval)


def fly_reference(problem, syn, n_ld: int, x0) -> dict:
    """Fly a Synthesis at the LD nodes open loop (``flown_controls``) from the entry state
    ``x0`` (the reference's own initial bank and clock): ``reference_errors`` of that flight."""
    return reference_errors(problem, syn, fly_ld(problem, syn, n_ld, np.array(x0, float), accuracy=1e-9,
                                                 samples_per_interval=16, log_points=200))


def reference_errors(problem, syn, check) -> dict:
    """A flight ``check`` (PropagationCheck) of a Synthesis: miss from the problem's target [m]
    and the final altitude [m] and speed [m/s] errors from the reference's ({'failed': why}
    when the flight stopped early)."""
    if "failed" in check.terminal_error:
        return {"failed": check.terminal_error["failed"]}
    xf = check.states[-1]
    names = problem.state_names
    lon, lat = problem.final["lon"], problem.final["lat"]
    miss = central_angle(xf[names.index("lon")], xf[names.index("lat")], lon, lat) * problem.planet.reference_radius
    return {"miss_m": float(miss), "altitude_m": float(xf[0] - syn.states[-1, 0]),
            "velocity_m_s": float(xf[names.index("V")] - syn.states[-1, names.index("V")])}


def accuracy_case(state: dict, case: dict):
    """One entry state: (row, None) (module docstring, steps 1-4)."""
    db, problem, s = state["database"], state["problem"], state["settings"]
    offsets = np.asarray(case["offsets"], float)
    row = {"index": case["index"], "success": False,
           **{f"offset_{n}": float(v) for n, v in zip(db.grid.names, offsets)}}
    refs = {}
    for mode in MODES:
        t0 = time.perf_counter()
        syn = db.reference(mode, offsets, state["hd_points"])
        row[f"{mode}_synthesis_s"] = time.perf_counter() - t0
        row[f"{mode}_extrapolated"] = int(syn.extrapolated.sum())
        refs[mode] = syn
    at_ld = {mode: db.reference(mode, offsets) for mode in MODES}  # the same references at the LD nodes
    p = offset_problem(problem, dict(zip(db.grid.names, offsets)))
    ld = at_ld["ampi"]
    t0 = time.perf_counter()
    r = nlp.solve(p, guess=(ld.time, ld.states, ld.controls), verifier=fly_controls, **s)
    row.update(ocp_s=time.perf_counter() - t0, ocp_objective=float(r.objective), ocp_final_time_s=float(r.final_time),
               message=r.message[:300])
    if not r.success:
        return row, None
    names = problem.state_names
    for mode, syn in refs.items():
        truth = r.state_function()(syn.time / syn.final_time * r.final_time)
        for n in COMPARED:
            k = names.index(n)
            err = syn.states[:, k] - truth[:, k]
            row[f"{mode}_{n}_max"] = float(np.max(np.abs(err)))
            if n in ("h", "V"):
                row[f"{mode}_{n}_rel_max"] = float(np.max(np.abs(err) / np.abs(truth[:, k])))
        row[f"{mode}_final_time_s"] = float(syn.final_time - r.final_time)
        x0 = [p.initial[n] for n in names[:6]] + [syn.states[0, 6], 0.0]
        flown = fly_reference(p, at_ld[mode], db.n_ld, x0)
        if "failed" in flown:
            row[f"{mode}_open_loop_failed"] = flown["failed"]
            row[f"{mode}_open_loop_miss_m"] = math.nan
        else:
            row[f"{mode}_open_loop_miss_m"] = flown["miss_m"]
    row["success"] = True
    return row, None


def accuracy_study(out_dir: str, study: AccuracyStudy | None = None, *, backend: str = "processes",
                   workers: int | None = None, progress: bool = True) -> list:
    """Run (or resume) the study into ``out_dir``; returns the rows in case order."""
    study = study or AccuracyStudy()
    config = study.config()
    db = TrajectoryDatabase.load(config["database"])
    offsets = entry_offsets(db, study.cases, study.seed)
    task = Task("drake_entry.guidance.ampi.accuracy_study:setup_worker", "drake_entry.guidance.ampi.accuracy_study:accuracy_case",
                config)
    cases = [{"index": i, "offsets": o.tolist()} for i, o in enumerate(offsets)]
    run_cases(task, cases, out_dir, task_manifest(task, cases, kind="ampi_accuracy"), backend=backend, workers=workers,
              progress=progress, desc="AMPI accuracy")
    rows, _ = read_rows(out_dir)
    return [rows[i] for i in sorted(rows)]


def _stats(values) -> dict:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], float)
    if v.size == 0:
        return {"n": 0, "mean": math.nan, "std": math.nan, "max": math.nan}
    return {"n": int(v.size), "mean": float(v.mean()), "std": float(v.std()), "max": float(v.max())}


def summarise(rows: list) -> dict:
    """Eq. 13 per mode and state (mean, std, max of the per-case max errors; SI / rad), t_f
    error, open-loop miss, CPU times; counts of cases solved and failed (with reasons)."""
    ok = [r for r in rows if r.get("success")]
    out = {"cases": len(rows), "verified": len(ok),
           "failed": {int(r["index"]): r.get("message", r.get("error", "")) for r in rows if not r.get("success")},
           "ocp_s": _stats(r.get("ocp_s") for r in rows if "ocp_s" in r)}
    for mode in MODES:
        m = {n: _stats(r[f"{mode}_{n}_max"] for r in ok) for n in COMPARED}
        m.update({f"{n}_rel": _stats(r[f"{mode}_{n}_rel_max"] for r in ok) for n in ("h", "V")})
        m["final_time_s"] = _stats(r[f"{mode}_final_time_s"] for r in ok)
        m["final_time_abs_s"] = _stats(abs(r[f"{mode}_final_time_s"]) for r in ok)
        m["open_loop_miss_m"] = _stats(r[f"{mode}_open_loop_miss_m"] for r in ok)
        m["synthesis_s"] = _stats(r[f"{mode}_synthesis_s"] for r in rows if f"{mode}_synthesis_s" in r)
        m["extrapolated_cases"] = sum(1 for r in rows if r.get(f"{mode}_extrapolated", 0) > 0)
        out[mode] = m
    return out


def format_summary(summary: dict) -> str:
    """The summary as a table (eq. 13 form, Fig. 5 and 6 quantities)."""
    lines = [f"{summary['verified']} of {summary['cases']} OCPs verified "
             f"(solve {summary['ocp_s']['mean']:.2f} s mean, {summary['ocp_s']['max']:.2f} s max)",
             f"{'max error per case':>22s} | {'AMPI mean':>10s} {'std':>9s} {'max':>9s} | "
             f"{'NTT mean':>10s} {'std':>9s} {'max':>9s}"]

    def line(label, key, factor=1.0):
        a, n = summary["ampi"][key], summary["ntt"][key]
        lines.append(f"{label:>22s} | {a['mean'] * factor:10.4g} {a['std'] * factor:9.3g} {a['max'] * factor:9.3g} | "
                     f"{n['mean'] * factor:10.4g} {n['std'] * factor:9.3g} {n['max'] * factor:9.3g}")
    for n in COMPARED:
        factor, unit = UNITS.get(n, (math.degrees(1.0), "deg"))
        line(f"{n} [{unit}]", n, factor)
    line("h relative [%]", "h_rel", 100.0)
    line("V relative [%]", "V_rel", 100.0)
    line("t_f signed [s]", "final_time_s")
    line("|t_f| [s]", "final_time_abs_s")
    line("open-loop miss [km]", "open_loop_miss_m", 1e-3)
    line("synthesis [ms]", "synthesis_s", 1e3)
    lines.append(f"extrapolated: AMPI {summary['ampi']['extrapolated_cases']} cases, "
                 f"NTT {summary['ntt']['extrapolated_cases']}")
    return "\n".join(lines)


def reconstruction_error(db: TrajectoryDatabase, index: int, problem, hd_points: int = 601) -> dict:
    """Case ``index``'s LD->HD reconstruction (eq. 11) against the Drake flight of its own
    controls from its stored entry state: max |error| per state over the HD points (SI /
    rad) and the final position difference [m]."""
    ld = db.entry(index)
    hd = db.entry(index, hd_points)
    check = fly_ld(problem, ld, db.n_ld, ld.states[0], accuracy=1e-10, samples_per_interval=32,
                    log_points=4 * (hd_points - 1))  # the log times include the HD times
    if "failed" in check.terminal_error:
        raise ScenarioError(f"case {index}: {check.terminal_error['failed']}")
    flown = np.array([np.interp(hd.time, check.time, c) for c in check.states.T]).T
    names = problem.state_names
    out = {n: float(np.max(np.abs(hd.states[:, names.index(n)] - flown[:, names.index(n)]))) for n in COMPARED}
    out["position_m"] = float(check.terminal_error["position_m"])
    return out
