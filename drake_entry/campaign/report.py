"""The campaign report: one document for every method and campaign, Markdown and a
self-contained HTML file, in the form of NASA entry Monte-Carlo practice (Hanson & Beard 2010,
NASA/TP-2010-216447; docs/references.md).

``summary_statistics(rows)`` counts the verdicts and gives the terminal errors' mean, 1-sigma
and percentiles (paper 000 Table 3; paper 003 Table 3 counts inside 25/50/75 km) and the worst
path-limit margins. ``write_report(out_dir)`` reads a campaign directory's streams
(drake_entry.campaign.store) and writes report.md and report.html: verdict, provenance,
dispersions, requirements, outcome, statistics (drake_entry.campaign.statistics), what drives the
misses and failures (drake_entry.campaign.drivers), cost and captioned figures
(drake_entry.campaign.report_figures).
"""
from __future__ import annotations

import base64
import dataclasses as dc
import datetime
import hashlib
import html
import json
import math
import os
import re
import shlex

import numpy as np

from drake_entry.campaign import report_figures as figures
from drake_entry.campaign.drivers import failure_drivers
from drake_entry.campaign.engine import source_commit
from drake_entry.campaign.interactive import INTERACTIVE, write_interactive
from drake_entry.campaign.rows import row_problem
from drake_entry.campaign.sensitivity import pawn_sensitivity
from drake_entry.campaign.statistics import (
    CONFIDENCE,
    COVERAGE,
    SUCCESS_LEVELS,
    describe,
    finite_column,
    order_statistic_bound,
    running_estimates,
    runs_for_bound,
    success_lower_bound,
)
from drake_entry.campaign.store import coverage, read_nominal, read_trajectories
from drake_entry.campaign.success_requirement import success_verdict
from drake_entry.errors import CampaignError, DrakeEntryError
from drake_entry.models.aerodynamics import AERO_REGIMES
from drake_entry.models.dispersions import PERTURBATION_COLUMNS_KM
from drake_entry.models.verdict import BOX_CRITERIA, BOX_MISSED, failure_clauses, margin_breached
from drake_entry.scenario import ERROR_COLUMNS as ERROR_COLUMN_NAMES
from drake_entry.scenario import Scenario, upgrade_scenario_yaml
from drake_entry.typed_yaml import load_yaml_typed

__all__ = ["path_limit_tolerance", "ERROR_COLUMNS", "MARGIN_COLUMNS", "failure_categories", "reached_terminal", "requirement_verdict",
           "summary_statistics", "counts_sentence", "errors_markdown", "flown_scenario", "rows_as_columns",
           "write_report", "write_markdown_report", "PEAK_QUANTITIES", "OTHER_QUANTITIES", "CONTROL_QUANTITIES",
           "DISPERSION_FIELDS", "NAV_UNITS", "DISPERSION_LABELS", "NAV_NAMES", "table_cell", "format_number",
           "drake_entry_version", "MAX_FAILED_LISTED", "figure_list", "write_html", "aim_text"]

# (row column, label, unit) of the terminal errors, in the scenario schema's order
ERROR_COLUMNS = tuple(zip(ERROR_COLUMN_NAMES,
                          ("Δh", "Δθ", "Δφ", "ΔV", "ΔR (range to go)", "cross-range", "distance to target"),
                          ("m", "deg", "deg", "m/s", "m", "m", "m"), strict=True))
MARGIN_COLUMNS = ("margin_heat_flux", "margin_dynamic_pressure", "margin_normal_load", "margin_total_load")


def _flags(rows: dict, col: str, n: int, default) -> np.ndarray:
    """A boolean column (missing column or entry: ``default``, an array or a bool)."""
    v = rows.get(col)
    d = np.broadcast_to(np.asarray(default, bool), (n,))
    return d.copy() if v is None else np.array([d[i] if x is None else bool(x) for i, x in enumerate(v)], bool)


def failure_categories(row: dict) -> list[str]:
    """Why a row is not a success: 'outside the acceptance box' and '<limit> limit breached'
    for each breached path limit its message names (models.verdict.failure_clauses); otherwise
    the first clause of its message (it did not reach, its guidance never engaged, it raised)."""
    missed, breached, first = failure_clauses(str(row.get("message") or ""))
    out = [BOX_MISSED] if missed else []
    out += [f"{name} limit breached" for name in breached]
    return out or [first]


def path_limit_tolerance(scenario) -> float:
    """The scenario's relative path-limit tolerance (terminal.path_limit_tolerance; 0 without one)."""
    return float(getattr(getattr(scenario, "terminal", None), "path_limit_tolerance", 0.0) or 0.0)


def reached_terminal(rows: dict) -> np.ndarray:
    """Samples whose flight reached the terminal interface (E_f, or the terminal altitude of a
    method that stops there: the row's ``reached_terminal``; campaigns written before that
    column: stopped at E_f) with finite terminal errors: the population of the error
    statistics, inside the box or not."""
    n = len(rows["index"])
    stop = rows.get("stop") or [None] * n
    flag = rows.get("reached_terminal") or [None] * n
    reached = [bool(f) if f is not None else (bool(s) and str(s).startswith("reached energy"))
               for f, s in zip(flag, stop)]
    return np.array(reached, bool) & np.isfinite(finite_column(rows, "err_distance_m", n))


def summary_statistics(rows: dict, tolerance: float = 0.0) -> dict:
    """Statistics of a campaign's rows (a column dict, e.g. from Parquet).

    Counts, each separately: samples, successful (the verdict: reached, inside the box and
    within every path limit), reached (terminal interface reached), inside_acceptance_box (among
    the reached), within_limits (among every flight: a flight stopped before its interface that
    breached no limit is within them), failed (not successful) with their reasons
    (``failure_categories``), and the samples inside each box criterion. Terminal-error
    statistics over the reached samples; path-limit margins (every ``margin_*`` column) over
    every sample that flew (a finite margin), a breach counted as the verdict counts it
    (models.verdict.margin_breached with the scenario's path-limit ``tolerance``).
    """
    n = len(rows["index"])
    ok = np.array([bool(v) for v in rows["success"]])
    reached = reached_terminal(rows)
    inside = _flags(rows, "inside_box", n, ok) & reached  # rows before the verdict columns: success
    within = _flags(rows, "within_limits", n, ok)  # every flight: one stopped early held its limits till then
    out = {"samples": n, "successful": int(ok.sum()), "reached": int(reached.sum()),
           "inside_acceptance_box": int(inside.sum()), "within_limits": int(within.sum()),
           "failed": int(n - ok.sum()), "errors": {}, "margins": {}, "inside_box": {}}
    reasons = {}
    keys = list(rows)
    for i in np.flatnonzero(~ok):
        row = {k: rows[k][i] for k in keys}
        for key in failure_categories(row):
            reasons[key] = reasons.get(key, 0) + 1
    out["failure_reasons"] = reasons
    for col, _, _ in ERROR_COLUMNS:
        v = finite_column(rows, col, n)[reached]
        if v.size == 0:
            continue
        out["errors"][col] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0,
                              "p5": float(np.percentile(v, 5)), "p50": float(np.percentile(v, 50)),
                              "p95": float(np.percentile(v, 95)), "max_abs": float(np.abs(v).max())}
    if reached.any():
        d = finite_column(rows, "err_distance_m", n)[reached]
        out["inside_km"] = {str(r): int((d <= r * 1e3).sum()) for r in (2, 25, 50, 75)}
    for col in [c for c in rows if c.startswith("inside_") and c.endswith("_box") and c != "inside_box"]:
        out["inside_box"][col[len("inside_"):-len("_box")]] = int(sum(bool(v) for v in rows[col] if v is not None))
    for col in [c for c in MARGIN_COLUMNS if c in rows] + sorted(c for c in rows if c.startswith("margin_")
                                                                  and c not in MARGIN_COLUMNS):
        m = finite_column(rows, col, n)
        flew = np.isfinite(m)
        if flew.any():
            out["margins"][col] = {"worst": float(m[flew].min()),
                                   "violations": int(margin_breached(m[flew], tolerance).sum()),
                                   "worst_sample": int(np.asarray(rows["index"])[flew][m[flew].argmin()])}
    if "wall_time_s" in rows:
        w = finite_column(rows, "wall_time_s", n)
        out["wall_time_s"] = {"mean": float(np.nanmean(w)), "total": float(np.nansum(w))}
        cost = {k: finite_column(rows, k, n)[reached] for k in ("planning_wall_s", "plans", "derivative_evaluations")}
        if reached.any() and all(np.isfinite(v).all() for v in cost.values()):
            out["cost"] = {"wall_s_per_sample": float(w[reached].mean()),
                           "planning_share": float(cost["planning_wall_s"].sum() / w[reached].sum()),
                           "plans_per_sample": float(cost["plans"].mean()),
                           "derivative_evaluations_per_sample": float(cost["derivative_evaluations"].mean())}
            plants = [p for p in rows.get("plant", []) if isinstance(p, str)]
            if plants:  # which plant realisation flew (systems/native_plant.py), with its count
                out["cost"]["plants"] = {p: plants.count(p) for p in sorted(set(plants))}
    return out


def counts_sentence(stats: dict) -> str:
    """'N successful (reached, inside the box and within every path limit); ...' of a summary."""
    return (f"{stats['successful']} successful (reached, inside the acceptance box and within every path limit); "
            f"{stats['reached']} reached the terminal interface, {stats.get('inside_acceptance_box', '?')} of them "
            f"inside the acceptance box; {stats.get('within_limits', '?')} of {stats['samples']} within every path "
            f"limit (a flight stopped early counts when it breached none); {stats['failed']} not successful")


def errors_markdown(stats: dict, reference=None) -> str:
    """The terminal errors' mean and 1-sigma (paper 000 Table 3 layout), with the scenario's
    ``reference_results`` beside them when it gives any."""
    ref = reference.errors if reference is not None and reference.source else {}
    head = "| variable | this campaign: mean ± 1σ |" + (f" {reference.source} |" if ref else "") + " unit |"
    lines = [head, "|---|---|" + ("---|" if ref else "") + "---|"]
    for col, label, unit in ERROR_COLUMNS:
        if col not in stats["errors"]:
            continue
        s = stats["errors"][col]
        fmt = "{:.4f}" if unit == "deg" else "{:.1f}"
        cells = [label, f"{fmt.format(s['mean'])} ± {fmt.format(s['std'])}"]
        if ref:
            cells.append(f"{ref[col][0]:g} ± {ref[col][1]:g}" if col in ref else "—")
        lines.append("| " + " | ".join(cells + [unit]) + " |")
    return "\n".join(lines)


def flown_scenario(manifest: dict | None):
    """The scenario a campaign flew, from its manifest (None for a manifest without one or of
    another version)."""
    text = (manifest or {}).get("scenario_yaml")
    if not text:
        return None
    try:
        return load_yaml_typed(Scenario, text=upgrade_scenario_yaml(text), where="campaign manifest")
    except DrakeEntryError:  # a manifest of another version: report without what it would give
        return None


def rows_as_columns(records: list) -> dict:
    keys = sorted({k for r in records for k in r if k != "traceback"})
    return {k: [r.get(k) for r in records] for k in keys}


def write_report(out_dir: str, *, title: str | None = None, limits=None, reference=None) -> str:
    """Write report.md, report.html (self-contained: figures inline), summary.json and the PNG
    figures for the campaign in out_dir; return the path of report.md.

    Reads the campaign's streams (samples.jsonl, trajectories.jsonl: the truth, also for a
    killed or running campaign) and the scenario as flown (its manifest). The report: the
    verdict with Clopper-Pearson bounds, provenance, the dispersion table, the requirements
    table, the outcome and the failed samples, statistics of every terminal error, peak, heat
    load, flight time and control-activity figure, what drives the misses and failures, and
    captioned figures. ``limits``: the vehicle's path limits drawn on the figures (default: the
    flown scenario's vehicle); ``reference``: published results put beside the terminal errors
    (default: the flown scenario's ``reference_results``). Raises CampaignError when out_dir
    holds no campaign."""
    cov = coverage(out_dir, row_problem)
    meta = cov["manifest"]
    records = [cov["rows"][k] for k in sorted(cov["rows"])]
    if not records:
        raise CampaignError(f"{out_dir} holds a campaign without any finished sample yet: nothing to report")
    rows = rows_as_columns(records)
    trajs = read_trajectories(out_dir, set(cov["rows"]))
    traj = None
    if trajs:
        traj = {}
        for s in sorted(trajs):
            for k, v in trajs[s].items():
                traj.setdefault(k, []).extend(v)
    scenario = flown_scenario(meta)
    stats = summary_statistics(rows, path_limit_tolerance(scenario))
    if limits is None and scenario is not None:
        limits = _vehicle_limits(scenario)
    if reference is None:
        reference = getattr(scenario, "reference_results", None)
    stats["coverage"] = {"requested": cov["requested"], "done": len(records), "cut_lines": cov["cut"],
                         "invalid_lines": cov["invalid"], "quarantined_lines": cov["quarantined"]}
    stats["success_lower_bound"] = {f"{level:g}": success_lower_bound(stats["successful"], stats["samples"], level)
                                    for level in SUCCESS_LEVELS}
    verdict = requirement_verdict(stats, scenario)
    if verdict is not None:
        stats["success_requirement"] = dc.asdict(verdict) | {"text": verdict.text()}
    reached = reached_terminal(rows)
    quantities = _quantities(rows, reached, scenario)
    stats["distributions"] = {key: describe(values) for key, (_, _, values) in quantities.items()}
    stats["drivers"] = failure_drivers(rows)
    stats["sensitivity"] = pawn_sensitivity(rows)
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(stats, f, indent=2)
    name = title or _name(meta)
    figs = _figures(rows, reached, traj, out_dir, scenario, limits, name, meta)
    figs += [f for f in [_sensitivity_figure(rows, stats, out_dir, name)] if f is not None]
    write_interactive(out_dir, rows, traj, scenario, name, labels=DISPERSION_LABELS)
    note = (f'<p><a href="{INTERACTIVE}">Interactive view</a>: the footprint and the margins linked; selecting '
            "samples shows their trajectories and inputs (self-contained, beside this file).</p>")
    sections = [_header(meta, stats, title, rows), _provenance(meta, stats), _dispersions(scenario),
                _requirements(rows, reached, stats, scenario, verdict), _outcome(rows, stats, traj),
                _distributions(rows, quantities, reached, stats, reference, scenario), _drivers(stats), _sensitivity(stats),
                _cost(stats),
                figure_list(figs)]
    return write_markdown_report(sections, out_dir, title=name, html_note=note)


def write_markdown_report(sections: list, out_dir: str, *, title: str, html_note: str = "") -> str:
    """report.md (the non-empty ``sections``, blank-line separated) and report.html in ``out_dir``
    (``html_note``: HTML put under its title only); returns the path of report.md."""
    md = "\n\n".join(section for section in sections if section) + "\n"
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write(md)
    write_html(md, out_dir, title=title, note=html_note)
    return path


def _path_limits(scenario) -> list:
    """The flown scenario's path limits (models.verdict.PathLimit; [] when the scenario or its
    vehicle file cannot be read here)."""
    if scenario is None:
        return []
    try:
        return scenario.path_limits()
    except DrakeEntryError:
        return []


def _limits_text(scenario) -> str:
    """The path limits of the flown scenario and their tolerance ('' when the scenario or its
    vehicle file cannot be read here)."""
    limits = _path_limits(scenario)
    if not limits:
        return ""
    return (", ".join(f"{lim.name} {lim.bound_text()}" for lim in limits)
            + f"; tolerance {100 * scenario.terminal.path_limit_tolerance:g} % of each limit")


def _mission_limits(scenario) -> list:
    """The guidance spec's mission path limits (PathLimits; [] without a readable scenario)."""
    if scenario is None:
        return []
    try:
        return list(scenario.guidance.path_limits(scenario))
    except DrakeEntryError:
        return []


def _method(rows: dict) -> str:
    names = sorted({str(m) for m in rows.get("method", []) if m})
    return ", ".join(names) or "?"


#: (row column, label, unit, scale from the row's SI) of the non-error quantities of the statistics tables
PEAK_QUANTITIES = (("peak_heat_flux_W_m2", "peak heat flux", "kW/m^2", 1e-3, "heat_flux_max"),
                   ("peak_dynamic_pressure_Pa", "peak dynamic pressure", "kPa", 1e-3, "dynamic_pressure_max"),
                   ("peak_normal_load_g", "peak normal load", "g", 1.0, "normal_load_max"),
                   ("peak_total_load_g", "peak total load", "g", 1.0, "total_load_max"))
OTHER_QUANTITIES = (("heat_load_J_m2", "heat load", "MJ/m^2", 1e-6), ("flight_time_s", "flight time", "s", 1.0))
CONTROL_QUANTITIES = (("bank_reversals", "bank reversals", "-", 1.0), ("bank_travel_deg", "bank travel", "deg", 1.0),
                      ("peak_bank_rate_deg_s", "peak bank rate", "deg/s", 1.0),
                      ("time_at_bank_limit_s", "time at the bank limit", "s", 1.0),
                      ("time_at_bank_rate_limit_s", "time at the bank-rate limit", "s", 1.0))
#: dispersion rows: (spec path, label, unit)
#: dispersion rows: (spec path, label, unit, the value that disperses nothing)
DISPERSION_FIELDS = (("entry.altitude_m", "entry altitude", "m", 0.0),
                     ("entry.longitude_deg", "entry longitude", "deg", 0.0),
                     ("entry.latitude_deg", "entry latitude", "deg", 0.0),
                     ("entry.velocity_m_s", "entry speed", "m/s", 0.0),
                     ("entry.flight_path_deg", "entry flight-path angle", "deg", 0.0),
                     ("entry.heading_deg", "entry heading", "deg", 0.0),
                     ("density_scale", "density factor", "-", 1.0),
                     ("density_wave_amplitude", "density wave amplitude (fraction)", "-", 0.0),
                     ("lift_scale", "lift-coefficient factor", "-", 1.0),
                     ("drag_scale", "drag-coefficient factor", "-", 1.0),
                     ("mass_scale", "mass factor", "-", 1.0))
NAV_UNITS = ("m", "rad", "rad", "m/s", "rad", "rad")
#: row columns of the drawn dispersions (drake_entry.models.dispersions.Draw.columns) in words
DISPERSION_LABELS = {"disp_dh_m": "entry altitude deviation [m]", "disp_dlon_deg": "entry longitude deviation [deg]",
                     "disp_dlat_deg": "entry latitude deviation [deg]", "disp_dV_m_s": "entry speed deviation [m/s]",
                     "disp_dgamma_deg": "entry flight-path deviation [deg]",
                     "disp_dpsi_deg": "entry heading deviation [deg]", "disp_density_scale": "density factor",
                     "disp_density_wave": "density wave amplitude", "disp_lift_scale": "lift-coefficient factor",
                     "disp_drag_scale": "drag-coefficient factor", "disp_mass_scale": "mass factor",
                     **{f"disp_nav_bias_{k}": f"navigation bias, {k}" for k in ("h", "lon", "lat", "V", "gamma", "psi")},
                     **{f"disp_d{c}_{r}": f"{c} error, {r}" for c in ("CL", "CD") for r in AERO_REGIMES},
                     "disp_trim_alpha_deg": "trim angle-of-attack error [deg]",
                     **{f"disp_d{q}_{km}km": f"{name} perturbation at {km} km" for km in PERTURBATION_COLUMNS_KM
                        for q, name in (("rho", "density"), ("T", "temperature"))},
                     **{f"disp_wind_{d}_{km}km": f"wind towards the {d} at {km} km [m/s]" for km in PERTURBATION_COLUMNS_KM
                        for d in ("east", "north")},
                     "disp_ins_dr0_m": "INS position error at entry [m]", "disp_ins_dv0_m_s": "INS velocity error at entry [m/s]",
                     **{f"disp_ins_accel_bias_{a}_m_s2": f"accelerometer bias, {a} axis [m/s²]" for a in "xyz"},
                     **{f"disp_ins_scale_factor_{a}_ppm": f"accelerometer scale factor, {a} axis [ppm]" for a in "xyz"},
                     **{f"disp_ins_gyro_drift_{a}_deg_h": f"gyro drift, {w} [deg/h]" for a, w in
                        (("e", "east"), ("n", "north"), ("u", "up"))}}
NAV_NAMES = ("altitude", "longitude", "latitude", "speed", "flight-path angle", "heading")


def _name(meta: dict) -> str:
    return f"{os.path.basename(str(meta.get('scenario', '?'))).removesuffix('.yaml')} Monte-Carlo campaign"


def _vehicle_limits(scenario):
    try:
        return scenario.make_vehicle().limits
    except DrakeEntryError:
        return None


def _quantities(rows: dict, reached, scenario=None) -> dict:
    """{key: (label, unit, values)} of every quantity of the statistics tables: terminal errors
    against the guidance's aim and (``box_<criterion>_error``, in the box's units) against the
    acceptance box's centre over the reached samples, the rest over every sample that flew
    (finite). With an energy stop, ΔV is labelled as what it is: -g Δh / V, not a second error."""
    n = len(rows["index"])
    out = {}
    energy_stop = scenario is not None and not getattr(scenario.guidance, "stops_at_altitude", True)
    for col, label, unit in ERROR_COLUMNS:
        if col in rows:
            if col == "err_velocity_m_s" and energy_stop:
                label = "ΔV (at the energy stop: -g Δh / V, follows Δh)"
            out[col] = (label, unit, finite_column(rows, col, n)[reached])
    for c in BOX_CRITERIA:
        col = f"box_{c.name}_error"
        if col in rows:
            out[col] = (c.label + ("" if c.centre is None else " − box centre"), c.unit or "-",
                        finite_column(rows, col, n)[reached] / c.si)
    for col, label, unit, scale, *_ in PEAK_QUANTITIES + OTHER_QUANTITIES + CONTROL_QUANTITIES:
        if col in rows:
            out[col] = (label, unit, finite_column(rows, col, n) * scale)
    return out


def table_cell(text) -> str:
    """A Markdown table cell: a '|' in the text is escaped."""
    return str(text).replace("|", "\\|")


def format_number(x, digits: int = 4) -> str:
    if x is None:
        return "—"
    if isinstance(x, float) and not math.isfinite(x):
        return "—"
    return f"{x:.{digits}g}"


def _header(meta: dict, stats: dict, title: str | None, rows: dict) -> str:
    c = stats["coverage"]
    n, k = stats["samples"], stats["successful"]
    lb = stats["success_lower_bound"]
    lines = [f"# {title or _name(meta)}", ""]
    lines.append(f"**{k} of {n} samples successful; the success probability is at least "
                 f"{100 * lb['0.9']:.2f} % at 90 % confidence and {100 * lb['0.95']:.2f} % at 95 % confidence** "
                 "(one-sided Clopper-Pearson bounds on these samples).")
    if "success_requirement" in stats:
        lines += ["", f"**Required success probability {stats['success_requirement']['probability'] * 100:g} % at "
                  f"{stats['success_requirement']['confidence'] * 100:g} % confidence: "
                  f"{stats['success_requirement']['text']}.**"]
    lines += ["", f"Scenario `{meta.get('scenario', '?')}` (guidance method `{_method(rows)}`), seed "
              f"{meta.get('seed', '?')}. "
              f"Covers {c['done']} of {c['requested']} requested samples"
              + (f" (**incomplete**: {c['requested'] - c['done']} not run; re-run the campaign command to finish it)"
                 if c["done"] < c["requested"] else "") + ": " + counts_sentence(stats) + "."]
    damaged = c["cut_lines"] + c["invalid_lines"] + c["quarantined_lines"]
    if damaged:
        lines += ["", f"Stream damage: {c['cut_lines']} cut last line(s) and {c['invalid_lines']} invalid line(s) "
                  f"not counted, {c['quarantined_lines']} line(s) in quarantine.jsonl (their samples ran again)."]
    return "\n".join(lines)


def _provenance(meta: dict, stats: dict) -> str:
    v = meta.get("versions", {})
    sessions = meta.get("sessions") or []
    last = sessions[-1] if sessions else {}
    digest = hashlib.sha256(str(meta.get("scenario_yaml", "")).encode()).hexdigest()
    overrides = meta.get("overrides") or {}
    command = (f"drake-entry campaign {meta.get('scenario', '?')} --runs {meta.get('runs', '?')} "
               f"--seed {meta.get('seed', '?')} --trajectory-step {meta.get('trajectory_step_s', '?')}"
               + "".join(" --set " + shlex.quote(f"{k}={val if isinstance(val, str) else json.dumps(val)}")
                         for k, val in overrides.items()) + " --out DIR")
    unrecorded = "not recorded (an installed package, not a git checkout)"
    commits = list(dict.fromkeys(s.get("git_commit") or unrecorded for s in sessions)) or [unrecorded]
    flown = (f"commit {commits[0]}" if len(commits) == 1 else
             f"commits {', '.join(commits)} (the campaign was resumed at another commit: each run's is below)")
    rows = [("drake_entry", f"{v.get('drake_entry', '?')}, {flown}"),
            ("Drake", f"{v.get('drake', '?')} (its build carries the solvers: Clarabel, SCS, Ipopt, SNOPT)"),
            ("Python, NumPy, SciPy", ", ".join(str(last.get(k, "not recorded")) for k in ("python", "numpy", "scipy"))),
            ("platform", str(last.get("platform", "not recorded"))),
            ("runs of the campaign", "; ".join(f"{s.get('date_utc', '?')}: `{s.get('command', '')}`"
                                               + (f" at commit {str(s.get('git_commit'))[:7]}" if len(commits) > 1 else "")
                                               for s in sessions)
             or "not recorded (a campaign written before the provenance record)"),
            ("scenario", f"`{meta.get('scenario', '?')}`, as flown (overrides applied) sha256 {digest[:16]}…"),
            ("overrides", ", ".join(f"{k} = {val}" for k, val in overrides.items()) or "none"),
            ("seeds", f"master seed {meta.get('seed', '?')}; sample i draws from Drake's RandomGenerator seeded with "
                      f"numpy SeedSequence([{meta.get('seed', '?')}, i]) (each sample re-runs alone)"),
            ("samples", f"{stats['coverage']['done']} done of {stats['coverage']['requested']} requested"),
            ("campaign fingerprint", f"{str(meta.get('fingerprint', '?'))[:16]}…"),
            ("reproduce", f"`{command}`"),
            ("report written", f"{datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')} by "
                               f"drake_entry {drake_entry_version()}"
                               + (f", commit {writer}" if (writer := source_commit()) else ""))]
    return "## Provenance\n\n| item | value |\n|---|---|\n" + "\n".join(f"| {a} | {b} |" for a, b in rows)


def drake_entry_version() -> str:
    import drake_entry

    return drake_entry.__version__


def _fixed_value(d) -> float | None:
    """The value of a plain number or a schema Deterministic; None for a distribution."""
    if isinstance(d, (int, float)):
        return float(d)
    return float(d.value) if type(d).__name__ == "Deterministic" else None


def _distribution_text(d) -> tuple[str, str]:
    """(distribution, bounds or sigma) of a schema scalar or a plain number."""
    name = type(d).__name__
    if _fixed_value(d) is not None:
        return "fixed", f"{_fixed_value(d):g}"
    if name == "Uniform":
        return "uniform", f"[{d.min:g}, {d.max:g}]"
    if name == "Gaussian":
        return "Gaussian", f"mean {d.mean:g}, 1σ {d.stddev:g} (3σ {3 * d.stddev:.4g}: 99.73 %)"
    return name, str(d)


def _regime_rows(a) -> list:
    """Dispersion-table rows of the aerodynamic errors by Mach regime and the trim error."""
    if a is None:
        return []
    edges = [0.0, *a.mach_boundaries, math.inf]
    rows = [f"| C_L and C_D relative errors, {r} (Mach {lo:g} to {hi:g}) | 0 | Gaussian, correlation {rho:g} | "
            f"1σ {sl:g} and {sd:g} | - |"
            for r, lo, hi, sl, sd, rho in zip(AERO_REGIMES, edges, edges[1:], a.lift_sigma, a.drag_sigma, a.correlation)
            if sl or sd]
    if rows:
        rows.append(f"| regime blend width | — | fixed | {a.blend_mach:g} | Mach |")
    if a.trim_alpha_sigma_deg:
        rows.append(f"| trim angle-of-attack error | 0 | Gaussian | 1σ {a.trim_alpha_sigma_deg:g} | deg |")
    return rows


def _profile_text(altitude_km, values) -> str:
    """A profile by altitude in words: 'v at h km, ...'."""
    return ", ".join(f"{v:g} at {h:g} km" for h, v in zip(altitude_km, values))


def _perturbation_rows(p) -> list:
    """Dispersion-table rows of the density and temperature perturbation profiles."""
    if p is None:
        return []
    profile = lambda sigma: _profile_text(p.altitude_km, sigma)  # noqa: E731
    return [f"| density perturbation along the flight | 0 | per-flight part {100 * p.large_scale_fraction:g} % of the "
            f"variance, the rest correlated over {p.vertical_scale_km:g} km of altitude | 1σ {profile(p.density_sigma)} "
            f"| fraction |",
            f"| temperature perturbation along the flight | 0 | the same process, correlation with density "
            f"{p.density_temperature_correlation:g} | 1σ {profile(p.temperature_sigma)} | fraction |"]


def _wind_rows(w) -> list:
    """Dispersion-table rows of the horizontal wind: its mean profile and its perturbation."""
    if w is None:
        return []
    profile = lambda values: _profile_text(w.altitude_km, values)  # noqa: E731
    return [f"| wind towards the east, mean | {profile(w.east_mean_m_s)} | fixed | — | m/s |",
            f"| wind towards the north, mean | {profile(w.north_mean_m_s)} | fixed | — | m/s |",
            f"| wind perturbation, each horizontal component | 0 | per-flight part {100 * w.large_scale_fraction:g} % of "
            f"the variance, the rest correlated over {w.vertical_scale_km:g} km of altitude | 1σ "
            f"{profile(w.sigma_m_s)} | m/s |"]


def _inertial_rows(n) -> list:
    """Dispersion-table rows of the inertial navigation errors."""
    if n is None:
        return []
    rows = []
    if not n.enabled:
        rows.append("| inertial navigation | switched off | — | perfect navigation (the errors drawn, not flown) | — |")
    if n.initial_covariance is not None:
        sd = np.sqrt(np.clip(np.diag(np.asarray(n.initial_covariance, float)), 0.0, None))
        rows.append(f"| INS error at entry, position (east, north, up) | 0 | Gaussian (covariance) | 1σ "
                    f"{sd[0]:g}, {sd[1]:g}, {sd[2]:g} | m |")
        rows.append(f"| INS error at entry, velocity (east, north, up) | 0 | Gaussian (covariance) | 1σ "
                    f"{sd[3]:g}, {sd[4]:g}, {sd[5]:g} | m/s |")
    rows += [f"| accelerometer bias, each axis | 0 | Gaussian | 1σ {n.accelerometer_bias_sigma_m_s2:g} | m/s² |",
             f"| accelerometer scale factor, each axis | 0 | Gaussian | 1σ {n.accelerometer_scale_factor_sigma_ppm:g} "
             f"| ppm |",
             f"| gyro drift, each axis | 0 | Gaussian | 1σ {n.gyro_drift_sigma_deg_h:g} | deg/h |",
             f"| INS gravity feedback (Schuler, vertical channel) | {'on' if n.gravity_feedback else 'off'} | — | — | — |"]
    return rows


def _covariance_rows(covariance) -> list:
    """Dispersion-table rows of an entry delivery covariance: each 1-sigma, then the correlations."""
    if covariance is None:
        return []
    c = np.asarray(covariance, float)
    sd = np.sqrt(np.clip(np.diag(c), 0.0, None))
    names = ("altitude", "longitude", "latitude", "speed", "flight-path angle", "heading")
    units = ("m", "deg", "deg", "m/s", "deg", "deg")
    rows = [f"| entry {n} (delivery covariance) | 0 | Gaussian, correlated | 1σ {s:g} | {u} |"
            for n, s, u in zip(names, sd, units) if s]
    pairs = [f"{names[i]}-{names[j]} {c[i, j] / (sd[i] * sd[j]):+.2f}" for i in range(6) for j in range(i + 1, 6)
             if sd[i] and sd[j] and c[i, j]]
    if pairs:
        rows.append(f"| entry delivery correlations | — | — | {'; '.join(pairs)} | - |")
    return rows


def _dispersions(scenario) -> str:
    if scenario is None:
        return ("## Dispersions\n\nThe flown scenario could not be read from the manifest (a campaign of another "
                "version): see campaign.json.")
    spec, entry = scenario.dispersions, scenario.entry
    nominal = {"entry.altitude_m": f"{entry.altitude_km * 1e3:g} m", "entry.longitude_deg": f"{entry.longitude_deg:g} deg",
               "entry.latitude_deg": f"{entry.latitude_deg:g} deg", "entry.velocity_m_s": f"{entry.velocity_m_s:g} m/s",
               "entry.flight_path_deg": f"{entry.flight_path_deg:g} deg", "entry.heading_deg": f"{entry.heading_deg:g} deg"}
    lines = []
    for path, label, unit, undispersed in DISPERSION_FIELDS:
        holder = spec.entry if path.startswith("entry.") else spec
        value = getattr(holder, path.split(".")[-1])
        if _fixed_value(value) == undispersed:
            continue  # not dispersed: the nominal model
        kind, spread = _distribution_text(value)
        where = nominal.get(path, "1 (the nominal model)" if undispersed == 1.0 else "0")
        delta = " (deviation)" if path.startswith("entry.") else ""
        lines.append(f"| {label}{delta} | {where} | {kind} | {spread} | {unit} |")
        if path == "density_wave_amplitude":
            lines.append(f"| density wave length | — | fixed | {spec.density_wave_length_km:g} | km |")
    bias = spec.nav_bias
    name = type(bias).__name__
    if name == "GaussianVectorX":
        for i, (m, s) in enumerate(zip(bias.mean, bias.stddev)):
            if s:
                lines.append(f"| navigation bias, {NAV_NAMES[i]} | 0 | Gaussian | mean {m:g}, 1σ {s:g} | {NAV_UNITS[i]} |")
    elif name == "UniformVectorX":
        for i, (lo, hi) in enumerate(zip(bias.min, bias.max)):
            if lo or hi:
                lines.append(f"| navigation bias, {NAV_NAMES[i]} | 0 | uniform | [{lo:g}, {hi:g}] | {NAV_UNITS[i]} |")
    for i, s in enumerate(spec.nav_noise_sigma):
        if s:
            lines.append(f"| navigation white noise, {NAV_NAMES[i]} | 0 | Gaussian per step | 1σ {s:g} | "
                         f"{NAV_UNITS[i]} |")
    lines += (_regime_rows(spec.aero_regimes) + _covariance_rows(spec.entry_covariance)
              + _perturbation_rows(spec.atmosphere_perturbations) + _wind_rows(spec.winds)
              + _inertial_rows(spec.inertial_navigation))
    head = "## Dispersions\n\n"
    source = f"Source: {spec.source}." if spec.source else "Source: not stated in the scenario (`dispersions.source`)."
    if not lines:
        return head + "Nothing is dispersed: every sample flies the nominal scenario. " + source
    return (head + source + " Entry values are deviations added to the nominal entry state.\n\n"
            "| parameter | nominal | distribution | bounds or σ | unit |\n|---|---|---|---|---|\n" + "\n".join(lines))


def requirement_verdict(stats: dict, scenario):
    """The SuccessVerdict of the scenario's success requirement on the campaign's counts (None
    when the scenario states none)."""
    req = getattr(scenario, "success_requirement", None)
    if req is None or req.probability is None or not stats["samples"]:
        return None
    return success_verdict(stats["successful"], stats["samples"], req.probability, req.confidence)


def _requirements(rows: dict, reached, stats: dict, scenario, verdict=None) -> str:
    """The requirement table: ``verdict`` (requirement_verdict: the scenario's success
    requirement, None when it states none), every box criterion and path limit."""
    n = len(rows["index"])
    nr = int(reached.sum())
    lines = []
    sources = dict(getattr(scenario.terminal, "requirement_sources", {}) or {}) if scenario is not None else {}
    if verdict is not None:
        source = scenario.success_requirement.source or "the scenario's `success_requirement`"
        lines.append(f"| success probability | {verdict.required} | one-sided Clopper-Pearson lower bound of "
                     f"{verdict.successes} of {verdict.runs} | {100 * verdict.lower:.3f} % | "
                     f"{100 * (verdict.lower - verdict.probability):+.3f} % | {verdict.text()} | "
                     f"{source} |")
    term = scenario.terminal if scenario is not None else None
    lines.append(f"| reach the terminal interface | every sample | count | {nr} of {n} | — | "
                 f"{'PASS' if nr == n else 'FAIL'} | the verdict's |")
    for c in BOX_CRITERIA:
        col, flag = f"box_{c.name}_error", f"inside_{c.name}_box"
        if term is None or getattr(term, c.tolerance, None) is None or flag not in rows:
            continue
        tol = getattr(term, c.tolerance)
        unit = f" {c.unit}" if c.unit else ""
        inside = int(sum(bool(v) for v, r in zip(rows[flag], reached) if r and v is not None))
        e = finite_column(rows, col, n)[reached] / c.si if col in rows else np.array([])
        e = e[np.isfinite(e)]
        worst = float(np.abs(e).max()) if e.size else math.nan
        centre = None if c.centre is None else getattr(term, c.centre)
        threshold = f"≤ {tol:g}{unit}" if centre is None else f"in [{centre - tol:g}, {centre + tol:g}]{unit}"
        statistic = (f"largest value of {nr}" if centre is None else
                     f"largest distance from the centre {centre:g}{unit} of {nr}")
        lines.append(f"| {c.label} | {threshold} | {statistic} | {format_number(worst)}{unit} | "
                     f"{format_number(tol - worst)}{unit} | {'PASS' if inside == nr == n else 'FAIL'} ({inside} of {n} "
                     f"inside) | {table_cell(sources.get(c.name, '—'))} |")
    limits = _path_limits(scenario)
    peaks = {"heat_flux": "peak_heat_flux_W_m2", "dynamic_pressure": "peak_dynamic_pressure_Pa",
             "normal_load": "peak_normal_load_g", "total_load": "peak_total_load_g"}
    tolerance = path_limit_tolerance(scenario)
    for lim in limits:
        m = stats["margins"].get(f"margin_{lim.name}")
        if m is None:
            continue
        flew = int(np.isfinite(finite_column(rows, f"margin_{lim.name}", n)).sum())
        peak = ""
        if lim.name in peaks and peaks[lim.name] in rows:
            worst = float(np.nanmax(finite_column(rows, peaks[lim.name], n))) * lim.scale
            peak = f"{worst:.4g} {lim.unit}"
        else:
            peak = "—"
        ok = m["violations"] == 0
        lines.append(f"| {lim.name} | {table_cell(lim.bound_text())} | worst flown sample of {flew} | {peak} | "
                     f"{100 * m['worst']:.2f} % (sample {m['worst_sample']}) | "
                     f"{'PASS' if ok else 'FAIL'} ({flew - m['violations']} of {flew} held) | "
                     f"{table_cell(sources.get(f'{lim.name}_limit', '—'))} |")
    for requirement, why in (getattr(term, "departures", {}) or {}).items():
        lines.append(f"| {table_cell(requirement)} | not judged | — | — | — | NOT JUDGED | "
                     f"departure: {table_cell(' '.join(str(why).split()))} |")
    note = (f"A limit counts as held up to its value plus {100 * tolerance:g} % of it (the scenario's "
            "`terminal.path_limit_tolerance`), at every log sample and integrator step. PASS means every sample met "
            "the requirement; the statistic and the margin are those of the worst sample (margins relative to the "
            "limit). A bank margin of 0 % means the bank actuator reached the vehicle's bank limit, where it clips: "
            "held, not breached. The source column is the scenario's `terminal.requirement_sources` (— where it "
            "names none); a requirement that departs from its source says so there.")
    verdict = ("A sample succeeds when it reached the terminal interface, ended inside every acceptance criterion "
               "and held every path limit at every log sample and integrator step.")
    limits_text = _limits_text(scenario)
    if limits_text:
        verdict += " Path limits: " + limits_text + "."
    return ("## Requirements\n\n" + verdict + "\n\n| requirement | threshold | statistic | campaign value | margin | "
            "verdict | source |\n|---|---|---|---|---|---|---|\n" + "\n".join(lines) + "\n\n" + note)


def _outcome(rows: dict, stats: dict, traj) -> str:
    lb = stats["success_lower_bound"]
    out = ["## Outcome", "", counts_sentence(stats) + ".", "",
           "| confidence | lower bound on the success probability (one-sided Clopper-Pearson) |", "|---|---|"]
    out += [f"| {100 * float(level):g} % | {100 * value:.2f} % |" for level, value in lb.items()]
    runs_needed = runs_for_bound()
    out += ["", f"With every sample successful, {runs_needed} runs would show 99 % success at 90 % confidence."]
    if stats["failure_reasons"]:
        out += ["", "Samples not successful, by reason:", ""] + [f"- {k}: {v}" for k, v in stats["failure_reasons"].items()]
        failed = [i for i, ok in enumerate(rows["success"]) if not ok]
        out += ["", "| sample | seed | reason |", "|---|---|---|"]
        for i in failed[:MAX_FAILED_LISTED]:
            reason = str(rows.get("message", [""] * len(rows["index"]))[i] or "").replace("|", "/")[:200]
            out.append(f"| {rows['index'][i]} | {rows.get('seed', ['?'] * len(rows['index']))[i]} | {reason} |")
        if len(failed) > MAX_FAILED_LISTED:
            out.append(f"| … | | {len(failed) - MAX_FAILED_LISTED} more in samples.parquet |")
        out += ["", "Each sample re-runs alone and reproduces its row: `drake_entry.campaign.sample.run_sample("
                "ClosedLoopSetup.from_scenario(scenario), master_seed, index)`."]
    if stats.get("inside_km"):
        out += ["", "Samples within a distance of the target: " + ", ".join(
            f"{k} km: {v}" for k, v in stats["inside_km"].items())]
    if traj is None:
        out += ["", "Trajectories were not kept (`--trajectory-step 0`) or none finished: the state envelopes, "
                "constraint histories, drag profiles and groundtracks are omitted."]
    return "\n".join(out)


MAX_FAILED_LISTED = 50


def aim_text(scenario) -> str:
    """Where the guidance aims, as the statistics tables say it: 'the guidance's terminal
    interface: altitude 26.5 km (a stop on altitude)' or '... energy of h_f = 26.5 km, V_f = 727
    m/s (a stop on energy)'; '' when the scenario is unknown or states no interface."""
    if scenario is None:
        return ""
    try:
        h, V, _ = scenario.guidance_terminal_state()
    except (DrakeEntryError, AttributeError, TypeError, ValueError):
        return ""
    g = scenario.guidance
    datum = " geodetic" if scenario.altitude_datum == "ellipsoid" else ""
    if getattr(g, "stops_at_altitude", False):
        return f"altitude {g.terminal_altitude_km:g} km{datum} (the flight stops there), speed {V:.1f} m/s"
    return (f"the energy of h_f = {g.terminal_altitude_km:g} km{datum}, V_f = {V:.1f} m/s (the flight stops there: at "
            "that energy ΔV = -g Δh / V follows Δh)")


def _distributions(rows: dict, quantities: dict, reached, stats: dict, reference, scenario=None) -> str:
    n_reached = int(reached.sum())
    head = ("| quantity | unit | N | min | P0.13 | P1 | P50 | mean | σ | P99 | P99.87 | max | "
            f"Wilks {100 * COVERAGE:g} %/{100 * CONFIDENCE:g} % |")
    sep = "|---|---|---|---|---|---|---|---|---|---|---|---|---|"

    def table(keys):
        lines = [head, sep]
        for key in keys:
            if key not in quantities:
                continue
            label, unit, values = quantities[key]
            d = stats["distributions"][key]
            if d.get("n", 0) == 0:
                continue
            signed = key.startswith(("err_", "box_")) and key not in ("err_distance_m", "box_distance_error")
            bound = order_statistic_bound(np.abs(values) if signed else values)
            cells = [label + (" (bound on the absolute value)" if signed else ""), unit, str(d["n"])]
            cells += [format_number(d.get(k)) for k in ("min", "p0.13", "p1", "p50", "mean", "sigma", "p99", "p99.87", "max")]
            cells.append(format_number(bound) if bound is not None else f"— (needs {runs_for_bound()} runs)")
            lines.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines)

    out = ["## Statistics", "",
           "Percentiles are empirical (linear interpolation between order statistics); P0.13 and P99.87 (the 3σ levels "
           "of a normal distribution, 99.73 % two-sided) are given only when the sample holds a point beyond them "
           "(770 runs or more). σ is the sample standard deviation; mean ± 3σ covers 99.73 % only of a normal "
           f"distribution. The Wilks column is a distribution-free bound: with {runs_for_bound()} runs or more, the "
           f"largest value (or a lower order statistic) exceeds the {100 * COVERAGE:g} % quantile with "
           f"{100 * CONFIDENCE:g} % confidence.", "",
           f"### Terminal errors against the guidance's aim ({n_reached} samples that reached the terminal "
           "interface)", "",
           "The guidance aims at " + (aim_text(scenario) or "its terminal interface") + " over the target; "
           "these errors say how well it hit its aim. The acceptance box judges against its own centre (its table below).",
           "", table([c for c, _, _ in ERROR_COLUMNS])]
    if stats["errors"]:
        out += ["", errors_markdown(stats, reference), "",
                "ΔR is the range to go along the final heading (+ short of the target); the cross-range is reported "
                "separately."]
        note = getattr(reference, "note", "") if reference is not None and reference.source else ""
        if note:
            out += ["", f"Why the figures differ from {reference.source}: {note}"]
    box_keys = [f"box_{c.name}_error" for c in BOX_CRITERIA if f"box_{c.name}_error" in quantities]
    if box_keys:
        out += ["", f"### Terminal errors against the acceptance box's centre ({n_reached} samples that reached the "
                "terminal interface)", "", "What the requirement table judges: each criterion's value less the box's "
                "centre (the distance to the target as it is), in the box's units; a value beyond the criterion's "
                "tolerance is outside the box.", "", table(box_keys)]
    out += ["", "### Peak path quantities, heat load and flight time (every sample that flew)", "",
            table([c for c, *_ in PEAK_QUANTITIES + OTHER_QUANTITIES])]
    if any(c in rows for c, *_ in CONTROL_QUANTITIES):
        out += ["", "### Control activity (the bank actuator's position, every sample that flew)", "",
                table([c for c, *_ in CONTROL_QUANTITIES]), "",
                "Reversals are sign changes of the flown bank between excursions beyond 1 deg; travel is the total "
                "angle turned; the rate is the actuator's (finite differences over the integrator steps); time at a "
                "limit counts intervals whose two ends are at it (rate: within 1 % of the vehicle's bank-rate limit)."]
    return "\n".join(out)


def _drivers(stats_: dict) -> str:
    d = stats_.get("drivers") or {}
    if not d.get("inputs"):
        return ""
    lines = ["## What drives the misses and the failures", "",
             "Every dispersed input against every outcome by Spearman rank correlation ρ over the samples where both "
             "are finite (success counts 1, failure 0; a margin is 1 - peak / limit, so a negative ρ means the input "
             "eats the margin). The inputs with the largest |ρ| in any column are listed. A monotonic association, "
             "not a causal share: with many inputs some ρ are large by chance, so only the bold cells pass the "
             f"Bonferroni level p < {d['level']:.2g} (0.05 over the number of cells).", ""]
    lines += _input_table(d, "+.2f", lambda c: c[1] < d["level"])
    if d.get("failures"):
        level = d.get("input_level", 0.05)
        lines += ["", "### Failed against successful samples", "",
                  "Each input's values in the failed samples against the successful ones: the two-sample "
                  "Kolmogorov-Smirnov test (any difference of distribution, so a failure mode at both tails of an "
                  "input shows where a shift does not), the Mann-Whitney U test (a shift), and the failures counted "
                  f"in the input's {len(d['failures'][0]['failed_by_quintile'])} quantile bins (equal sample counts, "
                  f"lowest first). The three inputs with the smallest KS p-value; bold below the level {level:.2g} "
                  "(0.05 over the inputs).", "",
                  "| input | median failed / successful | KS D | KS p | Mann-Whitney p | failures by quintile |",
                  "|---|---|---|---|---|---|"]
        for f in d["failures"]:
            p = f"{f['ks_p']:.2g}"
            lines.append(f"| {_input_words(f['input'])} | {format_number(f['median_failed'])} / "
                         f"{format_number(f['median_successful'])} | {f['ks']:.2f} | "
                         f"{f'**{p}**' if f['ks_p'] < level else p} | {f['mann_whitney_p']:.2g} | "
                         f"{' · '.join(str(k) for k in f['failed_by_quintile'])} |")
    if d.get("modes"):
        lines += ["", "Failure modes (the failed samples grouped by why they failed; for a group of 3 or more, the "
                      "input that separates it best from the successful samples):", ""]
        for m in d["modes"]:
            text = f"- {m['reason']}: {m['samples']} (samples {', '.join(str(i) for i in m['indices'])}"
            text += ", …)" if m["samples"] > len(m["indices"]) else ")"
            sep = m.get("separating")
            if sep:
                text += (f"; {_input_words(sep['input'])}: median {format_number(sep['median_failed'])} against "
                         f"{format_number(sep['median_successful'])} in the successful samples (KS p = "
                         f"{sep['ks_p']:.2g}; by quintile {' · '.join(str(k) for k in sep['failed_by_quintile'])})")
            lines.append(text)
    return "\n".join(lines)


def _input_words(col: str) -> str:
    return DISPERSION_LABELS.get(col, col.removeprefix("disp_"))


def _input_table(d: dict, number: str, bold) -> list[str]:
    """The header and one row per input of a drivers or sensitivity table ``d`` (its outcomes,
    inputs and cells): each cell's first number in the format ``number``, bold where ``bold(cell)``."""
    outcomes = d["outcomes"]
    lines = ["| input | " + " | ".join(w for _, w in outcomes) + " |", "|---" * (len(outcomes) + 1) + "|"]
    for r in d["inputs"]:
        cells = []
        for col, _ in outcomes:
            c = r["cells"].get(col)
            text = "—" if c is None else format(c[0], number)
            cells.append(f"**{text}**" if c is not None and bold(c) else text)
        lines.append(f"| {_input_words(r['input'])} | " + " | ".join(cells) + " |")
    return lines


#: the unit of each outcome column the sensitivity figures plot (margins: 1 - peak / limit)
OUTCOME_UNITS = {col: unit for col, _, unit in ERROR_COLUMNS}


def _outcome_words(col: str, words: str) -> str:
    return f"{words} [{OUTCOME_UNITS.get(col, '1 - peak / limit')}]"


def _sensitivity(stats_: dict) -> str:
    """The PAWN table (campaign.sensitivity): each leading input's index on each outcome, bold
    above the outcome's noise floor, the floors in the last row."""
    d = stats_.get("sensitivity") or {}
    if not d.get("inputs"):
        return ""
    outcomes = d["outcomes"]
    lines = ["### How much each input shapes each outcome (PAWN)", "",
             f"PAWN index (SALib): the median over {d['slices']} equal-probability slices of the input of the "
             "Kolmogorov-Smirnov distance between the outcome's distribution and its distribution within the slice "
             "(0: the outcome ignores the input; 1: the input alone decides it). Computed from this campaign's "
             f"{d['samples']} samples, no special design; it sees non-monotonic effects that ρ misses. Bold: above "
             f"the outcome's noise floor, the largest index of {d['dummies']} independent dummy inputs analysed "
             "alongside (last row).", ""]
    lines += _input_table(d, ".2f", lambda c: c[1])
    lines.append("| *noise floor (dummies)* | " + " | ".join(
        f"*{d['floors'][col]:.2f}*" if col in d["floors"] else "—" for col, _ in outcomes) + " |")
    return "\n".join(lines)


def _sensitivity_figure(rows: dict, stats_: dict, out_dir: str, title: str, panels: int = 3):
    """report_figures.sensitivity_scatter of the ``panels`` strongest significant (input,
    outcome) pairs of the PAWN table, one per input and one per outcome (an energy stop's speed
    error mirrors its altitude error: a second panel of one input would repeat the first)."""
    d = stats_.get("sensitivity") or {}
    n = len(rows["index"])
    words = dict((c, w) for c, w in d.get("outcomes", []))
    order = {c: k for k, c in enumerate(words)}  # a tie goes to the outcome listed first
    candidates = sorted(((index, r["input"], col) for r in d.get("inputs", [])
                         for col, (index, significant) in r["cells"].items() if significant),
                        key=lambda c: (-c[0], order[c[2]]))
    chosen, used = [], set()
    for index, inp, col in candidates:
        if inp not in used and col not in used and len(chosen) < panels:
            chosen.append((index, inp, col))
            used |= {inp, col}
    failed = np.array([not bool(v) for v in rows["success"]])
    pairs = [(_input_words(inp), finite_column(rows, inp, n), _outcome_words(col, words[col]),
              finite_column(rows, col, n), index, d["floors"][col], failed) for index, inp, col in chosen]
    return figures.sensitivity_scatter(pairs, out_dir, title)


def _cost(stats_: dict) -> str:
    if not stats_.get("cost"):
        return ""
    c = stats_["cost"]
    return (f"## Cost\n\n{c['wall_s_per_sample']:.2f} s of one core per sample, {100 * c['planning_share']:.0f} % of "
            f"it re-planning ({c['plans_per_sample']:.1f} plans), {c['derivative_evaluations_per_sample']:.0f} plant "
            "derivative evaluations" + (" on the " + " and ".join(f"{p} plant ({k} samples)" for p, k in
                                                                  c["plants"].items()) if c.get("plants") else "")
            + ".")


def _figures(rows: dict, reached, traj, out_dir: str, scenario, limits, title: str, meta: dict | None = None) -> list:
    """[(path, caption)] of every figure the campaign supports."""
    n = len(rows["index"])
    figs = []
    if reached.any():
        errors = {f"{label} [{unit}]": finite_column(rows, col, n)[reached] for col, label, unit in ERROR_COLUMNS if col in rows}
        distance = tuple(f"{label} [{unit}]" for col, label, unit in ERROR_COLUMNS if col == "err_distance_m")
        figs.append(figures.error_histograms(errors, out_dir, title, nonnegative=distance))
        radius = getattr(getattr(scenario, "terminal", None), "distance_tolerance_km", None)
        not_successful = np.array([not bool(v) for v in rows["success"]])[reached]
        figs.append(figures.footprint(finite_column(rows, "err_crossrange_m", n)[reached] / 1e3,
                                      finite_column(rows, "err_range_m", n)[reached] / 1e3, out_dir, title,
                                      radius_km=radius, failed=not_successful))
    peaks = {f"{label} [{unit}]": (finite_column(rows, col, n) * scale,
                                   getattr(limits, lim) * scale if limits is not None else None)
             for col, label, unit, scale, lim in PEAK_QUANTITIES if col in rows}
    figs.append(figures.peak_histograms(peaks, out_dir, title))
    figs.append(_margin_figure(rows, out_dir, scenario, title))
    if traj is not None:
        figs.append(figures.envelopes(traj, out_dir, title, nominal=read_nominal(out_dir)))
        failed = [i for i, ok in zip(rows["index"], rows["success"]) if not ok]
        figs.append(figures.path_quantities(traj, out_dir, title, limits, mission_limits=_mission_limits(scenario),
                                            failed=failed))
        figs.append(figures.drag_profiles(traj, out_dir, title, failed=failed))
        target = ((scenario.target.longitude_deg, scenario.target.latitude_deg) if scenario is not None else None)
        figs.append(figures.ground_tracks(traj, out_dir, title, target=target))
        step = float((meta or {}).get("trajectory_step_s") or 10.0)
        figs.append(figures.bank_histories(traj, out_dir, title, detailed=_detailed_samples(traj, step)))
    figs.append(_convergence_figure(rows, out_dir, scenario, title))
    return [f for f in figs if f is not None]


def _margin_figure(rows: dict, out_dir: str, scenario, title: str):
    """figures.margin_histograms of every margin_* column of the rows, each named with its
    limit's bound (the scenario's path limits; the column's name alone without a scenario)."""
    n = len(rows["index"])
    texts = {lim.name: lim.bound_text() for lim in _path_limits(scenario)}
    bad = np.array([not bool(v) for v in rows["success"]])
    margins = {c.removeprefix("margin_"): (finite_column(rows, c, n), bad, texts.get(c.removeprefix("margin_"), ""))
               for c in sorted(c for c in rows if c.startswith("margin_"))}
    return figures.margin_histograms(margins, out_dir, title, samples=rows["index"],
                                     tolerance=path_limit_tolerance(scenario))


def _convergence_figure(rows: dict, out_dir: str, scenario, title: str):
    """figures.convergence of the campaign's rows (the miss distance in km, the path-limit margins)."""
    n = len(rows["index"])
    quantities = {}
    miss = "miss distance [km]" if "err_distance_m" in rows else None
    if miss:
        quantities[miss] = finite_column(rows, "err_distance_m", n) / 1e3
    margins = tuple(c for c in MARGIN_COLUMNS if c in rows and np.isfinite(finite_column(rows, c, n)).any())
    quantities.update({c: finite_column(rows, c, n) for c in margins})
    est = running_estimates([bool(v) for v in rows["success"]], quantities)
    req = getattr(scenario, "success_requirement", None)
    terminal = getattr(scenario, "terminal", None)
    return figures.convergence(est, out_dir, title, miss=miss, tolerance=getattr(terminal, "distance_tolerance_km",
                                                                                  None),
                               margins=margins, required=None if req is None else req.probability)


def _detailed_samples(traj: dict, step_s: float) -> list:
    """Samples stored finer than half the campaign's storage step ``step_s`` [s] (the first few
    of a campaign, at the detailed step or the scenario's log period: campaign.sample)."""
    sample, t = np.asarray(traj["sample"]), np.asarray(traj["time_s"], float)
    out = []
    for s in np.unique(sample):
        ts = t[sample == s]
        if ts.size > 3 and np.median(np.diff(ts)) < 0.5 * step_s:
            out.append(int(s))
    return out[:5]


def figure_list(figs: list) -> str:
    out = ["## Figures"]
    for k, (path, caption) in enumerate(figs, 1):
        name = os.path.basename(path)
        out += ["", f"![Figure {k}: {name}]({name})", "", f"*Figure {k}. {caption}*"]
    return "\n".join(out)


def write_html(markdown_text: str, out_dir: str, *, title: str, note: str = "") -> str:
    """report.html: the Markdown rendered (tables), every figure inline as a data URI; ``note``
    (HTML) under the first heading."""
    import markdown

    body = markdown.markdown(markdown_text, extensions=["tables"])
    if note:
        body = body.replace("</h1>", "</h1>\n" + note, 1)

    def inline(match):
        src = match.group(1)
        path = os.path.join(out_dir, src)
        if not os.path.isfile(path):
            return match.group(0)
        with open(path, "rb") as f:
            data = base64.b64encode(f.read()).decode()
        return f'src="data:image/png;base64,{data}"'

    body = re.sub(r'src="([^"]+\.png)"', inline, body)
    css = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.4}"
           "table{border-collapse:collapse;margin:1em 0;font-size:0.9em}td,th{border:1px solid #bbb;padding:3px 6px}"
           "th{background:#eee}img{max-width:100%}em{color:#333}")
    html_text = (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{html.escape(title)}</title>"
                 f"<style>{css}</style></head><body>\n{body}\n</body></html>\n")
    path = os.path.join(out_dir, "report.html")
    with open(path, "w") as f:
        f.write(html_text)
    return path
