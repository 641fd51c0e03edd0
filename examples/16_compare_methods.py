"""Example 16: every guidance method on one mission, the same dispersions and seeds, one report.

Flies the packaged comparison ``horus2b`` (paper 000's HORUS-2B mission: each method's
settings for it, or why it cannot fly it, are in drake_entry/comparisons/horus2b.yaml) as one
Monte-Carlo campaign per method with the same seed, so sample i of every method draws the same
entry dispersions, and writes one report: success, inside the box and within the limits with
Clopper-Pearson intervals, terminal errors, path-limit margins, control activity, planning time
and core seconds per sample, overlaid footprints.

    python examples/16_compare_methods.py [--quick] [--runs N] [--out out/examples/16]

The command-line equivalent is ``drake-entry compare horus2b --runs 20 --seed 2026``.
--quick flies two methods (drag-energy and the fixed bank profile) on 2 samples each.
"""
import json
import os

from drake_entry.claims import Claims, run_example
from drake_entry.comparison.report import summary_text
from drake_entry.comparison.runner import run_comparison
from drake_entry.comparison.spec import load_comparison

SEED = 2026


def main(quick: bool = False, out_dir: str = "out/examples/16", runs: int = 20) -> dict:
    comparison = load_comparison("horus2b")
    only = ["drag_energy", "bank_profile"] if quick else None
    runs = 2 if quick else runs
    report = run_comparison(comparison, runs=runs, out_dir=out_dir, seed=SEED, only=only)
    with open(os.path.join(out_dir, "comparison_summary.json")) as f:
        summary = json.load(f)
    print("\n" + summary_text(summary))
    print(f"report: {report}")
    return {"summary": summary, "report": report, "quick": quick, "runs": runs}


def check(r: dict, quick: bool = False) -> Claims:
    c = Claims("example 16: every method on HORUS-2B")
    s, n = r["summary"], r["runs"]
    c.check("every method flew the same dispersions (sample i identical across methods)",
            s["same_dispersions"] and s["samples_compared"] == n, f"{s['samples_compared']} samples compared")
    de = s["methods"]["drag_energy"]
    c.check("the mission's own method (drag-energy, paper 000) succeeds on every sample", de["successful"] == n,
            f"{de['successful']} of {n}")
    bp = s["methods"]["bank_profile"]
    c.check("the fixed bank profile (no range feedback) misses the 2-km box on every sample", bp["successful"] == 0
            and bp["miss_km"]["median"] > 2.0, f"miss median {bp['miss_km']['median']:.1f} km")
    if not quick:
        flown = [label for label in s["methods"]]
        c.check("every method the comparison flies has a campaign", len(flown) == 4, ", ".join(flown))
    c.check("the report is written", os.path.exists(r["report"]), r["report"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/16",
                                 quick="two methods, 2 samples each",
                                 options=[("--runs", {"type": int, "default": 20, "help": "samples per method (default: 20)"})]))
