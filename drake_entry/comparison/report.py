"""The report of a comparison: several guidance methods, one mission, the same dispersions.

Reads ``comparison.json`` and each flown method's campaign directory (its rows: the one verdict
of every flight, drake_entry.models.verdict) and writes ``report.md``, ``report.html``,
``comparison_summary.json`` and the figures. Per method: success, inside the box and within
the limits with Clopper-Pearson 90 % intervals; terminal-error statistics; the worst margin of
every path limit; control activity (reversals, bank travel, time at the bank and bank-rate
limits); pre-flight and on-board planning time and core seconds per sample; then overlaid
footprints, the success intervals and the miss-distance distributions. Methods that were not
flown are listed with their reason. Checks that sample i drew the same dispersions for every
method and says so.
"""
from __future__ import annotations

import json
import os

import numpy as np
from scipy import stats as scipy_stats

from drake_entry.campaign.report import (
    MARGIN_COLUMNS,
    drake_entry_version,
    figure_list,
    flown_scenario,
    format_number,
    path_limit_tolerance,
    reached_terminal,
    rows_as_columns,
    summary_statistics,
    table_cell,
    write_markdown_report,
)
from drake_entry.campaign.rows import row_problem
from drake_entry.campaign.statistics import finite_column
from drake_entry.campaign.store import coverage, read_manifest
from drake_entry.comparison.derive import value_text
from drake_entry.errors import CampaignError
from drake_entry.figures import plt, save_figure
from drake_entry.models.verdict import margin_breached

__all__ = ["MANIFEST", "LEVEL", "MARGIN_NAMES", "read_comparison_manifest", "clopper_pearson", "method_summary",
           "summary_text", "dispersion_check", "write_comparison_report", "derivation_tables", "footprints",
           "success_intervals", "miss_distributions", "footprint_zoom"]

#: the file a comparison directory is identified by
MANIFEST = "comparison.json"
#: the confidence of the two-sided Clopper-Pearson intervals of the report
LEVEL = 0.90
#: margins shown, with their names in the table (a margin is (limit - peak) / limit)
MARGIN_NAMES = {"margin_heat_flux": "heat flux", "margin_dynamic_pressure": "dynamic pressure",
                "margin_normal_load": "normal load", "margin_total_load": "total load", "margin_bank": "bank"}


def read_comparison_manifest(out_dir: str) -> dict | None:
    """comparison.json of ``out_dir`` (None when absent)."""
    path = os.path.join(out_dir, MANIFEST)
    try:
        with open(path) as f:
            manifest = json.load(f)
    except FileNotFoundError:
        return None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise CampaignError(f"{path} is not a comparison manifest (not JSON: {str(e).splitlines()[0]}); give "
                            f"another directory") from None
    if not isinstance(manifest, dict) or not isinstance(manifest.get("methods"), dict):
        raise CampaignError(f"{path} is not a comparison manifest (no 'methods' record); give another directory")
    return manifest


def clopper_pearson(successes: int, runs: int, level: float = LEVEL) -> tuple[float, float]:
    """The exact two-sided ``level`` interval on a success probability (scipy.stats.binomtest)."""
    ci = scipy_stats.binomtest(int(successes), int(runs)).proportion_ci(confidence_level=level, method="exact")
    return float(ci.low), float(ci.high)


def _method_rows(out_dir: str, label: str) -> dict | None:
    cov = coverage(os.path.join(out_dir, label), row_problem)
    records = [cov["rows"][k] for k in sorted(cov["rows"])]
    return rows_as_columns(records) if records else None


def method_summary(rows: dict, tolerance: float = 0.0) -> dict:
    """The comparison's figures of one method's campaign rows (``tolerance``: its scenario's
    relative path-limit tolerance, which the breaches are counted with)."""
    n = len(rows["index"])
    s = summary_statistics(rows, tolerance)
    reached = reached_terminal(rows)
    out = {"samples": n, "successful": s["successful"], "reached": s["reached"],
           "inside_box": s["inside_acceptance_box"], "within_limits": s["within_limits"],
           "failure_reasons": s["failure_reasons"]}
    for key in ("successful", "inside_box", "within_limits"):
        out[f"{key}_interval"] = clopper_pearson(out[key], n)
    d = finite_column(rows, "err_distance_m", n)[reached] / 1e3
    if d.size:
        out["miss_km"] = {"median": float(np.median(d)), "p95": float(np.percentile(d, 95)), "max": float(d.max())}
    for col in ("err_range_m", "err_crossrange_m", "err_altitude_m", "err_velocity_m_s"):
        v = finite_column(rows, col, n)[reached]
        if v.size:
            out[col] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)) if v.size > 1 else 0.0}
    out["margins"] = {}
    for col in [c for c in MARGIN_COLUMNS if c in rows] + (["margin_bank"] if "margin_bank" in rows else []):
        m = finite_column(rows, col, n)
        m = m[np.isfinite(m)]
        if m.size:
            out["margins"][col] = {"worst": float(m.min()), "breached": int(margin_breached(m, tolerance).sum())}
    for col in ("bank_reversals", "bank_travel_deg", "time_at_bank_limit_s", "time_at_bank_rate_limit_s",
                "plans", "planning_wall_s", "wall_time_s"):
        v = finite_column(rows, col, n)
        v = v[np.isfinite(v)]
        if v.size:
            out[col] = {"mean": float(v.mean()), "max": float(v.max())}
    return out


def dispersion_check(all_rows: dict) -> tuple[bool, int, float]:
    """(same draws, samples compared, largest difference): sample i's dispersion columns
    (``disp_*``) across every flown method."""
    columns, compared, worst = None, 0, 0.0
    by_index = {}
    for rows in all_rows.values():
        cols = sorted(c for c in rows if c.startswith("disp_"))
        columns = cols if columns is None else [c for c in columns if c in cols]
        for j, i in enumerate(rows["index"]):
            by_index.setdefault(int(i), []).append({c: rows[c][j] for c in cols})
    for draws in by_index.values():
        if len(draws) < 2:
            continue
        compared += 1
        for c in columns or []:
            vals = np.array([np.nan if d.get(c) is None else float(d[c]) for d in draws])
            if np.isfinite(vals).all():
                worst = max(worst, float(np.ptp(vals)))
    return worst == 0.0, compared, worst


def summary_text(summary: dict) -> str:
    """A comparison summary (comparison_summary.json) as a console table: each flown method's
    successes, median miss [km] and core seconds per sample, then each method not flown and why."""
    lines = [f"{'method':14s} {'successful':>11s} {'miss median [km]':>17s} {'core s/sample':>14s}"]
    for label, s in summary["methods"].items():
        miss = (s.get("miss_km") or {}).get("median", float("nan"))
        wall = (s.get("wall_time_s") or {}).get("mean", float("nan"))
        lines.append(f"{label:14s} {s['successful']:>4d} of {s['samples']:<4d} {miss:17.3g} {wall:14.1f}")
    lines += [f"{label:14s} not flown: {reason[:160]}" for label, reason in summary["not_flown"].items()]
    return "\n".join(lines)


def write_comparison_report(out_dir: str) -> str:
    """Write the comparison's report.md, report.html, comparison_summary.json and figures in
    ``out_dir``; return the path of report.md. CampaignError when it holds no comparison."""
    meta = read_comparison_manifest(out_dir)
    if meta is None:
        raise CampaignError(f"{out_dir} holds no comparison ({MANIFEST}): run `drake-entry compare` first")
    all_rows, summaries, flown = {}, {}, {}
    for label, info in meta["methods"].items():
        if info.get("flown") and os.path.isdir(os.path.join(out_dir, label)):
            rows = _method_rows(out_dir, label)
            if rows is not None:
                flown[label] = flown_scenario(read_manifest(os.path.join(out_dir, label)))
                all_rows[label], summaries[label] = rows, method_summary(rows, path_limit_tolerance(flown[label]))
    same, compared, worst = dispersion_check(all_rows)
    scenario = next(iter(flown.values()), None)  # every method flies the same mission: its terminal box
    radius = getattr(getattr(scenario, "terminal", None), "distance_tolerance_km", None)
    with open(os.path.join(out_dir, "comparison_summary.json"), "w") as f:
        json.dump({"comparison": meta["comparison"], "mission": meta["mission"], "seed": meta["seed"],
                   "same_dispersions": same, "samples_compared": compared, "methods": summaries,
                   "not_flown": {k: v.get("reason") or "not flown yet" for k, v in meta["methods"].items()
                                 if not v.get("flown")}},
                  f, indent=2)
    title = f"Comparison {meta['comparison']} (mission {meta['mission']}, {meta['runs']} samples per method)"
    figs = _figures(all_rows, summaries, out_dir, title, radius)
    sections = [_header(meta, summaries, same, compared, worst, scenario), _verdict_table(meta, summaries),
                _error_table(summaries), _margin_table(summaries), _activity_table(meta, summaries),
                _mapping_table(meta), derivation_tables(meta), figure_list(figs) if figs else ""]
    return write_markdown_report(sections, out_dir, title=title)


def _num(x) -> str:
    """A table number: whole units from 100 up, else 3 significant digits."""
    if x is None or not np.isfinite(x):
        return "—"
    return f"{x:.0f}" if abs(x) >= 100 else format_number(x, 3)


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %"


def _header(meta, summaries, same, compared, worst, scenario) -> str:
    sessions = meta.get("sessions") or [{}]
    last = sessions[-1]
    box = []
    if scenario is not None:
        t = scenario.terminal
        for name, value, unit in (("altitude", t.altitude_tolerance_km, "km"), ("Mach", t.mach_tolerance, ""),
                                  ("speed", t.velocity_tolerance_m_s, "m/s"),
                                  ("distance to target", t.distance_tolerance_km, "km")):
            if value is not None:
                box.append(f"{name} ± {value:g} {unit}".rstrip() if name != "distance to target"
                           else f"{name} <= {value:g} {unit}")
    lines = [f"# Comparison {meta['comparison']}", "", meta.get("description", ""), "",
             f"Mission `{meta['mission']}`; {meta['runs']} dispersed samples per method, seed {meta['seed']}; "
             f"drake_entry {drake_entry_version()}, drake {meta['versions'].get('drake')}; made "
             f"{last.get('date_utc', '?')} by `{last.get('command', '?')}` (commit {last.get('git_commit')})."]
    if box:
        lines += ["", "Acceptance box at the terminal interface: " + ", ".join(box) + "; every path limit of the "
                  "vehicle at every flown sample (a flight succeeds only when it reaches its terminal interface, "
                  "inside the box, within every limit)."]
    if compared:
        lines += ["", (f"Same dispersions: sample i drew the same dispersions for every method (checked on "
                       f"{compared} samples flown by more than one method)." if same else
                       f"**Dispersions differ between methods** (largest difference {worst:.3g} on {compared} "
                       f"samples): the methods did not fly the same draws.")]
    return "\n".join(lines)


def _verdict_table(meta, summaries) -> str:
    lvl = f"{100 * LEVEL:g} %"
    out = ["## Verdict", "",
           f"Counts out of the samples flown; brackets: the exact two-sided {lvl} Clopper-Pearson interval on the "
           "probability; each method's name links to its own campaign report.", "",
           "| method | samples | successful | inside the box | within every limit | why not successful |",
           "|---|---|---|---|---|---|"]
    for label, info in meta["methods"].items():
        s = summaries.get(label)
        if s is None:
            why = "see the mapping below" if info.get("reason") else "not flown yet"
            out.append(f"| {label} (!{info['method']}) | — | not flown | — | — | {why} |")
            continue
        cells = []
        for key in ("successful", "inside_box", "within_limits"):
            lo, hi = s[f"{key}_interval"]
            cells.append(f"{s[key]} [{_pct(lo)}, {_pct(hi)}]")
        reasons = "; ".join(f"{k}: {v}" for k, v in sorted(s["failure_reasons"].items(), key=lambda kv: -kv[1]))
        out.append(f"| [{label}]({label}/report.md) (!{info['method']}) | {s['samples']} | {' | '.join(cells)} | "
                   f"{table_cell(reasons) or '—'} |")
    return "\n".join(out)


def _ms(s: dict, col: str, scale: float = 1.0, digits: int = 3) -> str:
    v = s.get(col)
    return "—" if v is None else f"{format_number(v['mean'] * scale, digits)} ± {format_number(v['std'] * scale, 2)}"


def _error_table(summaries) -> str:
    if not summaries:
        return ""
    out = ["## Terminal errors", "",
           "Over the samples that reached the terminal interface: the miss distance to the target and the errors' "
           "mean ± 1σ (range to go: + short of the target; cross-range: + right of the final heading).", "",
           "| method | reached | miss median [km] | miss P95 [km] | miss max [km] | range to go [km] | cross-range [km] "
           "| altitude [m] | speed [m/s] |", "|---|---|---|---|---|---|---|---|---|"]
    for label, s in summaries.items():
        miss = s.get("miss_km") or {}
        out.append(f"| {label} | {s['reached']} of {s['samples']} | {format_number(miss.get('median'), 3)} | "
                   f"{format_number(miss.get('p95'), 3)} | {format_number(miss.get('max'), 3)} | {_ms(s, 'err_range_m', 1e-3)} | "
                   f"{_ms(s, 'err_crossrange_m', 1e-3)} | {_ms(s, 'err_altitude_m')} | {_ms(s, 'err_velocity_m_s')} |")
    return "\n".join(out)


def _margin_table(summaries) -> str:
    cols = [c for c in MARGIN_NAMES if any(c in s["margins"] for s in summaries.values())]
    if not cols:
        return ""
    out = ["## Path limits", "",
           "The worst margin over every sample flown, (limit - peak) / limit (negative: breached), and in brackets "
           "the number of samples that breached the limit.", "",
           "| method | " + " | ".join(MARGIN_NAMES[c] for c in cols) + " |", "|---|" + "---|" * len(cols)]
    for label, s in summaries.items():
        cells = []
        for c in cols:
            m = s["margins"].get(c)
            cells.append("—" if m is None else f"{round(100 * m['worst'], 1) + 0.0:.1f} % ({m['breached']})")  # no -0.0
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(out)


def _activity_table(meta, summaries) -> str:
    if not summaries:
        return ""
    out = ["## Control activity and cost", "",
           "Means per sample (max in brackets). Bank reversals and travel count the flown bank angle; time at the "
           "bank limit or at the bank-rate limit measures saturation. Pre-flight planning: once per mission, before "
           "the campaign (measured in the calling process); on board: the plans made during a flight and their wall "
           "time; core s per sample: the wall time of one sample on one core (one sample per process).", "",
           "| method | reversals | bank travel [deg] | at bank limit [s] | at bank-rate limit [s] | pre-flight planning "
           "[s] | on-board plans | on-board planning [s] | core s per sample |", "|---|---|---|---|---|---|---|---|---|"]

    def mm(s, col):
        v = s.get(col)
        return "—" if v is None else f"{_num(v['mean'])} ({_num(v['max'])})"

    for label, s in summaries.items():
        pre = meta["methods"][label].get("preflight_planning_s")
        out.append(f"| {label} | {mm(s, 'bank_reversals')} | {mm(s, 'bank_travel_deg')} | "
                   f"{mm(s, 'time_at_bank_limit_s')} | {mm(s, 'time_at_bank_rate_limit_s')} | {_num(pre)} | "
                   f"{mm(s, 'plans')} | {mm(s, 'planning_wall_s')} | {mm(s, 'wall_time_s')} |")
    return "\n".join(out)


def _mapping_table(meta) -> str:
    out = ["## How the mission maps to each method", "",
           "Every method shares the mission (vehicle, environment, entry state, target, terminal box, dispersions, "
           "simulation settings); only its own settings differ. The scenario each method flew is in "
           "`scenarios/<method>.yaml`; a method that cannot fly the mission says why.", "",
           "| method | flown | settings |", "|---|---|---|"]
    for label, info in meta["methods"].items():
        text = info.get("mapping") or ""
        if not info.get("flown"):
            text = (f"{text} **Not flown:** {info['reason']}" if info.get("reason")
                    else f"{text} (not flown yet: not selected in any run so far)").strip()
        where = f" ([scenario]({info['scenario']}))" if info.get("flown") and info.get("scenario") else ""
        out.append(f"| {label} (!{info['method']}) | {'yes' if info.get('flown') else 'no'} | "
                   f"{table_cell(text)}{where} |")
    return "\n".join(out)


def derivation_tables(meta) -> str:
    """Each derived method's search: every candidate flown, its successes of the search's flights
    and mean box ratio, and which were kept ('' when no method's settings were derived)."""
    derived = {label: info["derivation"] for label, info in meta["methods"].items() if info.get("derivation")}
    if not derived:
        return ""
    out = ["## Settings derived from the mission", "",
           "A method listed without settings (or every method, when the comparison names only its mission) takes "
           "them from the mission (drake_entry.guidance.derivation) and chooses its free ones by flying them: each "
           "candidate on the nominal entry and dispersed draws of a seed no campaign uses, kept when every flight "
           "succeeds within three quarters of each box tolerance, else the best (most successes, then the smallest "
           "mean box ratio |error| / tolerance, a limit breach counting 10 more, a flight stopped short 100 more). "
           "Steps run in order, each at the values kept before it."]
    for label, d in derived.items():
        kept = ", ".join(f"{k} = {value_text(v)}" for k, v in d["chosen"].items()) or "nothing searched"
        out += ["", f"**{label}**: kept {kept}",
                "", "| step | candidate | successful | mean box ratio | s | why not (first flights) |",
                "|---|---|---|---|---|---|"]
        for t in d["trials"]:
            values = ", ".join(f"{k.replace('guidance.', '')} {value_text(v)}" for k, v in t["values"].items())
            ratio = "—" if t["mean_box_ratio"] is None else f"{t['mean_box_ratio']:.2f}"
            why = t["setup_failure"] or "; ".join(t["why"])
            out.append(f"| {t['step']} | {values} | {t['successes']} of {t['flights']} | {ratio} | {t['wall_s']:.1f} | "
                       f"{table_cell(why[:300])} |")
    return "\n".join(out)


def _figures(all_rows, summaries, out_dir, title, radius_km) -> list:
    if not all_rows:
        return []
    return [footprints(all_rows, out_dir, title, radius_km), success_intervals(summaries, out_dir, title),
            miss_distributions(all_rows, out_dir, title, radius_km)]


def footprint_zoom(half: float, radius_km, successful) -> tuple[float, str]:
    """The zoom panel's half-width [km] and title: three times the distance criterion when the
    whole spread (``half`` [km]) is wider than twice that; else (the zoom would repeat the whole)
    1.2 times the 90th percentile of the successful samples' larger offset (``successful`` [km]),
    so the accurate methods' clusters are seen; a tenth of the spread without a criterion."""
    if radius_km is None:
        return 0.1 * half, "zoom on the centre (a tenth of the spread)"
    if half > 6.0 * radius_km or len(successful) == 0:
        return 3.0 * radius_km, "zoom on the acceptance region"
    p90 = float(np.percentile(successful, 90))
    return max(1.2 * p90, 1e-3 * radius_km), "zoom on 90 % of the successful samples"


def footprints(all_rows: dict, out_dir: str, title: str, radius_km) -> tuple[str, str]:
    """Overlaid terminal footprints (cross-range against range to go [km]) of every method: the
    whole spread, and a zoom on the acceptance region."""
    fig, axes = plt.subplots(1, 2, figsize=(12.0, 6.2))
    extent, inner = [], []  # |x|, |y| of every sample reached; of the successful ones
    t = np.linspace(0.0, 2.0 * np.pi, 300)
    for k, (label, rows) in enumerate(all_rows.items()):
        n = len(rows["index"])
        reached = reached_terminal(rows)
        x = finite_column(rows, "err_crossrange_m", n)[reached] / 1e3
        y = finite_column(rows, "err_range_m", n)[reached] / 1e3
        ok = np.array([bool(v) for v in rows["success"]])[reached]
        color = f"C{k % 10}"
        for ax in axes:
            if ok.any():
                ax.plot(x[ok], y[ok], "o", ms=4, color=color, label=f"{label}: successful ({ok.sum()})")
            if (~ok).any():
                ax.plot(x[~ok], y[~ok], "x", ms=6, color=color, label=f"{label}: not successful ({(~ok).sum()})")
        extent += list(np.abs(x)) + list(np.abs(y))
        inner += list(np.maximum(np.abs(x[ok]), np.abs(y[ok])))
    half = 1.1 * max(extent, default=1.0)
    zoom, zoom_name = footprint_zoom(half, radius_km, inner)
    for ax, h, name in ((axes[0], max(half, zoom), "every sample that reached"), (axes[1], zoom, zoom_name)):
        if radius_km is not None:
            ax.plot(radius_km * np.cos(t), radius_km * np.sin(t), "r--", lw=1.2,
                    label=f"distance criterion ({radius_km:g} km)")
        ax.plot(0.0, 0.0, "k+", ms=14, mew=1.5, label="target")
        ax.set_xlim(-h, h)
        ax.set_ylim(-h, h)
        ax.set_aspect("equal")
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("cross-range [km] (+ right of the final heading)")
        ax.set_ylabel("range to go [km] (+ short of the target)")
        ax.grid(True, alpha=0.4)
    handles, labels = axes[1].get_legend_handles_labels()
    rows = -(-len(labels) // 4)  # the legend's rows below the axes, their labels clear of it
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.03 + 0.033 * rows, 1, 0.96))
    path = os.path.join(out_dir, "comparison_footprints.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path, ("Terminal footprints of every method on the same dispersed samples (those that reached the "
                  "terminal interface), centred on the target, equal axes; left the whole spread, right a zoom to "
                  "three times the distance criterion (dashed circle), or, when the whole spread is already that "
                  "close, to the successful samples' 90th percentile (its title says which). Dots are successful "
                  "flights, crosses the "
                  "others (outside the box in distance, altitude or speed, or a path limit breached). Look for the "
                  "spread and bias of each method, and for crosses inside the circle: failed on altitude, speed or "
                  "limits.")


def success_intervals(summaries: dict, out_dir: str, title: str) -> tuple[str, str]:
    """Success, inside-the-box and within-limits fractions with their Clopper-Pearson intervals."""
    labels = list(summaries)
    fig, ax = plt.subplots(figsize=(7.5, 0.9 + 0.75 * len(labels)))
    for j, (key, name) in enumerate((("successful", "successful"), ("inside_box", "inside the box"),
                                     ("within_limits", "within every limit"))):
        for i, label in enumerate(labels):
            s = summaries[label]
            p = s[key] / s["samples"]
            lo, hi = s[f"{key}_interval"]
            y = i + (j - 1) * 0.22
            ax.errorbar(p, y, xerr=[[p - lo], [hi - p]], fmt="o", color=f"C{j}", capsize=3,
                        label=name if i == 0 else None)
    ax.set_yticks(range(len(labels)))
    ax.set_yticklabels([f"{lab} (N = {summaries[lab]['samples']})" for lab in labels])
    ax.set_xlim(-0.02, 1.02)
    ax.set_xlabel("fraction of samples [-]")
    ax.invert_yaxis()
    ax.grid(True, axis="x", alpha=0.4)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3)
    paths = []
    save_figure(fig, out_dir, "comparison_success.png", paths, title)
    return paths[0], (f"Fraction of samples successful, inside the acceptance box and within every path limit, per "
                      f"method, with the exact two-sided {100 * LEVEL:g} % Clopper-Pearson interval. Overlapping "
                      "intervals mean the campaigns do not separate the methods at this size.")


def miss_distributions(all_rows: dict, out_dir: str, title: str, radius_km) -> tuple[str, str]:
    """Empirical distribution of the miss distance [km] of every method (logarithmic axis)."""
    fig, ax = plt.subplots(figsize=(9.5, 4.2))
    for k, (label, rows) in enumerate(all_rows.items()):
        n = len(rows["index"])
        d = np.sort(finite_column(rows, "err_distance_m", n)[reached_terminal(rows)] / 1e3)
        if d.size:
            ax.step(np.maximum(d, 1e-3), np.arange(1, d.size + 1) / n, where="post", color=f"C{k % 10}",
                    label=f"{label} ({d.size} of {n} reached)")
    if radius_km is not None:
        ax.axvline(radius_km, color="r", ls="--", lw=1.2, label=f"distance criterion ({radius_km:g} km)")
    ax.set_xscale("log")
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel("miss distance to the target at the terminal interface [km] (log scale)")
    ax.set_ylabel("fraction of samples [-]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    paths = []
    save_figure(fig, out_dir, "comparison_miss.png", paths, title)
    return paths[0], ("Empirical distribution of the miss distance per method, as a fraction of all its samples "
                      "(a curve that ends below 1: samples that did not reach the terminal interface). Left and "
                      "steep is accurate and consistent; read each method's fraction inside the box where its curve "
                      "crosses the dashed line.")
