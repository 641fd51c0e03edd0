"""drake-entry: plan, fly and analyse atmospheric-entry trajectories on Drake.

Commands:
  scenarios [NAME]    the packaged scenarios (name, guidance method, vehicle, description), or one
                      scenario's YAML file with its comments
  campaign SCENARIO   closed-loop Monte-Carlo campaign (Drake RandomSimulation) with a report;
                      exit 1 when a sample is not successful
  report DIR          (re)write the report (report.md, report.html) of a campaign directory
  fly SCENARIO        one closed-loop guided flight with plots
  plan SCENARIO       the guidance method's reference plan, flown by Drake, with its figures
                      (drag-energy, SCvx, AMPI and swarm-bank methods)
  simulate SCENARIO   fly the open-loop diagram; write the trajectory and PNG plots
and the commands the methods and shared packages contribute (their commands.py modules), e.g.
  optimize PROBLEM    optimal reference by the NLP path (paper 002), verified and flown by Drake
  results             every packaged closed-loop scenario as a campaign with its report
  fit-horus           refit the HORUS-2B aero forms (paper 000 eqs. 32-33); print residuals

Benchmarks are scripts, not commands: python benchmarks/run.py (see README).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Callable, NamedTuple

import numpy as np

from drake_entry.errors import DrakeEntryError, Interrupted, ScenarioError


def _cmd_simulate(args) -> int:
    from drake_entry.campaign.plots import trajectory_plots
    from drake_entry.campaign.tables import write_table
    from drake_entry.diagrams.open_loop import simulate
    from drake_entry.models.trajectory import metrics
    from drake_entry.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    tr = simulate(scenario)
    os.makedirs(args.out, exist_ok=True)
    path = write_table(tr.table(), os.path.join(args.out, f"trajectory.{args.format}"))
    vehicle = scenario.make_vehicle()
    pngs = trajectory_plots(tr, args.out, limits=vehicle.limits,
                            target=(scenario.target.longitude_deg, scenario.target.latitude_deg),
                            title=f"{scenario.name}: open loop")
    planet = scenario.make_planet()
    x = tr.state[-1]
    dist = planet.great_circle_distance(x[1], x[2], np.radians(scenario.target.longitude_deg),
                                        np.radians(scenario.target.latitude_deg))
    summary = {
        "scenario": scenario.name, "stop": tr.reason, "flight_time_s": float(tr.time[-1]),
        "final_altitude_km": float(x[0] / 1e3), "final_mach": float(tr.column("mach")[-1]),
        "distance_to_target_km": float(dist / 1e3), **metrics(tr, vehicle.limits), "wall_time_s": tr.wall_time,
    }
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    for k, v in summary.items():
        print(f"{k:28s} {v:.6g}" if isinstance(v, float) else f"{k:28s} {v}")
    print(f"wrote {path} and {len(pngs)} plots to {args.out}")
    return 0


def _cmd_fly(args) -> int:
    from drake_entry.campaign.plots import trajectory_plots
    from drake_entry.campaign.tables import write_table
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
    from drake_entry.diagrams.sample import campaign_row
    from drake_entry.scenario import apply_overrides, load_scenario

    scenario = load_scenario(args.scenario)
    apply_overrides(scenario, parse_overrides(args.overrides))
    setup = ClosedLoopSetup.from_scenario(scenario)
    res = fly(setup)
    tr = res.trajectory
    os.makedirs(args.out, exist_ok=True)
    write_table(tr.table(), os.path.join(args.out, f"trajectory.{args.format}"))
    title = f"{scenario.name}: closed loop ({res.method})"
    trajectory_plots(tr, args.out, limits=setup.vehicle.limits,
                     target=(scenario.target.longitude_deg, scenario.target.latitude_deg), title=title)
    setup.method.flight_plots(res, args.out, title=scenario.name)
    summary = {**campaign_row(res, setup), "wall_time_s": tr.wall_time}  # the row a campaign would record
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2, default=float)
    for k, v in summary.items():
        print(f"{k:28s} {v:.6g}" if isinstance(v, float) else f"{k:28s} {v}")
    print(f"wrote trajectory, summary and plots to {args.out}")
    return 0 if res.success else 1


def _cmd_plan(args) -> int:
    import importlib

    from drake_entry.guidance import REGISTRY, method_for
    from drake_entry.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    package = REGISTRY[type(scenario.guidance)].rpartition(".")[0]
    try:  # a method's CLI commands live beside it (docs/architecture.md)
        commands = importlib.import_module(f"{package}.commands")
    except ModuleNotFoundError as e:
        if e.name != f"{package}.commands":  # a missing import inside the module is a bug: raise it
            raise
        print(f"drake-entry: guidance method '{method_for(scenario.guidance).name}' has no plan report",
              file=sys.stderr)
        return 2
    return commands.plan_report(scenario, args.out)


def packaged_scenarios() -> list[str]:
    """The packaged scenario names (the YAML files of drake_entry/scenarios, read without
    importing the scenario schema)."""
    from importlib import resources

    return sorted(p.name[:-5] for p in resources.files("drake_entry").joinpath("scenarios").iterdir()
                  if p.name.endswith(".yaml"))


def closed_loop_scenarios() -> list[str]:
    """The packaged scenarios that declare a guidance method (a ``guidance:`` block): those a
    campaign can fly."""
    from importlib import resources

    folder = resources.files("drake_entry").joinpath("scenarios")
    return [n for n in packaged_scenarios() if any(line.startswith("guidance:")
                                                   for line in folder.joinpath(f"{n}.yaml").read_text().splitlines())]


def _cmd_scenarios(args) -> int:
    from importlib import resources

    from drake_entry.scenario import load_scenario

    names = packaged_scenarios()
    if args.name is not None:
        if args.name not in names:
            raise ScenarioError(f"scenario '{args.name}' is not packaged; packaged: {', '.join(names)}")
        print(resources.files("drake_entry").joinpath(f"scenarios/{args.name}.yaml").read_text(), end="")
        return 0
    rows = []
    closed = closed_loop_scenarios()
    for name in names:
        scenario = load_scenario(name)
        method = f"!{type(scenario.guidance).__name__}" if name in closed else "open loop (simulate)"
        rows.append((name, method, scenario.vehicle, scenario.description))
    widths = [max(len(r[i]) for r in rows + [("name", "guidance", "vehicle", "")]) for i in range(3)]
    print(f"{'name':{widths[0]}}  {'guidance':{widths[1]}}  {'vehicle':{widths[2]}}  description")
    for r in rows:
        print(f"{r[0]:{widths[0]}}  {r[1]:{widths[1]}}  {r[2]:{widths[2]}}  {r[3]}")
    print("\n`drake-entry scenarios NAME` prints one with its comments; a scenario YAML file of your own works "
          "wherever a name does.")
    return 0


def _version() -> str:
    import importlib.metadata

    import drake_entry

    try:
        drake = importlib.metadata.version("drake")
    except importlib.metadata.PackageNotFoundError:
        drake = "not installed"
    return f"drake-entry {drake_entry.__version__} (Drake {drake}, Python {sys.version.split()[0]})"


def _cmd_campaign(args) -> int:
    from drake_entry.diagrams.montecarlo import run_campaign

    backend = "dask" if args.scheduler else args.backend
    out = run_campaign(args.scenario, runs=args.runs, out_dir=args.out, seed=args.seed, workers=args.workers,
                       overrides=parse_overrides(args.overrides), backend=backend, scheduler=args.scheduler,
                       trajectory_step_s=args.trajectory_step)
    stats = _write_and_print_report(out)
    if stats["successful"] < stats["samples"]:  # a campaign that shows a failure exits non-zero
        print(f"drake-entry: {stats['samples'] - stats['successful']} of {stats['samples']} samples are not "
              f"successful (see {os.path.join(out, 'report.md')})", file=sys.stderr)
        return 1
    return 0


def check_output_dir(out: str) -> None:
    """Refuse an output directory that cannot be made or written before any work starts: a
    file on its path, a read-only or forbidden place (one line naming it)."""
    if not out or not out.strip():
        raise ScenarioError("--out is empty; give a directory")
    if "\0" in out:
        raise ScenarioError(f"--out {out!r} contains a NUL character; give a directory path")
    parent = os.path.normpath(out)  # 'a_file/' names the file too
    if os.path.exists(parent) and not os.path.isdir(parent):
        raise ScenarioError(f"--out {out} is a file, not a directory")
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent.rstrip(os.sep))
    parent = parent or "."
    if not os.path.isdir(parent):
        raise ScenarioError(f"--out {out}: {parent} is a file, not a directory; choose another --out")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ScenarioError(f"--out {out}: {parent} is not writable (read-only or no permission); choose another --out")


def parse_overrides(items) -> dict:
    """{'a.b': 'text'} from ["a.b=text", ...]: the text is read later as YAML by the same typed
    loader as a scenario file (scenario.apply_overrides), so it is checked against the field's
    declared type and named by its full path."""
    out = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ScenarioError(f"--set {item!r}: write FIELD=VALUE, e.g. guidance.resolve_period_s=100")
        out[key.strip()] = text
    return out


def _cmd_report(args) -> int:
    _write_and_print_report(args.dir)
    return 0


def _write_and_print_report(out_dir: str) -> dict:
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


class Command(NamedTuple):
    """A subcommand contributed by a package: ``COMMANDS`` in a method folder's ``commands.py``
    (found by itself) or in a shared package's (``SHARED_COMMAND_MODULES``)."""

    name: str
    help: str
    add_arguments: Callable  # (argparse.ArgumentParser) -> None
    run: Callable  # (argparse.Namespace) -> exit code


#: the shared packages that contribute commands (a method folder's commands.py is found by itself)
SHARED_COMMAND_MODULES = ("drake_entry.planning.nlp.commands", "drake_entry.campaign.commands")


def contributed_commands() -> list:
    """Every ``Command`` of the shared packages and of the method folders, in that order."""
    import importlib
    from importlib import resources

    folder = resources.files("drake_entry.guidance")
    methods = sorted(p.name for p in folder.iterdir() if p.is_dir() and p.joinpath("commands.py").is_file())
    modules = list(SHARED_COMMAND_MODULES) + [f"drake_entry.guidance.{m}.commands" for m in methods]
    return [c for name in modules for c in getattr(importlib.import_module(name), "COMMANDS", ())]


class _HelpWithDefaults(argparse.ArgumentDefaultsHelpFormatter):
    """Help that shows each argument's default, unless there is none or the help states it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or action.default in (None, argparse.SUPPRESS, []) or isinstance(action.default, bool):
            return text
        return super()._get_help_string(action)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-entry", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", required=True)
    scenarios = ", ".join(packaged_scenarios())
    scenario_help = f"packaged scenario name ({scenarios}; see `drake-entry scenarios`) or a YAML path"
    defaults = _HelpWithDefaults
    sc = sub.add_parser("scenarios", help="list the packaged scenarios, or print one with its comments",
                        formatter_class=defaults)
    sc.add_argument("name", nargs="?", default=None, help="a packaged scenario to print")
    sc.set_defaults(func=_cmd_scenarios)
    c = sub.add_parser("campaign", help="closed-loop Monte-Carlo campaign with a report", formatter_class=defaults)
    c.add_argument("scenario", help=scenario_help)
    c.add_argument("--runs", type=int, default=100, help="samples (a larger value extends a finished campaign)")
    c.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    c.add_argument("--seed", type=int, default=0, help="campaign seed; sample i is reproducible from (seed, i)")
    c.add_argument("--out", default="out/campaign", help="campaign directory (re-running resumes it)")
    c.add_argument("--backend", choices=("processes", "serial", "dask"), default="processes",
                   help="local processes (default), one process, or Dask distributed")
    c.add_argument("--scheduler", default=None,
                   help="Dask scheduler address (implies --backend dask); a LocalCluster when omitted")
    c.add_argument("--trajectory-step", type=float, default=10.0, metavar="SECONDS",
                   help="keep each sample's trajectory every SECONDS (0 = none, rows only; the first 5 samples "
                        "every 1 s for the report's bank histories)")
    c.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE", dest="overrides",
                   help="override a scenario field, e.g. --set guidance.resolve_period_s=100 (repeatable; "
                        "the value is read as YAML)")
    c.set_defaults(func=_cmd_campaign)
    r = sub.add_parser("report", help="write the report (report.md, report.html) of a campaign directory",
                       formatter_class=defaults)
    r.add_argument("dir", help="a campaign directory (finished, running, killed or partial)")
    r.set_defaults(func=_cmd_report)
    fl = sub.add_parser("fly", help="one closed-loop guided flight (exit 1 when it is not a success)",
                        formatter_class=defaults)
    fl.add_argument("scenario", help=scenario_help)
    fl.add_argument("--out", default="out/fly", help="output directory: trajectory table, summary.json, figures")
    fl.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="trajectory table format")
    fl.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE", dest="overrides",
                    help="override a scenario field, e.g. --set guidance.bank_end_deg=45 (repeatable; the value is "
                         "read as YAML, as in campaign)")
    fl.set_defaults(func=_cmd_fly)
    pl = sub.add_parser("plan", help="the guidance method's plan report, flown by the Drake Simulator (drag-energy: "
                        "corridor, reference and extraction, paper 000 Figs. 3-5; SCvx: the pre-flight plan and its "
                        "flight, paper 001; AMPI: the database reference for the entry state, paper 003; swarm "
                        "bank: sigma_0 search, Drake check, paper 004 figures); exit 1 when it is not verified",
                        formatter_class=defaults)
    pl.add_argument("scenario", help=scenario_help)
    pl.add_argument("--out", default="out/plan", help="output directory: figures and tables of the plan")
    pl.set_defaults(func=_cmd_plan)
    p = sub.add_parser("simulate", help="fly the open-loop diagram of a scenario", formatter_class=defaults)
    p.add_argument("scenario", help=scenario_help)
    p.add_argument("--out", default="out/simulate", help="output directory")
    p.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="trajectory table format")
    p.set_defaults(func=_cmd_simulate)
    argv = sys.argv[1:] if argv is None else list(argv)
    asked = next((a for a in argv if not a.startswith("-")), None)
    if asked not in sub.choices:  # a contributed command, the command list or a typo: load them all
        for command in contributed_commands():  # (importing the NLP package costs about 0.4 s)
            parser_ = sub.add_parser(command.name, help=command.help)
            command.add_arguments(parser_)
            parser_.set_defaults(func=command.run)
    args = parser.parse_args(argv)
    try:
        out = getattr(args, "out", None)
        if out is not None:
            check_output_dir(out)
        return args.func(args)
    except Interrupted as e:  # Ctrl-C in a campaign: finished samples kept
        print(f"\ndrake-entry: {' '.join(str(e).split())}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print(f"\ndrake-entry: interrupted (Ctrl-C); '{args.command}' stopped", file=sys.stderr)
        return 130
    except DrakeEntryError as e:  # bad input, a refused campaign directory, an unusable solver: one line
        print(f"drake-entry: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    except OSError as e:  # the file system refused a read or write: where and why, one line
        where = getattr(args, "out", None) or getattr(args, "dir", None)
        print(f"drake-entry: error: {os_error_line(e, where)}", file=sys.stderr)
        return 2


def os_error_line(e: OSError, where: str | None = None) -> str:
    """One line for an operating-system error: the path (else a file in ``where``), the
    cause, and what to do."""
    import errno

    path = e.filename if e.filename is not None else (f"a file in {where}" if where else "a file")
    if e.filename2 is not None:
        path = f"{path} -> {e.filename2}"
    cause = e.strerror or str(e) or type(e).__name__
    hint = {errno.ENOSPC: "free some space (finished campaign samples are kept; the same command resumes)",
            errno.EDQUOT: "free some space (finished campaign samples are kept; the same command resumes)",
            errno.EROFS: "choose a writable --out",
            errno.EACCES: "choose a directory you may write (--out) or change its permissions",
            errno.EPERM: "choose a directory you may write (--out) or change its permissions",
            errno.ENOTDIR: "a part of the path is a file, not a directory: choose another --out",
            errno.EISDIR: "a directory is in the way of a file",
            errno.ENOENT: "check the path"}.get(e.errno, "")
    return f"cannot use {path}: {cause}" + (f"; {hint}" if hint else "")


if __name__ == "__main__":
    sys.exit(main())
