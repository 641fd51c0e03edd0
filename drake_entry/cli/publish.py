"""The publish command: every result the documentation shows, regenerated in one command from a
committed tree (docs/results):

- ``OUT/campaigns/<scenario>``: every packaged closed-loop scenario (the papers' and their
  flight-like twins) as a Monte-Carlo campaign with its report, and ``OUT/campaigns/index.md``;
- ``OUT/compare/<mission>``: every method on each matrix mission (``drake-entry compare MISSION``,
  settings derived from the mission), and ``OUT/matrix.md`` with ``OUT/derivations/`` (with
  ``--missions`` naming some, the other missions' rows are carried from the matrix already there,
  marked so: the matrix is regenerated mission by mission);
- ``OUT/published.json``: the commit, the sizes, seeds and wall time of every part.

It refuses a source tree with uncommitted changes (or not a git checkout): a published figure
names the commit that made it (``--allow-changes`` publishes anyway; the reports then say
'+changes'). Every campaign and comparison resumes where an earlier run of the command left it, so
a killed run loses nothing and a larger ``--runs`` extends it.
"""
from __future__ import annotations

import datetime
import json
import os
import time

from drake_entry.cli.common import Command
from drake_entry.errors import DrakeEntryError

__all__ = ["COMMANDS", "MATRIX_MISSIONS", "publish_results", "committed_source"]

#: the missions of the mission x method matrix (the papers' packaged missions)
MATRIX_MISSIONS = ("horus2b", "cav_h_fnpeg", "cav_h_paper004", "capsule_lu2008", "shefex3_ampi", "sphynx_paper001",
                   "marv_guidance")
#: the seeds the documentation's results use (campaigns; comparisons)
CAMPAIGN_SEED, COMPARISON_SEED = 2018, 2026


def committed_source(allow_changes: bool) -> str:
    """The commit of the drake_entry source tree; DrakeEntryError when it has uncommitted
    changes, runs with another checkout's systems/ or diagrams/ (engine.foreign_sources) or is
    not a git checkout, unless ``allow_changes``."""
    import drake_entry
    from drake_entry.campaign.engine import foreign_sources, source_commit

    commit = source_commit()
    if allow_changes or (commit is not None and not commit.endswith("+changes")):
        return commit or "not a git checkout"
    if commit is None:
        raise DrakeEntryError("publish: the drake_entry source tree is not a git checkout (an installed wheel: publish "
                              "from a clone, `pip install -e .`), or pass --allow-changes")
    top = os.path.dirname(os.path.dirname(os.path.abspath(drake_entry.__file__)))
    foreign = foreign_sources(top)
    if foreign:
        raise DrakeEntryError(f"publish: drake_entry is imported from {top} but {' and '.join(foreign)} (another "
                              f"checkout's install), so no one commit names the code: install this checkout in its "
                              f"own environment (`pip install -e {top}`), or pass --allow-changes")
    raise DrakeEntryError(f"publish: the drake_entry source tree has uncommitted changes ({commit}); commit first, so "
                          "that every published report names the commit that made it, or pass --allow-changes")


def _checked(names, allowed, flag: str) -> list[str]:
    unknown = [n for n in names if n not in allowed]
    if unknown:
        raise DrakeEntryError(f"{flag} {' '.join(unknown)}: not one of {', '.join(allowed)}")
    return list(names)


def publish_results(out: str, *, runs: int, comparison_runs: int, campaigns=None, missions=None,
                    workers: int | None = None, allow_changes: bool = False, trajectory_step_s: float = 10.0,
                    scheduler: str | None = None) -> dict:
    """Regenerate the results below ``out`` (module doc): ``campaigns`` and ``missions`` name
    subsets (None: all; []: none); ``scheduler``: the address of a Dask cluster that flies the
    samples (None: ``workers`` local processes). Returns the published.json record."""
    from drake_entry.campaign.montecarlo import run_campaign
    from drake_entry.campaign.report import write_report
    from drake_entry.cli.campaigns import write_results_index
    from drake_entry.comparison.matrix import write_matrix
    from drake_entry.comparison.runner import run_comparison
    from drake_entry.comparison.spec import mission_comparison
    from drake_entry.scenario import closed_loop_scenarios

    commit = committed_source(allow_changes)
    every = closed_loop_scenarios()
    campaigns = every if campaigns is None else _checked(campaigns, every, "--campaigns")
    missions = list(MATRIX_MISSIONS) if missions is None else _checked(missions, MATRIX_MISSIONS, "--missions")
    if runs < 1 or comparison_runs < 1:
        raise DrakeEntryError(f"publish: --runs {runs} and --comparison-runs {comparison_runs}: allowed >= 1")
    where = {"scheduler": scheduler} if scheduler else {}  # an address implies the Dask backend
    started, t0 = datetime.datetime.now(datetime.timezone.utc), time.perf_counter()
    record = {"commit": commit, "started_utc": started.isoformat(timespec="seconds"), "campaign_runs": runs,
              "campaign_seed": CAMPAIGN_SEED, "comparison_runs": comparison_runs, "comparison_seed": COMPARISON_SEED,
              "samples_flown_on": f"Dask cluster {scheduler}" if scheduler else "local processes",
              "campaigns": {}, "comparisons": {}}
    folder = os.path.join(out, "campaigns")
    os.makedirs(folder, exist_ok=True)
    for name in campaigns:
        t = time.perf_counter()
        print(f"== campaign {name}: {runs} runs", flush=True)
        path = run_campaign(name, runs=runs, out_dir=os.path.join(folder, name), seed=CAMPAIGN_SEED, workers=workers,
                            trajectory_step_s=trajectory_step_s, **where)
        write_report(path)
        with open(os.path.join(path, "summary.json")) as f:
            stats = json.load(f)
        record["campaigns"][name] = {"runs": stats["samples"], "successful": stats["successful"],
                                     "wall_s": round(time.perf_counter() - t, 1)}
        print(f"   {stats['successful']} of {stats['samples']} successful", flush=True)
    if campaigns:
        write_results_index(folder)
    folders = []
    for name in missions:
        t = time.perf_counter()
        print(f"== every method on {name}: {comparison_runs} runs each", flush=True)
        directory = os.path.join(out, "compare", name)
        run_comparison(mission_comparison(name), runs=comparison_runs, out_dir=directory,
                       seed=COMPARISON_SEED, workers=workers, trajectory_step_s=trajectory_step_s, **where)
        with open(os.path.join(directory, "comparison_summary.json")) as f:
            summary = json.load(f)
        record["comparisons"][name] = {
            "methods": {label: f"{s['successful']} of {s['samples']}" for label, s in summary["methods"].items()},
            "not_flown": sorted(summary["not_flown"]), "wall_s": round(time.perf_counter() - t, 1)}
        folders.append(directory)
    if folders:
        record["matrix"] = os.path.relpath(write_matrix(folders, os.path.join(out, "matrix.md")), out)
    record["finished_utc"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    record["wall_s"] = round(time.perf_counter() - t0, 1)
    with open(os.path.join(out, "published.json"), "w") as f:
        json.dump(record, f, indent=2)
    return record


def _add_publish_arguments(parser) -> None:
    parser.add_argument("--runs", type=int, default=1000, help="samples per packaged scenario's campaign")
    parser.add_argument("--comparison-runs", type=int, default=100, help="samples per method and mission")
    parser.add_argument("--campaigns", nargs="*", default=None, metavar="SCENARIO",
                        help="these packaged closed-loop scenarios only (given with no name: none)")
    parser.add_argument("--missions", nargs="*", default=None, metavar="MISSION",
                        help=f"these matrix missions only ({', '.join(MATRIX_MISSIONS)}; given with no name: none)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument("--scheduler", default=None,
                        help="address of a running Dask scheduler (e.g. tcp://host:8786, a dask-jobqueue cluster's) "
                             "that flies the samples; searches and plans stay here (default: local processes)")
    parser.add_argument("--allow-changes", action="store_true",
                        help="publish from a tree with uncommitted changes (the reports say '+changes')")
    parser.add_argument("--out", default=os.path.join("docs", "results"), help="the results directory")


def publish(args) -> int:
    record = publish_results(args.out, runs=args.runs, comparison_runs=args.comparison_runs, campaigns=args.campaigns,
                             missions=args.missions, workers=args.workers, allow_changes=args.allow_changes,
                             scheduler=args.scheduler)
    print(f"published at commit {record['commit']} in {record['wall_s']:.0f} s: "
          f"{len(record['campaigns'])} campaigns, {len(record['comparisons'])} comparisons; "
          f"{os.path.join(args.out, 'published.json')}")
    return 0


COMMANDS = (Command("publish", "every result the documentation shows (docs/results), regenerated from a committed "
                    "tree: each packaged scenario's campaign, every method on each mission, the matrix",
                    _add_publish_arguments, publish),)
