"""The arguments of a run, checked where they enter and before any work.

The command line and the Python API (``run_campaign``, ``run_comparison``) call the same
checks, before any planning, file or directory: each refusal is one ScenarioError naming the
argument and its allowed range, and leaves the disk as it was.
"""
from __future__ import annotations

import math
import os

import numpy as np

from drake_entry.campaign.engine import check_backend, resolve_backend
from drake_entry.errors import ScenarioError

__all__ = ["MAX_RUNS", "RUNS_NOTE", "check_output_dir", "check_run_arguments"]

#: the largest campaign accepted: 10^7 samples at 0.5-40 s of a core each are 2-4600 core-days
MAX_RUNS = 10_000_000
RUNS_NOTE = " (10^7 samples take 2 to 4600 core-days by method; split larger studies into campaigns)"


def check_output_dir(out, name: str = "--out") -> str:
    """``out`` as a path, or a ScenarioError when it cannot be made or written: not a path, a
    file on its path, a read-only or forbidden place (``name``: the argument, as the caller's
    user typed it)."""
    if not isinstance(out, (str, os.PathLike)):
        raise ScenarioError(f"{name} must be a directory path (text); got {type(out).__name__}")
    out = os.fspath(out)
    if not out or not out.strip():
        raise ScenarioError(f"{name} is empty; give a directory")
    if "\0" in out:
        raise ScenarioError(f"{name} {out!r} contains a NUL character; give a directory path")
    parent = os.path.normpath(out)  # 'a_file/' names the file too
    if os.path.exists(parent) and not os.path.isdir(parent):
        raise ScenarioError(f"{name} {out} is a file, not a directory")
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent.rstrip(os.sep))
    parent = parent or "."
    if not os.path.isdir(parent):
        raise ScenarioError(f"{name} {out}: {parent} is a file, not a directory; choose another {name}")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ScenarioError(f"{name} {out}: {parent} is not writable (read-only or no permission); choose another "
                            f"{name}")
    return out


def check_run_arguments(*, runs, seed, trajectory_step_s, workers=None, backend: str = "processes",
                        scheduler: str | None = None) -> None:
    """One-line ScenarioErrors for a sample count, seed, trajectory step, backend or worker count
    out of range, or a backend that contradicts a Dask ``scheduler`` address (the same for a
    campaign and a comparison, before any search or plan)."""
    check_backend(backend, workers)
    resolve_backend(backend, scheduler)
    for name, value, lo, hi in (("runs", runs, 1, MAX_RUNS), ("seed", seed, 0, 2**63 - 1)):
        integer = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
        if not integer or not lo <= value <= hi:
            raise ScenarioError(f"{name} = {value!r} is {'out of range' if integer else 'not an integer'}; allowed: an "
                                f"integer in [{lo}, {hi}]" + (RUNS_NOTE if name == "runs" else ""))
    if isinstance(trajectory_step_s, bool) or not (isinstance(trajectory_step_s, (int, float, np.floating))
                                                   and 0 <= trajectory_step_s < math.inf):
        raise ScenarioError(f"trajectory_step_s = {trajectory_step_s!r} is out of range; allowed: >= 0 s "
                            f"(0 = no trajectories)")
