"""Campaign reports: Table-3-style statistics, margins and plots, written as Markdown + PNG.

``summary_statistics(rows)`` gives mean, 1-sigma and percentiles of the terminal errors
(paper 000 Table 3; paper 003 Table 3 counts inside 25/50/75 km) and the worst
path-constraint margins. ``write_report(out_dir)`` reads a campaign directory's streams
(drake_entry.campaign.store) and writes report.md with its figures and what it covers.
"""
from __future__ import annotations

import json
import os

import numpy as np

from drake_entry.campaign import plots  # sets the Agg backend before pyplot is imported
from drake_entry.campaign.plots import plt
from drake_entry.campaign.store import coverage, read_trajectories
from drake_entry.errors import CampaignError, DrakeEntryError, load_yaml_typed
from drake_entry.scenario import ERROR_COLUMNS as ERROR_COLUMN_NAMES
from drake_entry.scenario import Scenario

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
    for each breached path limit (the row's ``violations``) when that is why; otherwise the
    first clause of its message (it did not reach, its guidance never engaged, it raised)."""
    message = str(row.get("message") or "")
    inside, within = row.get("inside_box"), row.get("within_limits")
    if inside is None or within is None or not message.startswith(("outside the acceptance box",
                                                                    "path limits breached")):
        return [message.split(":")[0][:80]]  # it did not reach, or its guidance never engaged, ...
    out = [] if inside else ["outside the acceptance box"]
    out += [f"{part.split()[0]} limit breached" for part in str(row.get("violations") or "").split("; ") if part]
    return out or [message.split(":")[0][:80]]


def _finite(rows: dict, col: str, n: int) -> np.ndarray:
    """A column as floats (missing column or entry = nan)."""
    v = rows.get(col)
    return np.full(n, np.nan) if v is None else np.array([np.nan if x is None else x for x in v], float)


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
    return np.array(reached, bool) & np.isfinite(_finite(rows, "err_distance_m", n))


def summary_statistics(rows: dict) -> dict:
    """Statistics of a campaign's rows (a column dict, e.g. from Parquet).

    Counts, each separately: samples, successful (the verdict: reached, inside the box and
    within every path limit), reached (terminal interface reached), inside_acceptance_box and
    within_limits (among the reached), failed (not successful) with their reasons
    (``failure_categories``), and the samples inside each box criterion. Terminal-error
    statistics over the reached samples; path-limit margins (every ``margin_*`` column) over
    every sample that flew (a finite margin).
    """
    n = len(rows["index"])
    ok = np.array([bool(v) for v in rows["success"]])
    reached = reached_terminal(rows)
    inside = _flags(rows, "inside_box", n, ok) & reached  # rows before the verdict columns: success
    within = _flags(rows, "within_limits", n, ok) & reached
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
        v = _finite(rows, col, n)[reached]
        if v.size == 0:
            continue
        out["errors"][col] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0,
                              "p5": float(np.percentile(v, 5)), "p50": float(np.percentile(v, 50)),
                              "p95": float(np.percentile(v, 95)), "max_abs": float(np.abs(v).max())}
    if reached.any():
        d = _finite(rows, "err_distance_m", n)[reached]
        out["inside_km"] = {str(r): int((d <= r * 1e3).sum()) for r in (2, 25, 50, 75)}
    for col in [c for c in rows if c.startswith("inside_") and c.endswith("_box") and c != "inside_box"]:
        out["inside_box"][col[len("inside_"):-len("_box")]] = int(sum(bool(v) for v in rows[col] if v is not None))
    for col in [c for c in MARGIN_COLUMNS if c in rows] + sorted(c for c in rows if c.startswith("margin_")
                                                                  and c not in MARGIN_COLUMNS):
        m = _finite(rows, col, n)
        flew = np.isfinite(m)
        if flew.any():
            out["margins"][col] = {"worst": float(m[flew].min()), "violations": int((m[flew] < 0).sum()),
                                   "worst_sample": int(np.asarray(rows["index"])[flew][m[flew].argmin()])}
    if "wall_time_s" in rows:
        w = _finite(rows, "wall_time_s", n)
        out["wall_time_s"] = {"mean": float(np.nanmean(w)), "total": float(np.nansum(w))}
        cost = {k: _finite(rows, k, n)[reached] for k in ("planning_wall_s", "plans", "derivative_evaluations")}
        if reached.any() and all(np.isfinite(v).all() for v in cost.values()):
            out["cost"] = {"wall_s_per_sample": float(w[reached].mean()),
                           "planning_share": float(cost["planning_wall_s"].sum() / w[reached].sum()),
                           "plans_per_sample": float(cost["plans"].mean()),
                           "derivative_evaluations_per_sample": float(cost["derivative_evaluations"].mean())}
    return out


def counts_sentence(stats: dict) -> str:
    """'N successful (reached, inside the box and within every path limit); ...' of a summary."""
    return (f"{stats['successful']} successful (reached, inside the acceptance box and within every path limit); "
            f"{stats['reached']} reached the terminal interface, {stats.get('inside_acceptance_box', '?')} of them "
            f"inside the acceptance box and {stats.get('within_limits', '?')} within every path limit; "
            f"{stats['failed']} not successful")


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
        return load_yaml_typed(Scenario, text=text, where="campaign manifest")
    except DrakeEntryError:  # a manifest of another version: report without what it would give
        return None


def _columns(records: list) -> dict:
    keys = sorted({k for r in records for k in r if k != "traceback"})
    return {k: [r.get(k) for r in records] for k in keys}


def write_report(out_dir: str, *, title: str | None = None, limits=None, reference=None) -> str:
    """Write report.md, summary.json and PNG figures for the campaign in out_dir.

    Reads the campaign's streams (samples.jsonl, trajectories.jsonl: the truth, also for a
    killed or running campaign) and says what the report covers: samples requested and
    done, lines cut or quarantined. ``limits``: the vehicle's path limits drawn on the figures;
    ``reference``: the scenario's reference_results put beside the terminal errors (default:
    the flown scenario's, from the manifest). Raises CampaignError when out_dir holds no
    campaign."""
    cov = coverage(out_dir)
    meta = cov["manifest"]
    records = [cov["rows"][k] for k in sorted(cov["rows"])]
    if not records:
        raise CampaignError(f"{out_dir} holds a campaign without any finished sample yet: nothing to report")
    rows = _columns(records)
    trajs = read_trajectories(out_dir, set(cov["rows"]))
    traj = None
    if trajs:
        traj = {}
        for s in sorted(trajs):
            for k, v in trajs[s].items():
                traj.setdefault(k, []).extend(v)
    stats = summary_statistics(rows)
    scenario = flown_scenario(meta)
    stats["coverage"] = {"requested": cov["requested"], "done": len(records), "cut_lines": cov["cut"],
                         "invalid_lines": cov["invalid"], "quarantined_lines": cov["quarantined"]}
    with open(os.path.join(out_dir, "summary.json"), "w") as f:
        json.dump(stats, f, indent=2)
    figs = []
    reached = reached_terminal(rows)
    if reached.any():
        figs += _terminal_figures(rows, reached, out_dir)
    if traj is not None:
        figs += _trajectory_figures(traj, out_dir, limits)

    c = stats["coverage"]
    md = [f"# {title or 'Monte-Carlo campaign'}", "",
          f"Scenario `{meta.get('scenario', '?')}` (method `{_method(rows)}`), seed {meta.get('seed', '?')}, "
          f"dispersion {meta.get('dispersion', '?')}, overrides {meta.get('overrides', {})}.", "",
          f"Covers {c['done']} of {c['requested']} requested samples"
          + (f" (**incomplete**: {c['requested'] - c['done']} not run; re-run the campaign command to finish it)"
             if c["done"] < c["requested"] else "") + ": "
          + counts_sentence(stats) + "."]
    limits_text = _limits_text(scenario)
    if limits_text:
        md += ["", "Verdict: a sample succeeds when it reached the terminal interface, ended inside every "
               "acceptance criterion and held every path limit at every log sample and integrator step. "
               "Path limits: " + limits_text + "."]
    if stats["inside_box"]:
        md += ["", "Acceptance box (scenario `terminal` tolerances), samples inside each criterion: " + ", ".join(
            f"{k} {v}" for k, v in stats["inside_box"].items()) + "."]
    damaged = c["cut_lines"] + c["invalid_lines"] + c["quarantined_lines"]
    if damaged:
        md += ["", f"Stream damage: {c['cut_lines']} cut last line(s) and {c['invalid_lines']} invalid line(s) "
               f"not counted, {c['quarantined_lines']} line(s) in quarantine.jsonl (their samples ran again)."]
    md += [""]
    if stats["errors"]:
        md += ["## Terminal errors (samples that reached the terminal interface)", "",
               errors_markdown(stats, reference if reference is not None
                               else getattr(scenario, "reference_results", None)), "",
               "ΔR is the range to go along the final heading (+ short of the target); the cross-range "
               "is reported separately.", ""]
    if stats.get("inside_km"):
        md += ["Samples within a distance of the target: " + ", ".join(
            f"{k} km: {v}" for k, v in stats["inside_km"].items()), ""]
    if stats["margins"]:
        md += ["## Path-constraint margins (worst over all runs; negative = violated)", "",
               "| constraint | worst margin | violations | worst sample |", "|---|---|---|---|"]
        for col, m in stats["margins"].items():
            md.append(f"| {col.replace('margin_', '')} | {100 * m['worst']:.2f} % | {m['violations']} | "
                      f"{m['worst_sample']} |")
        if stats["margins"].get("margin_bank", {}).get("worst") == 0.0:
            md += ["", "A bank margin of 0 % means the bank actuator reached the vehicle's bank limit, where it "
                   "clips: held, not breached."]
    if stats.get("cost"):
        c = stats["cost"]
        md += ["", f"Cost: {c['wall_s_per_sample']:.2f} s of one core per sample, {100 * c['planning_share']:.0f} % of "
               f"it re-planning ({c['plans_per_sample']:.1f} plans), {c['derivative_evaluations_per_sample']:.0f} "
               "plant derivative evaluations."]
    if stats["failure_reasons"]:
        md += ["", "## Samples not successful, by reason", ""] + [
            f"- {k}: {v}" for k, v in stats["failure_reasons"].items()]
    if traj is None:
        md += ["", "Trajectories were not kept (`--trajectory-step 0`) or none finished: the state envelopes, "
               "constraint histories, drag profiles and groundtracks are omitted."]
    md += ["", "## Figures", ""] + [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in figs]
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write("\n".join(md) + "\n")
    return path


def _limits_text(scenario) -> str:
    """The path limits of the flown scenario and their tolerance ('' when the scenario or its
    vehicle file cannot be read here)."""
    if scenario is None:
        return ""
    try:
        limits = scenario.path_limits()
    except DrakeEntryError:
        return ""
    return (", ".join(f"{lim.name} {lim.bound_text()}" for lim in limits)
            + f"; tolerance {100 * scenario.terminal.path_limit_tolerance:g} % of each limit")


def _method(rows: dict) -> str:
    names = sorted({str(m) for m in rows.get("method", []) if m})
    return ", ".join(names) or "?"


def _terminal_figures(rows: dict, reached, out_dir: str) -> list:
    figs = []
    n = len(rows["index"])
    # histograms of the terminal errors
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    for ax, (col, label, unit) in zip(axes, (ERROR_COLUMNS[0], ERROR_COLUMNS[3], ERROR_COLUMNS[4])):
        v = _finite(rows, col, n)[reached]
        ax.hist(v[np.isfinite(v)], bins=40, color="C0")
        ax.set_xlabel(f"{label} [{unit}]")
        ax.grid(True)
    axes[0].set_ylabel("samples")
    figs.append(_save(fig, out_dir, "error_histograms.png"))

    # terminal footprint: range-to-go vs cross-range with a 2-sigma ellipse
    fig, ax = plt.subplots(figsize=(5.5, 5))
    x = _finite(rows, "err_crossrange_m", n)[reached] / 1e3
    y = _finite(rows, "err_range_m", n)[reached] / 1e3
    both = np.isfinite(x) & np.isfinite(y)
    x, y = x[both], y[both]
    ax.plot(x, y, ".", ms=3)
    if x.size > 2:
        cov = np.cov(np.vstack([x, y]))
        vals, vecs = np.linalg.eigh(cov)
        t = np.linspace(0, 2 * np.pi, 200)
        ell = vecs @ (2 * np.sqrt(np.maximum(vals, 0))[:, None] * np.vstack([np.cos(t), np.sin(t)]))
        ax.plot(x.mean() + ell[0], y.mean() + ell[1], "r-", label="2σ ellipse")
        ax.legend(fontsize=8)
    ax.set_xlabel("cross-range [km]")
    ax.set_ylabel("range to go [km]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True)
    figs.append(_save(fig, out_dir, "footprint.png"))
    return figs


def _trajectory_figures(traj: dict, out_dir: str, limits) -> list:
    figs = []
    sample = np.asarray(traj["sample"])
    E = np.asarray(traj["energy_J_kg"], float)
    E0, Ef = E.max(), E.min()
    e = (E0 - E) / (E0 - Ef)
    groups = [np.flatnonzero(sample == s) for s in np.unique(sample)]
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for ax, (col, scale, label) in zip(axes.ravel(), (("altitude_m", 1e-3, "altitude [km]"),
                                                       ("velocity_m_s", 1e-3, "speed [km/s]"),
                                                       ("flight_path_deg", 1.0, "flight-path angle [deg]"),
                                                       ("bank_deg", 1.0, "bank [deg]"))):
        v = np.asarray(traj[col], float) * scale
        for g in groups:
            ax.plot(e[g], v[g], lw=0.4, alpha=0.5)
        ax.set_ylabel(label)
        ax.grid(True)
    for ax in axes[1]:
        ax.set_xlabel("normalised energy e")
    figs.append(_save(fig, out_dir, "states_vs_energy.png"))  # paper 000 Fig. 6

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, (col, scale, label, lim) in zip(axes, (
            ("dynamic_pressure_Pa", 1e-3, "dynamic pressure [kPa]", "dynamic_pressure_max"),
            ("heat_flux_W_m2", 1e-3, "heat flux [kW/m^2]", "heat_flux_max"),
            ("normal_load_g", 1.0, "normal load [g]", "normal_load_max"))):
        v = np.asarray(traj[col], float) * scale
        for g in groups:
            ax.plot(e[g], v[g], lw=0.4, alpha=0.5)
        if limits is not None and np.isfinite(getattr(limits, lim)):
            ax.axhline(getattr(limits, lim) * scale, color="r", ls="--", lw=1)
        ax.set_xlabel("normalised energy e")
        ax.set_ylabel(label)
        ax.grid(True)
    figs.append(_save(fig, out_dir, "constraints_vs_energy.png"))  # paper 000 Fig. 7

    if "reference_drag_m_s2" in traj:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        ref = np.asarray(traj["reference_drag_m_s2"], float)
        D = np.asarray(traj["drag_m_s2"], float)
        for g in groups:
            m = ref[g] > 0
            ax.plot(e[g][m], ref[g][m], lw=0.4, alpha=0.5)
        ax.plot([], [], label="references (one per sample)")
        ax.plot(e, D, ",", color="k", alpha=0.3, label="flown")
        ax.set_xlabel("normalised energy e")
        ax.set_ylabel("drag [m/s^2]")
        ax.legend(fontsize=8)
        ax.grid(True)
        figs.append(_save(fig, out_dir, "drag_profiles.png"))  # paper 000 Fig. 8

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    lon, lat = np.asarray(traj["longitude_deg"]), np.asarray(traj["latitude_deg"])
    for g in groups:
        ax.plot(lon[g], lat[g], lw=0.4, alpha=0.5)
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.grid(True)
    figs.append(_save(fig, out_dir, "groundtracks.png"))  # paper 000 Fig. 9
    return figs


def _save(fig, out_dir, name) -> str:
    paths = []
    plots.save_figure(fig, out_dir, name, paths)
    return paths[0]
