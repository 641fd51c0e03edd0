"""drake-entry: plan, fly and analyse atmospheric-entry trajectories on Drake.

Commands:
  scenarios [NAME]    the packaged scenarios (name, guidance method, vehicle, description), or one
                      scenario's YAML file with its comments
  campaign SCENARIO   closed-loop Monte-Carlo campaign (Drake RandomSimulation) with a report;
                      exit 1 when a sample is not successful
  report DIR          (re)write the report (report.md, report.html) of a campaign or comparison
                      directory
  fly SCENARIO        one closed-loop guided flight with plots
  plan SCENARIO       the guidance method's reference plan, flown by Drake, with its figures
                      (drag-energy, SCvx, AMPI, swarm-bank and LGL terminal methods)
  simulate SCENARIO   fly the open-loop diagram; write the trajectory and PNG plots
  results             every packaged closed-loop scenario as a campaign with its report
  compare COMPARISON  several guidance methods on one mission, the same dispersions and seeds
  optimize PROBLEM    optimal reference by the NLP path (paper 002), verified and flown by Drake
and the commands of the methods (drake_entry/cli/methods/<method folder>.py), e.g.
  fit-horus           refit the HORUS-2B aero forms (paper 000 eqs. 32-33); print residuals

Benchmarks are scripts, not commands: python benchmarks/run.py (see README).
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading

from drake_entry.campaign.arguments import check_output_dir
from drake_entry.cli.common import Command, HelpWithDefaults, os_error_line
from drake_entry.errors import DrakeEntryError, Interrupted

__all__ = ["main", "commands", "FAMILIES"]

#: the command families, in the order of ``drake-entry --help`` (each a module with ``COMMANDS``)
FAMILIES = ("drake_entry.cli.flights", "drake_entry.cli.campaigns", "drake_entry.cli.comparisons",
            "drake_entry.cli.publish", "drake_entry.cli.optimize")


def commands() -> list[Command]:
    """Every command: the families', then those of the methods that have a module in
    ``drake_entry/cli/methods/`` (named after the method's folder in the registry)."""
    from importlib import resources

    from drake_entry.guidance import REGISTRY, folder_of

    folder = resources.files("drake_entry.cli").joinpath("methods")
    methods = [f for f in dict.fromkeys(folder_of(spec) for spec in REGISTRY) if folder.joinpath(f"{f}.py").is_file()]
    modules = list(FAMILIES) + [f"drake_entry.cli.methods.{m}" for m in methods]
    return [c for name in modules for c in getattr(importlib.import_module(name), "COMMANDS", ())]


def _version() -> str:
    import importlib.metadata

    import drake_entry

    try:
        drake = importlib.metadata.version("drake")
    except importlib.metadata.PackageNotFoundError:
        drake = "not installed"
    return f"drake-entry {drake_entry.__version__} (Drake {drake}, Python {sys.version.split()[0]})"


def _terminated(signum, frame):
    raise KeyboardInterrupt


@contextlib.contextmanager
def stoppable():
    """SIGINT and SIGTERM stop the command as Ctrl-C does (a campaign keeps its finished samples
    and says how to resume), also when it was started in the background, where the shell leaves
    SIGINT ignored and Python would leave it so; the handlers before are restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-entry", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", required=True)
    for command in commands():
        command_parser = sub.add_parser(command.name, help=command.help, formatter_class=HelpWithDefaults)
        command.add_arguments(command_parser)
        command_parser.set_defaults(func=command.run)
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    try:
        out = getattr(args, "out", None)
        if out is not None:
            check_output_dir(out)
        with stoppable():
            return args.func(args)
    except Interrupted as e:  # Ctrl-C in a campaign: finished samples kept
        print(f"\ndrake-entry: {' '.join(str(e).split())}", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print(f"\ndrake-entry: interrupted (Ctrl-C or SIGTERM); '{args.command}' stopped", file=sys.stderr)
        return 130
    except DrakeEntryError as e:  # bad input, a refused campaign directory, an unusable solver: one line
        print(f"drake-entry: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    except OSError as e:  # the file system refused a read or write: where and why, one line
        where = getattr(args, "out", None) or getattr(args, "dir", None)
        print(f"drake-entry: error: {os_error_line(e, where)}", file=sys.stderr)
        return 2


