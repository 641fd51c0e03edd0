"""How much each dispersed input shapes each outcome, from the campaign's own samples: PAWN
(Pianosi & Wagener 2015, SALib's ``pawn.analyze``), a moment-independent index that needs no
special sampling design: for input x_i, the Kolmogorov-Smirnov distance between the outcome's
unconditional distribution and its distribution with x_i held in one of S slices, summarised by
the median over the slices (0: the outcome does not depend on x_i; 1: x_i alone decides it).

The inputs are the rows' varying ``disp_*`` columns (drake_entry.campaign.drivers.dispersed_inputs),
sliced by rank (equal-probability slices, so a Gaussian input's tails are not starved); the
outcomes are the signed terminal errors against the aim, the miss distance and every path-limit
margin (drivers.outcome_columns, without success: drivers' Mann-Whitney test serves that).

With a finite sample the index of an input the outcome ignores is not 0: the KS distance of S
small random subsets. Each outcome is therefore also analysed against DUMMIES independent
uniform inputs drawn from a fixed seed, and an input's index counts as significant only above
the largest dummy's (the dummy-parameter test of Khorashadi Zadeh et al. 2017).
"""
from __future__ import annotations

import numpy as np
import scipy.stats as sps

from drake_entry.campaign.drivers import MIN_SAMPLES, dispersed_inputs, outcome_columns

__all__ = ["SLICES", "DUMMIES", "MIN_SENSITIVITY_SAMPLES", "pawn_sensitivity"]

#: conditioning slices per input (SALib's S; about 10 samples per slice at the smallest campaign)
SLICES = 10
#: independent uniform dummy inputs that set each outcome's noise floor
DUMMIES = 20
#: fewer samples with the outcome finite: no index (SLICES slices of at least 5 samples)
MIN_SENSITIVITY_SAMPLES = max(MIN_SAMPLES, 5 * SLICES)
#: the dummies' seed (fixed: the same rows give the same table)
DUMMY_SEED = 20_170_101


def pawn_sensitivity(rows: dict, top: int = 8) -> dict:
    """{outcomes: [[column, words]], inputs: [{input, cells: {outcome: [index, significant]},
    strongest}], floors: {outcome: the largest dummy's index}, slices, dummies, samples}: the
    ``top`` inputs by their largest significant index (then the largest index) over the
    outcomes; {} below MIN_SENSITIVITY_SAMPLES samples or with no varying input."""
    from SALib.analyze import pawn  # imported here: a report without enough samples never loads it

    n = len(rows.get("index", []))
    inputs = dispersed_inputs(rows, n)
    outcomes = [o for o in outcome_columns(rows, n) if o[0] != "success"]
    if n < MIN_SENSITIVITY_SAMPLES or not inputs or not outcomes:
        return {}
    dummies = np.random.default_rng(DUMMY_SEED).uniform(size=(n, DUMMIES))
    cells: dict = {col: {} for col, _ in inputs}
    floors, analysed = {}, []
    inputs_finite = np.all([np.isfinite(x) for _, x in inputs], axis=0)
    for out_col, words, y in outcomes:
        ok = np.isfinite(y) & inputs_finite
        if ok.sum() < MIN_SENSITIVITY_SAMPLES:
            continue
        ranks = np.column_stack([sps.rankdata(x[ok]) / ok.sum() for _, x in inputs] + [dummies[ok]])
        names = [col for col, _ in inputs] + [f"dummy_{k}" for k in range(DUMMIES)]
        problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
        median = np.asarray(pawn.analyze(problem, ranks, y[ok], S=SLICES, seed=DUMMY_SEED)["median"], float)
        floor = float(median[len(inputs):].max())
        floors[out_col] = floor
        analysed.append([out_col, words])
        for (col, _), value in zip(inputs, median[:len(inputs)]):
            cells[col][out_col] = [float(value), bool(value > floor)]
    if not analysed:
        return {}
    table = []
    for col, c in cells.items():
        if c:
            significant = [v for v, sig in c.values() if sig]
            table.append({"input": col, "cells": c, "strongest": max(v for v, _ in c.values()),
                          "strongest_significant": max(significant, default=0.0)})
    table.sort(key=lambda r: (-r["strongest_significant"], -r["strongest"]))
    return {"outcomes": analysed, "inputs": table[:top], "floors": floors, "slices": SLICES, "dummies": DUMMIES,
            "samples": n}
