"""What drives a campaign's misses and failures: every dispersed input (the rows' ``disp_*``
columns that vary) against every outcome (success, the miss distance, the signed terminal errors
and the margin to each path limit), by Spearman rank correlation over the samples where both are
finite, and for the failures the medians of the leading inputs in failed and successful samples
with a Mann-Whitney U test (scipy.stats). Rank correlation finds monotonic associations, not
causal shares; with many inputs some correlations are large by chance, so a cell counts as
significant only below the Bonferroni level 0.05 / (inputs x outcomes)."""
from __future__ import annotations

import numpy as np
import scipy.stats as sps

from drake_entry.campaign.statistics import finite_column

__all__ = ["OUTCOMES", "MIN_SAMPLES", "failure_drivers"]

#: (row column, words) of the outcomes the inputs are ranked against; margin_* columns follow
OUTCOMES = (("success", "success"), ("err_distance_m", "miss distance"), ("err_range_m", "range error"),
            ("err_crossrange_m", "cross-range error"), ("err_altitude_m", "altitude error"),
            ("err_velocity_m_s", "speed error"))
#: fewer samples than this with both values finite: no correlation
MIN_SAMPLES = 8


def _outcomes(rows: dict, n: int) -> list:
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
    median_successful, mann_whitney_p}]}: the ``top`` inputs by their largest |rho| over the
    outcomes; failures lists the inputs most associated with success when some samples failed
    and some succeeded ({} below MIN_SAMPLES samples)."""
    n = len(rows.get("index", []))
    if n < MIN_SAMPLES:
        return {}
    inputs = []
    for col in sorted(c for c in rows if c.startswith("disp_")):
        x = finite_column(rows, col, n)
        if np.isfinite(x).sum() >= MIN_SAMPLES and np.ptp(x[np.isfinite(x)]) > 0:
            inputs.append((col, x))
    outcomes = _outcomes(rows, n)
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
    failures = []
    if success.size == n and 0 < success.sum() < n:
        ranked = sorted((r for r in table if "success" in r["cells"]), key=lambda r: -abs(r["cells"]["success"][0]))
        for r in ranked[:3]:
            x = dict(inputs)[r["input"]]
            bad, good = x[~success & np.isfinite(x)], x[success & np.isfinite(x)]
            if bad.size == 0 or good.size == 0:
                continue
            failures.append({"input": r["input"], "rho": r["cells"]["success"][0], "p_value": r["cells"]["success"][1],
                             "median_failed": float(np.median(bad)), "median_successful": float(np.median(good)),
                             "mann_whitney_p": float(sps.mannwhitneyu(bad, good).pvalue)})
    return {"outcomes": [[c, w] for c, w, _ in outcomes], "inputs": table[:top], "level": level,
            "failures": failures}
