"""A Dask cluster of separate processes on this machine: ``ProcessCluster``.

What a cluster's nodes run, started here as processes of their own: one ``dask scheduler`` and
``dask worker`` processes (one thread each, no nanny, the quiet-worker settings of
``backends.DASK_QUIET_WORKERS`` as environment variables). A campaign reaches it only through its
address (``--scheduler``), exactly as it reaches a cluster's scheduler: use it to try a cluster
set-up on one machine, and in the tests that kill a worker mid-campaign. On a real cluster start
the same commands on its nodes, or let ``dask-jobqueue`` submit them (docs/campaigns.md).
"""
from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time

from drake_entry.campaign.backends import DASK_QUIET_WORKERS

__all__ = ["ProcessCluster", "worker_environment"]


def worker_environment() -> dict:
    """Environment variables carrying DASK_QUIET_WORKERS (Dask reads DASK_A__B__C as a.b.c)."""
    return {"DASK_" + key.upper().replace(".", "__").replace("-", "_"): str(value)
            for key, value in DASK_QUIET_WORKERS.items()}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class ProcessCluster:
    """A scheduler and ``workers`` worker processes on localhost (module docstring). A context
    manager: leaving it ends every process. ``log``: a file the processes write to (default:
    discarded). ``address`` is the scheduler's; ``workers`` the live worker processes by name."""

    def __init__(self, workers: int = 2, *, log: str | None = None, timeout_s: float = 60.0):
        if workers < 1:
            raise ValueError(f"ProcessCluster workers = {workers}; allowed >= 1")
        self.address = f"tcp://127.0.0.1:{_free_port()}"
        self._log = open(log, "a") if log else subprocess.DEVNULL
        self._count = 0
        self.workers: dict[str, subprocess.Popen] = {}
        self.scheduler = self._start("scheduler", "--host", "127.0.0.1", "--port", self.address.rsplit(":", 1)[1],
                                     "--no-dashboard")
        try:
            for _ in range(workers):
                self.add_worker()
            self.wait_for_workers(workers, timeout_s)
        except BaseException:
            self.close()
            raise

    def _start(self, *args) -> subprocess.Popen:
        dask = os.path.join(os.path.dirname(sys.executable), "dask")  # this environment's
        return subprocess.Popen([dask, *args], stdout=self._log, stderr=subprocess.STDOUT,
                                env=dict(os.environ, **worker_environment()), start_new_session=True)

    def add_worker(self) -> str:
        """Start one more worker process; returns its name."""
        name = f"worker-{self._count}"
        self._count += 1
        self.workers[name] = self._start("worker", self.address, "--name", name, "--nthreads", "1", "--no-nanny",
                                         "--no-dashboard", "--death-timeout", "60")
        return name

    def kill_worker(self, name: str, timeout_s: float = 60.0) -> None:
        """SIGKILL a worker process, as a node lost mid-campaign, and wait until the scheduler
        has removed it (TimeoutError otherwise)."""
        os.kill(self.workers.pop(name).pid, signal.SIGKILL)
        self._wait(lambda names: name not in names, f"the scheduler still lists {name}", timeout_s)

    def worker_names(self) -> set:
        """The names of the workers the scheduler counts now."""
        from dask.distributed import Client

        with Client(self.address, timeout=10) as client:
            return {w.get("name") for w in client.scheduler_info().get("workers", {}).values()}

    def wait_for_workers(self, n: int, timeout_s: float = 60.0) -> None:
        """Block until the scheduler counts ``n`` workers (TimeoutError naming the count)."""
        self._wait(lambda names: len(names) >= n, f"fewer than {n} workers joined", timeout_s)

    def _wait(self, done, what: str, timeout_s: float) -> None:
        deadline = time.monotonic() + timeout_s
        while not done(self.worker_names()):
            if time.monotonic() > deadline:
                raise TimeoutError(f"ProcessCluster: {what} within {timeout_s:.0f} s")
            time.sleep(0.1)

    def close(self) -> None:
        procs = [*self.workers.values(), self.scheduler]
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
        self.workers.clear()
        if self._log is not subprocess.DEVNULL:
            self._log.close()

    def __enter__(self) -> "ProcessCluster":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
