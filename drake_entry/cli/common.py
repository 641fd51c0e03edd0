"""What every command family shares: the ``Command`` record a family contributes, the help
formatter, the scenario argument, ``--set`` parsing and the checks of an output directory, and the
one-line account of an operating-system error."""
from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Callable, NamedTuple

from drake_entry.errors import ScenarioError

__all__ = ["write_plan_report", "Command", "HelpWithDefaults", "add_scenario_argument", "add_overrides_argument",
           "parse_overrides", "os_error_line"]


class Command(NamedTuple):
    """A subcommand: ``COMMANDS`` of a command family (``drake_entry.cli.<family>``) or of a
    method's commands (``drake_entry.cli.methods.<method folder>``)."""

    name: str
    help: str
    add_arguments: Callable  # (argparse.ArgumentParser) -> None
    run: Callable  # (argparse.Namespace) -> exit code


class HelpWithDefaults(argparse.ArgumentDefaultsHelpFormatter):
    """Help that shows each argument's default, unless there is none or the help states it."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text or action.default in (None, argparse.SUPPRESS, []) or isinstance(action.default, bool):
            return text
        return super()._get_help_string(action)


def add_scenario_argument(parser) -> None:
    """The positional SCENARIO: a packaged name or a YAML path."""
    from drake_entry.scenario import PACKAGED_SCENARIOS

    parser.add_argument("scenario", help=f"packaged scenario name ({', '.join(PACKAGED_SCENARIOS)}; see "
                        "`drake-entry scenarios`) or a YAML path")


def add_overrides_argument(parser, example: str) -> None:
    """``--set FIELD=VALUE`` (repeatable), collected in ``args.overrides``."""
    parser.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE", dest="overrides",
                        help=f"override a scenario field, e.g. --set {example} (repeatable; the value is read as "
                             "YAML)")


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


def write_plan_report(out_dir: str, summary: dict, figures: list, verified: bool, why: str) -> int:
    """The end of every method's plan report: ``plan.json`` written, the files named, and the exit
    status (0 when the plan is verified; else 1 with ``why`` on stderr)."""
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "plan.json"), "w") as f:
        json.dump(summary, f, indent=2, default=float)
    print(f"wrote plan.json and {len(figures)} plot(s) to {out_dir}")
    if not verified:
        print(f"drake-entry: {why}", file=sys.stderr)
    return 0 if verified else 1
