"""Console progress of a long computation (an NLP solve, a swarm search): silent for its first
``after`` seconds, then one line every ``interval`` seconds on stderr, each ending with how
to stop it. Shown when asked (True), never (False), or when stderr is a terminal ('auto')."""
from __future__ import annotations

import math
import sys
import time

__all__ = ["PROGRESS_AFTER_S", "PROGRESS_INTERVAL_S", "wanted", "ProgressLine"]

#: a computation prints progress once it has run this long [s], then at this interval [s]
PROGRESS_AFTER_S, PROGRESS_INTERVAL_S = 5.0, 5.0


def wanted(progress) -> bool:
    """True, False or 'auto' (stderr is a terminal) as a yes/no."""
    return bool(progress is True or (progress == "auto" and sys.stderr.isatty()))


class ProgressLine:
    """``emit(parts)`` prints ``  [label] <elapsed> s, part, part (hint)`` when due; the
    module's PROGRESS_AFTER_S / PROGRESS_INTERVAL_S unless ``after`` / ``interval`` are given."""

    def __init__(self, label: str, *, hint: str = "Ctrl-C stops it", stream=None, after: float | None = None,
                 interval: float | None = None):
        self.label, self.hint, self.stream = label, hint, stream or sys.stderr
        self.after, self.interval = after, interval
        self.t0 = self.next = math.inf

    def start(self):
        self.t0 = time.perf_counter()
        self.next = self.t0 + (PROGRESS_AFTER_S if self.after is None else self.after)

    def due(self) -> bool:
        return time.perf_counter() >= self.next

    def emit(self, parts: list[str]):
        now = time.perf_counter()
        self.next = now + (PROGRESS_INTERVAL_S if self.interval is None else self.interval)
        print(f"  [{self.label}] {now - self.t0:6.0f} s, " + ", ".join(parts) + f" ({self.hint})",
              file=self.stream, flush=True)
