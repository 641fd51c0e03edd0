"""Claims a script makes about its own results, checked and printed: every example ends with
its claims, and exits 1 when one does not hold (a script that shows a failure must say so in
its exit status, not only in its output).

    claims = Claims("example 06: paper 004's bank profile")
    claims.check("the plan reaches TAEM inside the limits", plan.success, plan.message)
    raise SystemExit(claims.report())

``run_example`` is the command line every example shares (``--quick``, ``--out`` and its own
options): it runs the example's ``main``, checks its claims and returns the exit status.
"""
from __future__ import annotations

import argparse
import dataclasses as dc
import sys

__all__ = ["Claim", "Claims", "run_example"]


@dc.dataclass(frozen=True)
class Claim:
    """One claim: its text, whether it holds, and what was measured."""

    text: str
    holds: bool
    measured: str = ""


class Claims:
    """An ordered list of checked claims."""

    def __init__(self, title: str):
        self.title = title
        self.items: list[Claim] = []

    def check(self, text: str, holds, measured: str = "") -> bool:
        """Record ``text`` as holding when ``holds`` is true; ``measured`` says with what figures."""
        self.items.append(Claim(text, bool(holds), str(measured)))
        return bool(holds)

    @property
    def failed(self) -> list[Claim]:
        return [c for c in self.items if not c.holds]

    @property
    def ok(self) -> bool:
        return bool(self.items) and not self.failed

    def report(self, stream=None) -> int:
        """Print every claim (ok / FAILED, with its figures) and a last line; return the exit
        status: 0 when all hold, 1 otherwise (also when nothing was claimed)."""
        stream = stream or sys.stdout
        print(f"\n{self.title}: claims", file=stream)
        for c in self.items:
            print(f"  [{'ok' if c.holds else 'FAILED'}] {c.text}" + (f" ({c.measured})" if c.measured else ""),
                  file=stream)
        if not self.items:
            print("no claim was checked: nothing is shown", file=stream)
            return 1
        n_bad = len(self.failed)
        print(f"{len(self.items) - n_bad} of {len(self.items)} claims hold"
              + (f"; {n_bad} FAILED" if n_bad else ""), file=stream)
        return 1 if n_bad else 0


def run_example(doc: str, main, check, *, out: str, quick: str = "", options=(), argv=None) -> int:
    """An example's command line: ``--quick`` (what it leaves out: ``quick``), ``--out`` (default
    ``out``) and its own ``options`` ((flag, argparse keywords) pairs, passed to ``main`` by their
    destination name); runs ``main(quick, out_dir, **options)``, prints ``check(result, quick)``
    and returns its exit status (1 when a claim fails)."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help=quick or "the reduced size")
    parser.add_argument("--out", default=out, help=f"output directory (default: {out})")
    for flag, keywords in options:
        parser.add_argument(flag, **keywords)
    args = vars(parser.parse_args(argv))
    quick_run, out_dir = args.pop("quick"), args.pop("out")
    return check(main(quick_run, out_dir, **args), quick_run).report()
