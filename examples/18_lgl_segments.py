"""Example 18: the LGL transcription on one global polynomial (paper 002) and on equal segments
that share their end nodes (``nlp.solve(..., segments=S)``), the same problem at the same
node count, side by side: solve time, objective, verification and costates.

One polynomial of N nodes couples every node to every other (an N x N differentiation block
per state); S segments give S blocks of (N - 1) / S + 1 nodes, which SNOPT factorises much
faster. The knots (the shared nodes) carry both segments' defect rows, and their costates
come from both segments' multipliers. What to look at: the same controls; the costates agree
off the path limits and, in segments, oscillate node to node on much of the arc where a path
limit is active (shaded: the shuttle's heating limit), where the one polynomial's stay smooth.

Quick run: Betts' heating-limited shuttle (nlp.catalogue) at 81 nodes, one polynomial and 4
segments of 21 nodes, each from the built-in guess. Full run: also paper 002's MARV at 125
nodes, one polynomial and 4 segments of 32, each from the same 60-node one-polynomial solve
(``drake-entry optimize marv --segments 4`` does this).

    python examples/18_lgl_segments.py [--quick] [--out out/examples/18]
"""
import os
import time

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.verification import fly_controls
from drake_entry.figures import plt, save_figure
from drake_entry.planning import nlp
from drake_entry.planning.nlp import catalogue
from drake_entry.planning.nlp.evaluator import model_values
from drake_entry.planning.ocp_yaml import load_problem

SEGMENTS = 4


def _pair(problem, nodes, guess, tolerance):
    """One polynomial and SEGMENTS segments from the same guess: {segments: (result, core s)}."""
    out = {}
    for segments in (1, SEGMENTS):
        t0 = time.process_time()
        r = nlp.solve(problem, transcription="lgl", solver="snopt", nodes=nodes, segments=segments, guess=guess,
                      tolerance=tolerance, verifier=fly_controls)
        out[segments] = (r, time.process_time() - t0)
        print(f"  {nodes} nodes, {segments} segment(s): {time.process_time() - t0:6.1f} core s, J = {r.objective:.8g}, "
              f"verified {r.success}")
    return out


def active_path_spans(r, share: float = 1e-3) -> list:
    """(start, end) times [s] of the runs of nodes of ``r`` where a path constraint is within
    ``share`` of its bound."""
    _, g, _, _ = model_values(r.problem, r.states.T, r.controls.T)
    near = np.zeros(len(r.time), bool)
    for c, values in zip(r.problem.path, g):
        for bound in (c.min, c.max):
            if np.isfinite(bound):
                near |= np.abs(values - bound) <= share * max(abs(bound), 1.0)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], near.astype(int), [0]])))
    return [(r.time[a], r.time[b - 1]) for a, b in zip(edges[::2], edges[1::2])]


def main(quick: bool = False, out_dir: str = "out/examples/18") -> dict:
    """Solve the cases (quick: the shuttle only); return per case the pair of solves, the
    published or reference objective, and the plot path."""
    os.makedirs(out_dir, exist_ok=True)
    cases = {}
    problem, published = catalogue.shuttle_crossrange(heating_limit=True)
    print("Betts' shuttle, maximum crossrange with the wing heating limit (Betts 2010, Sec. 6.1):")
    cases["shuttle"] = {"solves": _pair(problem, 81, nlp.initial_guess(problem), 1e-7),
                        "published": published["objective"], "state": "V", "control": "sigma"}
    if not quick:
        problem, settings = load_problem("marv")
        print("paper 002 MARV (eqs. 16-19), seeded by a 60-node solve on one polynomial:")
        seed = nlp.solve(problem, transcription="lgl", solver="snopt", nodes=60, tolerance=1e-6)
        cases["marv"] = {"solves": _pair(problem, 125, seed, settings.tolerance), "published": None,
                         "state": "sigma", "control": "u_sigma"}
    fig, axes = plt.subplots(len(cases), 2, figsize=(12, 4.2 * len(cases)), squeeze=False)
    for row, (name, case) in zip(axes, cases.items()):
        one, seg = case["solves"][1][0], case["solves"][SEGMENTS][0]
        p = one.problem
        i, j = p.state_names.index(case["state"]), p.control_names.index(case["control"])
        t = np.linspace(0.0, one.final_time, 1500)
        for r, style, label in ((one, "-", "one polynomial"), (seg, "--", f"{SEGMENTS} segments")):
            row[0].plot(t, np.degrees(r.control_function()(t)[:, j]), style, label=f"{label} ({r.nodes} nodes)")
            row[1].plot(r.costate_time, r.costates[:, i], style, marker=".", ms=3, label=label)
        for k, (a, b) in enumerate(active_path_spans(one)):
            pad = 0.003 * one.final_time  # a single node's touch shows too
            row[1].axvspan(a - pad, b + pad, color="C3", alpha=0.1, lw=0,
                           label="a path limit active (one polynomial)" if k == 0 else None)
        for ax in row:
            for k, knot in enumerate(seg.time[::(seg.nodes - 1) // SEGMENTS][1:-1]):
                ax.axvline(knot, color="grey", ls=":", lw=0.8, label="knots" if k == 0 else None)
            ax.legend(fontsize=8)
            ax.grid(alpha=0.3)
        row[0].set(xlabel="time [s]", ylabel=f"{case['control']} [deg{'/s' if p.controls == 'rates' else ''}]",
                   title=f"{name}: control {case['control']} along each solution")
        row[1].set(xlabel="time [s]", ylabel=f"lambda_{case['state']} = dJ/d{case['state']} [SI]",
                   title=f"{name}: costate of {case['state']} (eq. 15)")
    fig.suptitle("LGL on one polynomial and in segments: the same controls; in segments the costates oscillate "
                 "node to node on much of the arc where a path limit is active (shaded)", fontsize=10)
    plot = save_figure(fig, out_dir, "segments.png")
    print(f"wrote {plot}")
    return {"cases": cases, "plot": plot}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 18: LGL in segments")
    for name, case in r["cases"].items():
        (one, t_one), (seg, t_seg) = case["solves"][1], case["solves"][SEGMENTS]
        c.check(f"{name}: both solves verified", one.success and seg.success, f"{one.message[:60]} / {seg.message[:60]}")
        c.check(f"{name}: {SEGMENTS} segments take less core time than one polynomial", t_seg < t_one,
                f"{t_seg:.1f} s vs {t_one:.1f} s (ratio {t_seg / t_one:.2f})")
        if case["published"] is not None:
            rel = abs(seg.objective - case["published"]) / abs(case["published"])
            c.check(f"{name}: the segments' objective within 1e-4 of the published optimum", rel <= 1e-4,
                    f"{seg.objective:.8g} vs {case['published']:.8g} ({rel:.1e})")
        else:
            rel = (seg.objective - one.objective) / abs(one.objective)
            c.check(f"{name}: the segments' objective within 0.5 % of one polynomial's", abs(rel) <= 5e-3,
                    f"{seg.objective:.6f} vs {one.objective:.6f} ({rel:+.2%})")
    c.check("the figure was written", os.path.exists(r["plot"]), r["plot"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/18"))
