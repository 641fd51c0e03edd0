"""Claims a script makes about its own results, checked and printed: every example ends with
its claims, and exits 1 when one does not hold (a script that shows a failure must say so in
its exit status, not only in its output).

    claims = Claims("example 06: paper 004's bank profile")
    claims.check("the plan reaches TAEM inside the limits", plan.success, plan.message)
    raise SystemExit(claims.report())
"""
from __future__ import annotations

import dataclasses as dc
import sys


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
