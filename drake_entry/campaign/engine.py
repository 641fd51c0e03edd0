"""A campaign of independent cases, durable and resumable, on any backend.

``run_cases`` runs the cases of a ``backends.Task`` that are not yet done in ``out_dir``
(``campaign_store``: fingerprinted manifest, rows streamed as they finish, Parquet at the
end) on 'serial', 'processes' or 'dask', with a progress bar. The Monte-Carlo runner
(``montecarlo.run_campaign``) and the SCvx abort maps (``aborts``) are both campaigns of
this kind; a case that fails is a row with its reason and never stops the others.
"""
from __future__ import annotations

import datetime
import hashlib
import importlib.metadata
import json
import os
import platform
import subprocess
import sys

import numpy as np

import drake_entry
from drake_entry.campaign.backends import BACKENDS, Task, run_backend
from drake_entry.campaign.store import CampaignStore
from drake_entry.errors import Interrupted, ScenarioError

__all__ = ["versions", "session", "source_commit", "foreign_sources", "MAPPED_PACKAGES", "task_manifest", "check_backend", "resolve_backend", "run_cases", "SampleCases"]


def versions() -> dict:
    """The drake_entry and drake versions a campaign was run with (part of its identity)."""
    return {"drake_entry": drake_entry.__version__, "drake": importlib.metadata.version("drake")}


def session() -> dict:
    """Where and how this run of a campaign was made (not part of its identity; a resumed
    campaign keeps one record per run, ``manifest['sessions']``): the UTC date, the command,
    Python, NumPy and SciPy, the platform, drake_entry and Drake (whose build carries the
    solvers: Clarabel, SCS, Ipopt, SNOPT), and the git commit of the drake_entry source when it
    is a checkout (None for an installed wheel)."""
    def version(name):
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return None

    return {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "command": " ".join([os.path.basename(sys.argv[0]), *sys.argv[1:]]) if sys.argv and sys.argv[0] else "",
            "python": platform.python_version(), "numpy": np.__version__, "scipy": version("scipy"),
            "platform": platform.platform(terse=True), "git_commit": source_commit(), **versions()}


#: the packages pyproject's package-dir installs inside drake_entry from the checkout's top level
MAPPED_PACKAGES = (("drake_entry.systems", "systems"), ("drake_entry.diagrams", "diagrams"))


def foreign_sources(top: str) -> list[str]:
    """The mapped packages (MAPPED_PACKAGES) imported from outside ``top`` (the directory that
    holds drake_entry/), as 'name from directory': with drake_entry taken from one checkout (e.g.
    PYTHONPATH) and another checkout's editable install on the path, systems/ and diagrams/ come
    from that other checkout, so the commit of drake_entry alone does not name the code that ran.
    Their own places: ``top/systems`` in a checkout, ``top/drake_entry/systems`` in an installed
    wheel."""
    import importlib.util

    foreign = []
    for name, folder in MAPPED_PACKAGES:
        spec = importlib.util.find_spec(name)
        where = os.path.dirname(spec.origin) if spec is not None and spec.origin else None
        homes = [os.path.join(top, folder), os.path.join(top, "drake_entry", folder)]
        if where is None or not any(os.path.isdir(h) and os.path.samefile(where, h) for h in homes):
            foreign.append(f"{name} from {where}")
    return foreign


def source_commit() -> str | None:
    """The git commit of the drake_entry source tree (with '+changes' when it has uncommitted
    ones, or when systems/ or diagrams/ are imported from another checkout: ``foreign_sources``),
    or None when the package is not a git checkout."""
    here = os.path.dirname(os.path.abspath(drake_entry.__file__))
    try:
        top = subprocess.run(["git", "-C", here, "rev-parse", "--show-toplevel"], capture_output=True, text=True,
                             timeout=10)
        if top.returncode != 0 or not os.path.samefile(top.stdout.strip(), os.path.dirname(here)):
            return None
        head = subprocess.run(["git", "-C", here, "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", here, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    changed = bool(dirty.stdout.strip()) or bool(foreign_sources(top.stdout.strip()))
    return head.stdout.strip() + ("+changes" if changed else "") if head.returncode == 0 else None


def task_manifest(task: Task, cases: list, **extra) -> dict:
    """The manifest of a campaign of ``cases`` (dicts with an integer 'index') of ``task``:
    the task, the case list's sha256 and the versions identify it."""
    digest = hashlib.sha256(json.dumps(cases, sort_keys=True, default=float).encode()).hexdigest()
    return {"task": {"setup": task.setup, "run": task.run, "config": task.config}, "cases_sha256": digest,
            "versions": versions(), "runs": len(cases), "sessions": [session()], **extra}


def check_backend(backend: str, workers) -> None:
    """One-line ScenarioErrors for an unknown backend or a bad worker count."""
    if backend not in BACKENDS:
        raise ScenarioError(f"backend '{backend}' is unknown; allowed: {', '.join(BACKENDS)}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or not 1 <= workers <= 4096):
        raise ScenarioError(f"workers = {workers} is out of range; allowed: an integer in [1, 4096] (default: all cores)")


def resolve_backend(backend: str, scheduler: str | None) -> str:
    """The backend that flies the cases: a Dask ``scheduler`` address implies 'dask' (the
    cluster at it), so 'processes' (the default) becomes 'dask'; 'serial' with an address is a
    ScenarioError (one process here cannot fly on a cluster); without an address, ``backend``."""
    if not scheduler:
        return backend
    if backend == "serial":
        raise ScenarioError(f"backend 'serial' with the Dask scheduler {scheduler}: the samples fly either in this "
                            f"one process or on the cluster; omit one of them")
    return "dask"


def run_cases(task: Task, cases: list, out_dir: str, manifest: dict, *, backend: str = "processes",
              workers: int | None = None, scheduler: str | None = None, progress: bool = True,
              desc: str = "campaign") -> str:
    """Run the cases of ``cases`` (dicts, each with a unique integer 'index') not yet done in
    ``out_dir``; returns out_dir. ``manifest`` identifies the campaign (``task_manifest``, or
    the Monte-Carlo manifest); a directory holding another campaign is refused (CampaignError).
    workers: local processes (default all cores, at most one per case); ``scheduler``: the
    address of a Dask cluster, which implies backend 'dask' (resolve_backend)."""
    check_backend(backend, workers)
    backend = resolve_backend(backend, scheduler)
    if not isinstance(cases, SampleCases):
        indices = [c.get("index") for c in cases]
        if any(isinstance(i, bool) or not isinstance(i, int) for i in indices) or len(set(indices)) != len(indices):
            raise ScenarioError("cases need a unique integer 'index' each")
    store = CampaignStore(out_dir, manifest)
    done = store.done_indices()
    if isinstance(cases, SampleCases):  # lazy: a huge campaign starts at once
        todo = (c for c in cases if c["index"] not in done)
        remaining = len(cases) - sum(1 for i in done if i in cases)
    else:
        todo = [c for c in cases if c["index"] not in done]
        remaining = len(todo)
    workers = min(workers or os.cpu_count() or 1, max(remaining, 1))
    total = int(store.manifest.get("runs", len(cases)))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total, initial=min(len(done), total), unit="case", desc=desc, smoothing=0.05)
    failed = 0
    with store:
        def record(row, traj):
            nonlocal failed
            store.record(row, traj)
            if bar is not None:
                bar.update(1)
                if not row.get("success"):  # not a success: a verdict, not necessarily an error
                    failed += 1
                    bar.set_postfix(unsuccessful=failed)

        try:
            run_backend(backend, task, todo, record, workers=workers, scheduler=scheduler)
        except KeyboardInterrupt:
            finished = len(store.done_indices())
            raise Interrupted(f"interrupted after {finished} of {total} {desc} cases; every finished one is "
                              f"kept in {out_dir}: run the same command to resume") from None
        finally:
            if bar is not None:
                bar.close()
        store.finalise()
    return out_dir


class SampleCases:
    """The cases ``{'index': i, 'seed': seed_of(i)}`` for i in range(runs), made as they are
    read (a campaign of 10^9 samples holds no list of them)."""

    def __init__(self, runs: int, seed_of):
        self.runs, self.seed_of = int(runs), seed_of

    def __len__(self) -> int:
        return self.runs

    def __contains__(self, index) -> bool:
        return isinstance(index, int) and 0 <= index < self.runs

    def __iter__(self):
        return ({"index": i, "seed": self.seed_of(i)} for i in range(self.runs))
