"""The comparison command: ``compare`` flies several guidance methods on one mission with the same
dispersions and seeds and writes one report (drake_entry.comparison)."""
from __future__ import annotations

import json
import os
import sys

from drake_entry.cli.common import Command

__all__ = ["COMMANDS", "print_comparison_summary"]


def _add_compare_arguments(parser) -> None:
    from drake_entry.comparison.spec import PACKAGED_COMPARISONS

    parser.add_argument("comparison", help=f"a packaged comparison ({', '.join(PACKAGED_COMPARISONS)}), a comparison "
                        "YAML file (docs/comparisons.md), or a mission alone (a packaged scenario or a scenario file): "
                        "every method, its settings derived from the mission")
    parser.add_argument("--runs", type=int, default=20, help="dispersed samples per method (default: 20)")
    parser.add_argument("--seed", type=int, default=2026, help="seed of every method's campaign (default: 2026)")
    parser.add_argument("--only", nargs="*", default=None, metavar="LABEL",
                        help="fly these methods only (the others keep what an earlier run left)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                        help="trajectory storage step of the campaigns (default: 10)")
    parser.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler that flies the samples (searches and plans stay "
                             "here; default: local processes)")
    parser.add_argument("--out", default=None, help="comparison directory (default: out/compare/<name>)")


def compare(args) -> int:
    from drake_entry.comparison.runner import run_comparison
    from drake_entry.comparison.spec import load_comparison_or_mission

    comparison = load_comparison_or_mission(args.comparison)
    out = args.out or os.path.join("out", "compare", comparison.name)
    path = run_comparison(comparison, runs=args.runs, out_dir=out, seed=args.seed, workers=args.workers,
                          only=args.only, trajectory_step_s=args.trajectory_step, scheduler=args.scheduler)
    failed, flown = print_comparison_summary(out)
    print(f"report: {path}")
    if not flown:
        print("drake-entry: no method flew this mission (each one's reason is above and in the report)",
              file=sys.stderr)
        return 1
    if failed:
        print(f"drake-entry: {failed} method(s) with samples that are not successful (see the report)", file=sys.stderr)
    return 1 if failed else 0


def print_comparison_summary(out: str) -> tuple[int, int]:
    """Print each method's count of successful samples and each not-flown method's reason from
    ``out``'s comparison_summary.json; return (methods with an unsuccessful sample, methods flown)."""
    with open(os.path.join(out, "comparison_summary.json")) as f:
        summary = json.load(f)
    failed = 0
    for label, s in summary["methods"].items():
        failed += s["successful"] < s["samples"]
        print(f"   {label}: {s['successful']} of {s['samples']} successful")
    for label, reason in summary["not_flown"].items():
        print(f"   {label}: not flown ({reason.split(';')[0][:100]})")
    return failed, len(summary["methods"])


def _add_matrix_arguments(parser) -> None:
    parser.add_argument("folders", nargs="+", metavar="DIR", help="comparison directories (drake-entry compare --out)")
    parser.add_argument("--out", default=os.path.join("out", "compare"),
                        help="directory of the Markdown file written, matrix.md (default: out/compare); the rows of "
                             "missions not among DIR are kept from a matrix.md already there, marked carried")


def matrix(args) -> int:
    from drake_entry.comparison.matrix import write_matrix

    os.makedirs(args.out, exist_ok=True)
    path = write_matrix(args.folders, os.path.join(args.out, "matrix.md"))
    print(open(path).read())
    print(f"wrote {path}")
    return 0


COMMANDS = (Command("compare", "several guidance methods on one mission, the same dispersions and seeds: one report",
                    _add_compare_arguments, compare),
            Command("matrix", "the mission x method matrix of several comparison directories: one Markdown table",
                    _add_matrix_arguments, matrix))
