"""The campaign commands: ``campaign`` (a closed-loop Monte-Carlo campaign of one scenario with
its report), ``report`` (rewrite a campaign directory's report) and ``results`` (every packaged
closed-loop scenario as a campaign, with an index: the documentation's docs/results/)."""
from __future__ import annotations

import json
import os
import sys

from drake_entry.cli.common import Command, add_overrides_argument, add_scenario_argument, parse_overrides

__all__ = ["write_results_index", "COMMANDS", "write_and_print_report"]


def campaign(args) -> int:
    from drake_entry.campaign.montecarlo import run_campaign, run_until_confident

    settings = dict(runs=args.runs, out_dir=args.out, seed=args.seed, workers=args.workers,
                    overrides=parse_overrides(args.overrides), backend=args.backend, scheduler=args.scheduler,
                    trajectory_step_s=args.trajectory_step)
    if args.until_confident:
        out, _ = run_until_confident(args.scenario, max_runs=args.max_runs, **settings)
    else:
        out = run_campaign(args.scenario, **settings)
    stats = write_and_print_report(out)
    required = stats.get("success_requirement")
    where = os.path.join(out, "report.md")
    failures = stats["samples"] - stats["successful"]
    if required is not None and required["status"] != "PASS":
        print(f"drake-entry: the success requirement is not shown: {required['text']} (see {where})", file=sys.stderr)
        # shown not met, a failure flown, or --until-confident stopped short: exit non-zero; OPEN
        # without a failure is a campaign too small to judge, not a failure
        if required["status"] == "FAIL" or failures or args.until_confident:
            return 1
        print("drake-entry: no sample failed; `--until-confident` runs until the requirement is decided",
              file=sys.stderr)
        return 0
    if failures:  # a campaign that shows a failure exits non-zero
        print(f"drake-entry: {failures} of {stats['samples']} samples are not successful (see {where})",
              file=sys.stderr)
        return 1
    return 0


def report(args) -> int:
    from drake_entry.comparison.report import read_comparison_manifest, write_comparison_report

    if os.path.isdir(args.dir) and read_comparison_manifest(args.dir) is not None:  # a comparison's directory
        from drake_entry.cli.comparisons import print_comparison_summary

        path = write_comparison_report(args.dir)
        print_comparison_summary(args.dir)
        print(f"comparison report: {path}")
        return 0
    write_and_print_report(args.dir)
    return 0


def write_and_print_report(out_dir: str) -> dict:
    """Write the report of ``out_dir`` (its scenario as flown, from the manifest), print its
    terminal errors, margins and counts, and return its statistics (summary.json)."""
    from drake_entry.campaign.report import counts_sentence, errors_markdown, flown_scenario, write_report
    from drake_entry.campaign.store import read_manifest

    path = write_report(out_dir)
    with open(os.path.join(out_dir, "summary.json")) as f:
        stats = json.load(f)
    scenario = flown_scenario(read_manifest(out_dir))
    print(errors_markdown(stats, getattr(scenario, "reference_results", None)))
    for k, m in stats["margins"].items():
        print(f"worst {k}: {100 * m['worst']:.2f} % ({m['violations']} violations)")
    c = stats["coverage"]
    print(f"{c['done']}/{c['requested']} samples done: {counts_sentence(stats)}; report: {path}")
    return stats


def _add_campaign_arguments(parser) -> None:
    add_scenario_argument(parser)
    parser.add_argument("--runs", type=int, default=100, help="samples (a larger value extends a finished campaign)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--seed", type=int, default=0, help="campaign seed; sample i is reproducible from (seed, i)")
    parser.add_argument("--out", default="out/campaign", help="campaign directory (re-running resumes it)")
    parser.add_argument("--backend", choices=("processes", "serial", "dask"), default="processes",
                        help="local processes (default), one process, or Dask distributed")
    parser.add_argument("--scheduler", default=None,
                        help="Dask scheduler address (implies --backend dask); a LocalCluster when omitted")
    parser.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                        help="keep each sample's trajectory every SECONDS (0 = none, rows only; the first 5 samples "
                             "every 1 s for the report's bank histories)")
    parser.add_argument("--until-confident", action="store_true",
                        help="run in batches (--runs first) until the scenario's success_requirement is shown "
                             "(PASS) or shown not met (FAIL), or --max-runs are done")
    parser.add_argument("--max-runs", type=int, default=10_000, help="with --until-confident: the most samples "
                                                                     "(default: 10000)")
    add_overrides_argument(parser, "guidance.replan_period_s=100")


def _add_report_arguments(parser) -> None:
    parser.add_argument("dir", help="a campaign directory (finished, running, killed or partial) or a comparison "
                        "directory (drake-entry compare --out)")


def _add_results_arguments(parser) -> None:
    parser.add_argument("--runs", type=int, default=100, help="samples per scenario (default: 100)")
    parser.add_argument("--only", nargs="*", default=None, metavar="SCENARIO",
                        help="these packaged scenarios only (default: every closed-loop one)")
    parser.add_argument("--seed", type=int, default=2018, help="master seed of every campaign (default: 2018)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                        help="trajectory storage step of the campaigns (default: 10)")
    parser.add_argument("--out", default="out/results", help="one campaign directory per scenario below it "
                        "(default: out/results); index.md lists them")


def _provenance(campaign_dir: str) -> tuple[str, str]:
    """(seed, the commits of its sessions, short, '+changes' kept) of a campaign directory."""
    try:
        with open(os.path.join(campaign_dir, "campaign.json")) as f:
            record = json.load(f)
    except (OSError, ValueError):
        return "—", "not recorded"
    commits = list(dict.fromkeys((s.get("git_commit") or "not recorded") for s in record.get("sessions", [])))
    short = [c if c == "not recorded" else c[:7] + ("+changes" if c.endswith("+changes") else "") for c in commits]
    return str(record.get("seed", "—")), ", ".join(short) or "not recorded"


def write_results_index(out_dir: str) -> str:
    """index.md of every packaged closed-loop scenario's campaign directory below ``out_dir`` (those
    of earlier runs with --only too): runs, successes, the 90 % lower bound, the scenario's
    required success probability with its verdict (PASS, OPEN with the further runs that would
    show it, or FAIL), seed and commit, a link to each report; returns its path."""
    from drake_entry.campaign.success_requirement import MAX_RUNS
    from drake_entry.scenario import closed_loop_scenarios

    lines = ["# Campaign results", "",
             "Packaged closed-loop scenarios flown as Monte-Carlo campaigns (`drake-entry publish` regenerates "
             "every one from a committed tree; `drake-entry results` flies them into any directory). Each "
             "directory holds report.md (and report.html, self-contained), its figures, summary.json and "
             "campaign.json; each report states its command, runs, seed and commit. The required success "
             "probability is the scenario's `success_requirement`: PASS when the one-sided Clopper-Pearson lower "
             "bound reaches it, FAIL when the upper bound is below it, OPEN otherwise (with the further runs, "
             "every one successful, that would show it). Each `NAME_flight` is the flight-like twin of `NAME`: the "
             "same mission and method in a flight-like environment (docs/campaigns.md, flight-like twins).", "",
             "| scenario | runs | successful | success probability, 90 % lower bound | required | verdict | seed "
             "| commit | report |", "|---|---|---|---|---|---|---|---|---|"]
    absent = []
    for name in closed_loop_scenarios():
        directory = os.path.join(out_dir, name)
        summary = os.path.join(directory, "summary.json")
        if not os.path.isfile(summary):
            absent.append(f"`{name}`")
            continue
        with open(summary) as f:
            stats = json.load(f)
        seed, commits = _provenance(directory)
        req = stats.get("success_requirement")
        if req is None:
            required, verdict = "none stated", "—"
        else:
            required = f"{100 * req['probability']:g} % at {100 * req['confidence']:g} %"
            verdict = {"PASS": "**PASS**", "FAIL": "**FAIL**"}.get(req["status"], "OPEN")
            if req["status"] == "OPEN":
                verdict += (f": {req['more_runs']} more successful runs would show it" if req.get("more_runs")
                            else f": not within {MAX_RUNS:.0e} runs")
        lines.append(f"| `{name}` | {stats['samples']} | {stats['successful']} | "
                     f"{100 * stats['success_lower_bound']['0.9']:.2f} % | {required} | {verdict} | {seed} | "
                     f"{commits} | [report]({name}/report.md) |")
    if absent:
        lines += ["", f"Not flown in this directory: {', '.join(absent)}."]
    path = os.path.join(out_dir, "index.md")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def results(args) -> int:
    from drake_entry.campaign.montecarlo import run_campaign
    from drake_entry.campaign.report import write_report
    from drake_entry.errors import ScenarioError
    from drake_entry.scenario import closed_loop_scenarios

    names = closed_loop_scenarios()
    chosen = names if not args.only else args.only
    unknown = [n for n in chosen if n not in names]
    if unknown:
        raise ScenarioError(f"--only {' '.join(unknown)}: not a packaged closed-loop scenario; "
                            f"allowed: {', '.join(names)}")
    os.makedirs(args.out, exist_ok=True)
    failed = 0
    for name in chosen:
        print(f"== {name}: {args.runs} runs", flush=True)
        out = run_campaign(name, runs=args.runs, out_dir=os.path.join(args.out, name), seed=args.seed,
                           workers=args.workers, trajectory_step_s=args.trajectory_step)
        path = write_report(out)
        with open(os.path.join(out, "summary.json")) as f:
            stats = json.load(f)
        failed += stats["successful"] < stats["samples"]
        print(f"   {stats['successful']} of {stats['samples']} successful; report: {path}", flush=True)
    print(f"wrote {write_results_index(args.out)}")
    if failed:
        print(f"drake-entry: {failed} scenario(s) with samples that are not successful (see their reports)",
              file=sys.stderr)
    return 1 if failed else 0


COMMANDS = (Command("campaign", "closed-loop Monte-Carlo campaign with a report", _add_campaign_arguments, campaign),
            Command("report", "write the report (report.md, report.html) of a campaign or comparison directory",
                    _add_report_arguments, report),
            Command("results", "every packaged closed-loop scenario as a Monte-Carlo campaign with its report",
                    _add_results_arguments, results))
