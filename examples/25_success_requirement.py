"""Example 25: a required success probability, shown by running until confident.

A mission states the success probability its campaign must show and at what confidence, in its
scenario file (here HORUS-2B with paper 000's drag-energy guidance, ``based_on: horus2b``):

    success_requirement: {probability: 0.99, confidence: 0.9}

``drake-entry campaign SCENARIO --runs 50 --until-confident`` (the Python call below,
``run_until_confident``) flies 50 runs, judges the one-sided Clopper-Pearson bounds on the success
probability, and, while neither the lower bound reaches 99 % (PASS) nor the upper bound falls
below it (FAIL), flies the further runs that would show it were every one successful (at most as
many again as are done). With no failure 99 % at 90 % needs 230 runs (0.99^230 <= 0.1). The
report's requirement table and headline give the verdict; the figure shows both bounds against
the runs with the required probability.

    python examples/25_success_requirement.py [--quick] [--out out/examples/25]

--quick asks 50 % at 90 % from 2 runs (4 runs show it).
"""
import json
import os

import numpy as np

from drake_entry.campaign.montecarlo import run_until_confident
from drake_entry.campaign.rows import row_problem
from drake_entry.campaign.statistics import running_estimates
from drake_entry.campaign.store import coverage
from drake_entry.campaign.success_requirement import runs_to_show
from drake_entry.claims import Claims, run_example
from drake_entry.cli.campaigns import write_and_print_report
from drake_entry.figures import plt, save_figure

SEED = 2026


def write_scenario(folder: str, probability: float, confidence: float) -> str:
    """The mission file a user writes: HORUS-2B as packaged, with the required success probability."""
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "horus2b_required.yaml")
    with open(path, "w") as f:
        f.write("based_on: horus2b\nname: horus2b_required\n"
                f"success_requirement: {{probability: {probability}, confidence: {confidence}}}\n")
    return path


def bound_history(out_dir: str, confidence: float) -> dict:
    """The success fraction and its bounds over the first n samples (in sample order), n on a
    fine grid (campaign.statistics.running_estimates)."""
    rows = coverage(out_dir, row_problem)["rows"]
    return running_estimates([bool(rows[i].get("success")) for i in sorted(rows)], {}, level=confidence, points=400)


def main(quick: bool = False, out_dir: str = "out/examples/25") -> dict:
    probability, confidence, runs = (0.5, 0.9, 2) if quick else (0.99, 0.9, 50)
    scenario = write_scenario(os.path.join(out_dir, "mission"), probability, confidence)
    campaign = os.path.join(out_dir, "campaign")
    print(f"drake-entry campaign {scenario} --runs {runs} --until-confident --seed {SEED}")
    _, verdict = run_until_confident(scenario, runs=runs, max_runs=2000, out_dir=campaign, seed=SEED, workers=2,
                                     trajectory_step_s=0.0)
    stats = write_and_print_report(campaign)
    est = bound_history(campaign, confidence)
    n, fraction, lower, upper = (np.asarray(est[k], float) for k in ("n", "fraction", "lower", "upper"))

    fig, ax = plt.subplots(figsize=(8, 4.2))
    ax.plot(n, 100 * lower, "C0-", lw=1.2, label=f"lower bound ({100 * confidence:g} %, one-sided)")
    ax.plot(n, 100 * upper, "C1-", lw=1.2, label=f"upper bound ({100 * confidence:g} %, one-sided)")
    ax.plot(n, 100 * fraction, "k:", lw=0.8, label="observed success fraction")
    ax.axhline(100 * probability, color="r", ls="--", lw=1.2, label=f"required {100 * probability:g} %")
    ax.axvline(verdict.runs, color="0.4", ls=":", lw=1.0, label=f"stopped: {verdict.status} at {verdict.runs} runs")
    # zoomed on the requirement: ten times its failure allowance below it
    ax.set(xlabel="runs", ylabel="success probability [%]", xlim=(1, n[-1] * 1.02),
           ylim=(max(0.0, 100 * (probability - 10 * (1 - probability))), 100.3))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    path = save_figure(fig, out_dir, "success_bounds.png",
                       title=f"HORUS-2B, drag-energy guidance: the success probability's bounds against the runs "
                             f"({verdict.status})",
                       caption=f"Look at: PASS where the lower bound crosses the red line ({verdict.runs} runs here; "
                               f"axis zoomed on it); a failure drops both bounds.")
    return {"verdict": verdict, "stats": stats, "runs_first": runs, "plot": path, "campaign": campaign,
            "summary": json.load(open(os.path.join(campaign, "summary.json")))}


def check(r: dict, quick: bool = False) -> Claims:
    c = Claims("example 25: a required success probability, run until confident")
    v, s = r["verdict"], r["stats"]
    failures = v.runs - v.successes
    c.check("the requirement is shown: the lower bound reaches the required probability (PASS)",
            v.status == "PASS" and v.lower >= v.probability, v.text())
    c.check("the campaign stopped at the fewest runs that show it with its failures",
            v.runs == runs_to_show(failures, v.probability, v.confidence), f"{v.runs} runs, {failures} failures")
    c.check("it flew more than its first batch (it ran until confident)", v.runs > r["runs_first"],
            f"{r['runs_first']} first, {v.runs} in all")
    c.check("the report's summary carries the verdict", r["summary"].get("success_requirement", {}).get("status")
            == "PASS" and s["samples"] == v.runs, r["summary"].get("success_requirement", {}).get("text", "missing"))
    c.check("the figure is written", os.path.exists(r["plot"]), r["plot"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/25", quick="50 % at 90 % from 2 runs"))
