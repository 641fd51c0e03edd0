"""What drives a campaign's misses and failures: every dispersed input (the rows' ``disp_*``
columns that vary) against every outcome (success, the miss distance, the signed terminal errors
and the margin to each path limit), by Spearman rank correlation over the samples where both are
finite; and for the failures each input's distribution in the failed samples against the
successful ones (two-sample Kolmogorov-Smirnov, which sees failures at both tails of an input;
Mann-Whitney U for a shift; the failures counted in the input's quintiles), and the failures
grouped by why they failed, each group with the input that separates it best (scipy.stats).
Rank correlation finds monotonic associations, not causal shares; with many inputs some
correlations are large by chance, so a cell counts as significant only below the Bonferroni
level 0.05 / (inputs x outcomes) (an input's failure test: 0.05 / inputs)."""
from __future__ import annotations

import numpy as np
import scipy.stats as sps

from drake_entry.campaign.statistics import finite_column
from drake_entry.models.verdict import failure_clauses

__all__ = ["OUTCOMES", "MIN_SAMPLES", "QUANTILE_BINS", "MIN_MODE", "failure_drivers", "dispersed_inputs",
           "outcome_columns"]

#: (row column, words) of the outcomes the inputs are ranked against; margin_* columns follow
OUTCOMES = (("success", "success"), ("err_distance_m", "miss distance"), ("err_range_m", "range error"),
            ("err_crossrange_m", "cross-range error"), ("err_altitude_m", "altitude error"),
            ("err_velocity_m_s", "speed error"))
#: fewer samples than this with both values finite: no correlation
MIN_SAMPLES = 8


def dispersed_inputs(rows: dict, n: int) -> list:
    """[(column, values)] of the rows' dispersed inputs (``disp_*``) that vary over at least
    MIN_SAMPLES finite samples."""
    inputs = []
    for col in sorted(c for c in rows if c.startswith("disp_")):
        x = finite_column(rows, col, n)
        if np.isfinite(x).sum() >= MIN_SAMPLES and np.ptp(x[np.isfinite(x)]) > 0:
            inputs.append((col, x))
    return inputs


def outcome_columns(rows: dict, n: int) -> list:
    """[(column, words, values)] of the outcomes present, margins last."""
    out = []
    for col, words in OUTCOMES:
        if col not in rows:
            continue
        if col == "success":
            values = np.array([1.0 if v else 0.0 for v in rows["success"]])
        else:
            values = finite_column(rows, col, n)
        out.append((col, words, values))
    for col in sorted(c for c in rows if c.startswith("margin_")):
        out.append((col, f"{col.removeprefix('margin_').replace('_', ' ')} margin", finite_column(rows, col, n)))
    return [o for o in out if np.isfinite(o[2]).sum() >= MIN_SAMPLES and np.ptp(o[2][np.isfinite(o[2])]) > 0]


def failure_drivers(rows: dict, top: int = 8) -> dict:
    """{outcomes: [[column, words]], inputs: [{input, cells: {outcome: [rho, p]}, strongest}],
    level: the Bonferroni p level, failures: [{input, rho, p_value, median_failed,
    median_successful, ks, ks_p, mann_whitney_p, failed_by_quintile, quintile_edges}], modes:
    [{reason, samples, indices, separating}], input_level: 0.05 / inputs}: the ``top`` inputs by
    their largest |rho| over the outcomes; when some samples failed and some succeeded, failures
    lists the three inputs whose distribution differs most between them (Kolmogorov-Smirnov) and
    modes groups the failures by reason, each with its separating input ({} below MIN_SAMPLES
    samples)."""
    n = len(rows.get("index", []))
    if n < MIN_SAMPLES:
        return {}
    inputs = dispersed_inputs(rows, n)
    outcomes = outcome_columns(rows, n)
    if not inputs or not outcomes:
        return {}
    level = 0.05 / (len(inputs) * len(outcomes))
    table = []
    for col, x in inputs:
        cells = {}
        for out_col, _, y in outcomes:
            ok = np.isfinite(x) & np.isfinite(y)
            if ok.sum() < MIN_SAMPLES or np.ptp(x[ok]) == 0 or np.ptp(y[ok]) == 0:
                continue
            rho, p = sps.spearmanr(x[ok], y[ok])
            cells[out_col] = [float(rho), float(p)]
        if cells:
            table.append({"input": col, "cells": cells, "strongest": max(abs(c[0]) for c in cells.values())})
    table.sort(key=lambda r: -r["strongest"])
    success = np.array([bool(v) for v in rows.get("success", [])])
    failures, modes = [], []
    if success.size == n and 0 < success.sum() < n:
        rho = {r["input"]: r["cells"].get("success", [float("nan"), float("nan")]) for r in table}
        compared = [_failed_against_successful(col, x, ~success, success, rho.get(col)) for col, x in inputs]
        failures = sorted((c for c in compared if c), key=lambda c: c["ks_p"])[:3]
        modes = _failure_modes(rows, n, inputs, success)
    return {"outcomes": [[c, w] for c, w, _ in outcomes], "inputs": table[:top], "level": level,
            "failures": failures, "modes": modes, "input_level": 0.05 / len(inputs)}


#: the input's quantile bins the failures are counted in
QUANTILE_BINS = 5


def _failed_against_successful(col: str, x, failed, successful, rho=None) -> dict | None:
    """One input's values in the ``failed`` samples against the ``successful`` ones: medians,
    the two-sample Kolmogorov-Smirnov test (any difference of distribution: a failure mode at both
    tails of the input shows here where a shift test does not), the Mann-Whitney U test (a shift),
    and the failures counted in the input's QUANTILE_BINS quantile bins (None when a group is empty)."""
    ok = np.isfinite(x)
    bad, good = x[failed & ok], x[successful & ok]
    if bad.size == 0 or good.size == 0:
        return None
    edges = np.quantile(x[ok], np.linspace(0.0, 1.0, QUANTILE_BINS + 1))
    bins = np.clip(np.searchsorted(edges, x[failed & ok], side="right") - 1, 0, QUANTILE_BINS - 1)
    ks = sps.ks_2samp(bad, good)
    out = {"input": col, "median_failed": float(np.median(bad)), "median_successful": float(np.median(good)),
           "ks": float(ks.statistic), "ks_p": float(ks.pvalue),
           "mann_whitney_p": float(sps.mannwhitneyu(bad, good).pvalue),
           "failed_by_quintile": np.bincount(bins, minlength=QUANTILE_BINS).tolist(),
           "quintile_edges": [float(e) for e in edges]}
    if rho is not None:
        out["rho"], out["p_value"] = float(rho[0]), float(rho[1])
    return out


def _failure_modes(rows: dict, n: int, inputs: list, success) -> list:
    """The failed samples grouped by why they failed (the first reason of
    report.failure_categories' form: the message's first clause), each group of at least
    MIN_MODE samples with the input that separates it best from the successful samples
    (smallest Kolmogorov-Smirnov p-value)."""
    groups: dict = {}
    for i in np.flatnonzero(~success):
        groups.setdefault(_reason(rows, i), []).append(i)
    modes = []
    for reason, members in sorted(groups.items(), key=lambda kv: -len(kv[1])):
        mask = np.zeros(n, bool)
        mask[members] = True
        entry = {"reason": reason, "samples": len(members), "indices": [int(rows["index"][i]) for i in members][:20]}
        if len(members) >= MIN_MODE:
            compared = [c for c in (_failed_against_successful(col, x, mask, success) for col, x in inputs) if c]
            if compared:
                entry["separating"] = min(compared, key=lambda c: c["ks_p"])
        modes.append(entry)
    return modes


#: a failure mode needs this many samples for its separating input
MIN_MODE = 3


def _reason(rows: dict, i: int) -> str:
    """A failed sample's reason as a short key: the missed box criteria and breached limits its
    message names ('outside the acceptance box: distance ...' -> 'outside the box: distance';
    models.verdict.failure_clauses), else its first clause."""
    missed, breached, first = failure_clauses(str((rows.get("message") or [""] * (i + 1))[i] or ""))
    parts = ([f"outside the box: {', '.join(missed)}"] if missed else []) + (
        [f"breached: {', '.join(breached)}"] if breached else [])
    return "; ".join(parts) if parts else first
