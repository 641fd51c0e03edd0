"""``drake-entry results``: every packaged closed-loop scenario flown as a Monte-Carlo campaign
with its report, into one directory (the documentation's docs/results/ is made by it). CLI
layer (it runs diagrams)."""
from __future__ import annotations

import json
import os
import sys

from drake_entry.cli import Command, closed_loop_scenarios


def add_arguments(parser) -> None:
    parser.add_argument("--runs", type=int, default=100, help="samples per scenario (default: 100)")
    parser.add_argument("--only", nargs="*", default=None, metavar="SCENARIO",
                        help="these packaged scenarios only (default: every closed-loop one)")
    parser.add_argument("--seed", type=int, default=2018, help="master seed of every campaign (default: 2018)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                        help="trajectory storage step of the campaigns (default: 10)")
    parser.add_argument("--out", default="out/results", help="one campaign directory per scenario below it "
                        "(default: out/results); index.md lists them")


def run(args) -> int:
    from drake_entry.campaign.report import write_report
    from drake_entry.diagrams.montecarlo import run_campaign
    from drake_entry.errors import ScenarioError

    names = closed_loop_scenarios()
    chosen = names if not args.only else args.only
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise ScenarioError(f"--only {' '.join(unknown)}: not a packaged closed-loop scenario; "
                            f"allowed: {', '.join(names)}")
    os.makedirs(args.out, exist_ok=True)
    lines = ["# Campaign results", "",
             f"Every packaged closed-loop scenario flown as a Monte-Carlo campaign ({args.runs} runs, seed "
             f"{args.seed}) by `drake-entry results --runs {args.runs} --seed {args.seed}`; each directory holds "
             "report.md (and report.html, self-contained), its figures, summary.json and campaign.json.", "",
             "| scenario | successful | success probability, 90 % lower bound | report |", "|---|---|---|---|"]
    failed = 0
    for name in chosen:
        print(f"== {name}: {args.runs} runs", flush=True)
        out = run_campaign(name, runs=args.runs, out_dir=os.path.join(args.out, name), seed=args.seed,
                           workers=args.workers, trajectory_step_s=args.trajectory_step)
        path = write_report(out)
        with open(os.path.join(out, "summary.json")) as f:
            stats = json.load(f)
        ok, n = stats["successful"], stats["samples"]
        failed += ok < n
        lines.append(f"| `{name}` | {ok} of {n} | {100 * stats['success_lower_bound']['0.9']:.2f} % | "
                     f"[report]({name}/report.md) |")
        print(f"   {ok} of {n} successful; report: {path}", flush=True)
    with open(os.path.join(args.out, "index.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {os.path.join(args.out, 'index.md')}")
    if failed:
        print(f"drake-entry: {failed} scenario(s) with samples that are not successful (see their reports)",
              file=sys.stderr)
    return 1 if failed else 0


def add_compare_arguments(parser) -> None:
    from drake_entry.comparison import PACKAGED_COMPARISONS

    parser.add_argument("comparison", help=f"a packaged comparison ({', '.join(PACKAGED_COMPARISONS)}) or a comparison "
                        "YAML file (docs/campaigns.md, 'Comparing methods')")
    parser.add_argument("--runs", type=int, default=20, help="dispersed samples per method (default: 20)")
    parser.add_argument("--seed", type=int, default=2026, help="seed of every method's campaign (default: 2026)")
    parser.add_argument("--only", nargs="*", default=None, metavar="LABEL",
                        help="fly these methods only (the others keep what an earlier run left)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                        help="trajectory storage step of the campaigns (default: 10)")
    parser.add_argument("--out", default=None, help="comparison directory (default: out/compare/<name>)")


def run_compare(args) -> int:
    from drake_entry.comparison import load_comparison
    from drake_entry.diagrams.comparison import run_comparison

    comparison = load_comparison(args.comparison)
    out = args.out or os.path.join("out", "compare", comparison.name)
    path = run_comparison(comparison, runs=args.runs, out_dir=out, seed=args.seed, workers=args.workers,
                          only=args.only, trajectory_step_s=args.trajectory_step)
    with open(os.path.join(out, "comparison_summary.json")) as f:
        summary = json.load(f)
    failed = 0
    for label, s in summary["methods"].items():
        failed += s["successful"] < s["samples"]
        print(f"   {label}: {s['successful']} of {s['samples']} successful")
    for label, reason in summary["not_flown"].items():
        print(f"   {label}: not flown ({reason.split(';')[0][:100]})")
    print(f"report: {path}")
    if failed:
        print(f"drake-entry: {failed} method(s) with samples that are not successful (see the report)", file=sys.stderr)
    return 1 if failed else 0


COMMANDS = (Command("results", "every packaged closed-loop scenario as a Monte-Carlo campaign with its report",
                    add_arguments, run),
            Command("compare", "several guidance methods on one mission, the same dispersions and seeds: one report",
                    add_compare_arguments, run_compare))
