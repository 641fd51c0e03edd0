"""A campaign's success-probability requirement (a scenario's ``success_requirement``: the success
probability p to show at confidence c, e.g. 99.73 % at 90 %, the 3-sigma form of NASA entry,
descent and landing Monte-Carlo practice, Hanson & Beard 2010), judged with the one-sided
Clopper-Pearson bounds on the campaign's samples (campaign.statistics):

- PASS: the lower bound reaches p: the requirement is shown;
- FAIL: the upper bound is below p: shown not met (more runs are not expected to change it);
- OPEN: neither; ``more_runs`` is the fewest further runs, every one successful, that would make
  the lower bound reach p (with f failures among n runs the bound is the Beta(n - f, f + 1)
  quantile at 1 - c, which rises with n).

Without failures the runs that show p at c are ln(1 - c) / ln(p) rounded up: 852 for 99.73 % at
90 %, 230 for 99 % at 90 %.
"""
from __future__ import annotations

import dataclasses as dc

from drake_entry.campaign.statistics import success_lower_bound, success_upper_bound
from drake_entry.errors import ScenarioError
from drake_entry.scenario import SuccessRequirementSpec

__all__ = ["STATUSES", "MAX_RUNS", "SuccessVerdict", "runs_to_show", "success_verdict"]

#: the verdicts, in the order a campaign moves through them
STATUSES = ("OPEN", "PASS", "FAIL")
#: the most runs ``runs_to_show`` searches (None beyond)
MAX_RUNS = 10 ** 8


@dc.dataclass(frozen=True)
class SuccessVerdict:
    """A campaign's success-probability requirement judged on ``successes`` of ``runs``: status
    PASS, FAIL or OPEN (module docstring); lower, upper: the one-sided bounds at ``confidence``;
    more_runs: OPEN only, the further runs (all successful) that would show ``probability``."""

    status: str
    probability: float
    confidence: float
    successes: int
    runs: int
    lower: float
    upper: float
    more_runs: int | None = None

    @property
    def required(self) -> str:
        return f">= {100 * self.probability:g} % at {100 * self.confidence:g} % confidence"

    def text(self) -> str:
        """One sentence with the figures."""
        count = f"{self.successes} of {self.runs} successful"
        if self.status == "PASS":
            return (f"PASS: {count}; the success probability is at least {100 * self.probability:g} % at "
                    f"{100 * self.confidence:g} % confidence (lower bound {100 * self.lower:.3f} %)")
        if self.status == "FAIL":
            return (f"FAIL: {count}; at {100 * self.confidence:g} % confidence the success probability is below "
                    f"{100 * self.probability:g} % (upper bound {100 * self.upper:.3f} %): shown not met")
        more = ("no number of runs within " + f"{MAX_RUNS:.0e}" if self.more_runs is None
                else f"{self.more_runs} more runs, every one successful,")
        return (f"OPEN: {count}; lower bound {100 * self.lower:.3f} % against {100 * self.probability:g} % at "
                f"{100 * self.confidence:g} % confidence: {more} would show it")


def _check(probability: float, confidence: float) -> None:
    SuccessRequirementSpec(probability, confidence).validate()


def runs_to_show(failures: int, probability: float, confidence: float) -> int | None:
    """The fewest runs n with ``failures`` failures among them whose one-sided lower
    ``confidence`` bound on the success probability reaches ``probability`` (None beyond
    MAX_RUNS)."""
    _check(probability, confidence)
    if failures < 0:
        raise ScenarioError(f"failures must be >= 0, got {failures}")

    def shown(n: int) -> bool:
        return success_lower_bound(n - failures, n, confidence) >= probability

    lo, hi = failures, failures + 1  # shown(lo) is False (no success); find hi with shown(hi)
    while not shown(hi):
        lo, hi = hi, 2 * hi
        if hi > MAX_RUNS:
            return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if shown(mid) else (mid, hi)
    return hi


def success_verdict(successes: int, runs: int, probability: float, confidence: float) -> SuccessVerdict:
    """The requirement ``probability`` at ``confidence`` judged on ``successes`` of ``runs``."""
    _check(probability, confidence)
    lower = success_lower_bound(successes, runs, confidence)
    upper = success_upper_bound(successes, runs, confidence)
    if lower >= probability:
        return SuccessVerdict("PASS", probability, confidence, successes, runs, lower, upper)
    if upper < probability:
        return SuccessVerdict("FAIL", probability, confidence, successes, runs, lower, upper)
    needed = runs_to_show(runs - successes, probability, confidence)
    more = None if needed is None else max(needed - runs, 1)
    return SuccessVerdict("OPEN", probability, confidence, successes, runs, lower, upper, more)
