"""Where campaign cases run: 'serial' (this process), 'processes' (local worker processes,
spawn) or 'dask' (Dask distributed: the cluster at ``scheduler`` or a LocalCluster).

A campaign is a ``Task`` and a list of cases. Each worker builds the task's state once
(``Task.setup(config)``: for a Monte-Carlo campaign the ClosedLoopSetup with its planner,
for an abort map the models and mission) and runs cases with it (``Task.run(state, case)``
returns (row, trajectory or None)). The two functions are named "module:function" so a
spawned process or a Dask worker imports them. A worker whose set-up fails returns that
failure as each case's row instead of dying (a dying pool initializer is respawned for
ever), and a case that raises becomes a failed row with its reason.
"""
from __future__ import annotations

import dataclasses as dc
import hashlib
import importlib
import json
import multiprocessing as mp
import os
import signal
import traceback

__all__ = ["BACKENDS", "SCHEDULER_TIMEOUT_S", "IN_FLIGHT_PER_WORKER", "DASK_QUIET_WORKERS", "Task",
           "init_pool_worker", "init_worker", "failed_row", "work", "run_serial", "WORKER_MEMORY_FRACTION", "SERIAL_MEMORY_FRACTION",
           "worker_memory_budget", "run_processes", "run_dask",
           "run_backend"]

BACKENDS = ("serial", "processes", "dask")

#: how long a Dask scheduler address is tried before the campaign is refused [s]
SCHEDULER_TIMEOUT_S = 10
#: cases submitted to a Dask cluster ahead of the results, per worker
IN_FLIGHT_PER_WORKER = 4

# Dask settings for CPU-bound pure-Python tasks (see run_dask)
DASK_QUIET_WORKERS = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1000ms",
    "distributed.admin.system-monitor.interval": "5000ms",
    "distributed.worker.memory.monitor-interval": "1000ms",
}


@dc.dataclass(frozen=True)
class Task:
    """What every case of a campaign runs.

    Attributes:
      setup: "module:function" building a worker's state from ``config`` (once per worker).
      run: "module:function" mapping (state, case) to (row dict with 'index' and 'success',
        trajectory columns or None).
      config: JSON-serialisable settings of the setup (part of the campaign's identity).
    """

    setup: str
    run: str
    config: dict

    def key(self) -> str:
        """sha256 of the task (which worker state serves it)."""
        return hashlib.sha256(json.dumps(dc.asdict(self), sort_keys=True).encode()).hexdigest()


def _resolve(name: str):
    module, _, function = name.partition(":")
    return getattr(importlib.import_module(module), function)


_WORKER = {}


def _ignore_interrupts():
    """A worker process leaves Ctrl-C to the parent, which ends the pool (a worker that took
    the SIGINT of the terminal's process group would print its own traceback)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def init_pool_worker(task: Task):
    """A local pool worker: Ctrl-C is the parent's, then ``init_worker``."""
    _ignore_interrupts()
    init_worker(task)


def init_worker(task: Task):
    """Build this process's state for ``task`` once."""
    _WORKER.update(key=task.key(), run=None, state=None, error=None)
    try:
        _WORKER["run"] = _resolve(task.run)
        _WORKER["state"] = _resolve(task.setup)(task.config)
    except Exception as e:  # reported per case by work()
        _WORKER["error"] = f"worker set-up failed: {type(e).__name__}: {e}".splitlines()[0][:500]


def failed_row(case: dict, message: str, trace: str | None = None) -> dict:
    """The row of a case that produced no result: its identifying columns and the reason."""
    row = {**case, "success": False, "message": message[:500]}
    if trace:
        row["traceback"] = trace[-2000:]
    return row


def work(case: dict):
    """One case on this worker: (row, trajectory or None); never raises."""
    if _WORKER.get("error") is not None or _WORKER.get("run") is None:
        return failed_row(case, _WORKER.get("error") or "worker not initialised"), None
    try:
        return _WORKER["run"](_WORKER["state"], case)
    except Exception as e:  # one failed case never stops the campaign
        return failed_row(case, f"{type(e).__name__}: {e}".splitlines()[0], traceback.format_exc(limit=3)), None


def run_serial(task: Task, cases, record, memory_budget: int | None = None):
    """The cases in this process, one after the other, until this process holds more than
    ``memory_budget`` bytes (default SERIAL_MEMORY_FRACTION of the machine's memory) after a case:
    then the rest go to one worker process that retires as run_processes' do (this process cannot
    retire; before flown diagrams were released, systems/lifetime.py, an SCvx campaign of one
    worker held 21 GB after 97 samples)."""
    import psutil

    budget = int(SERIAL_MEMORY_FRACTION * psutil.virtual_memory().total) if memory_budget is None else memory_budget
    init_worker(task)
    me = psutil.Process()
    pending = iter(cases)
    for case in pending:
        record(*work(case))
        if me.memory_info().rss > budget:
            run_processes(task, pending, record, 1,
                          memory_budget=worker_memory_budget(1, WORKER_MEMORY_FRACTION - SERIAL_MEMORY_FRACTION))
            return


#: a local worker retires after a case that leaves it holding more than this fraction of the
#: machine's memory shared among the workers (its replacement builds the task's state afresh): a
#: guard against what a method or model keeps; flown diagrams are freed (docs/performance.md, "Memory")
WORKER_MEMORY_FRACTION = 0.6
#: a serial campaign hands its remaining cases to a worker process past this fraction (the
#: worker then has the rest of WORKER_MEMORY_FRACTION)
SERIAL_MEMORY_FRACTION = 0.25


def worker_memory_budget(workers: int, fraction: float = WORKER_MEMORY_FRACTION) -> int:
    """The resident memory [bytes] past which a local worker retires after its case."""
    import psutil

    return int(fraction * psutil.virtual_memory().total / max(workers, 1))


#: how often [s] a local worker waiting for its next case checks that its parent still runs
ORPHAN_CHECK_S = 1.0


def _next_case(inbox, parent: int):
    """The next case sent to this worker, or None to end: when sent None, and when the process
    that started it has gone (killed, so never sends None: its workers would otherwise wait for
    ever, or a case in hand would be the last they fly)."""
    import queue as queue_module

    while True:
        try:
            return inbox.get(timeout=ORPHAN_CHECK_S)
        except queue_module.Empty:
            if os.getppid() != parent:
                return None


def _process_worker(task: Task, inbox, outbox, slot: int, budget: int, parent: int):
    """A local worker: builds the task's state, then runs the cases it is sent (None ends it, and
    its parent ``parent`` ending: ``_next_case``), answering (slot, row, trajectory, retiring) for
    each; it retires (ends after answering) when its resident memory has grown past ``budget``
    bytes."""
    import psutil

    init_pool_worker(task)
    me = psutil.Process()
    while (case := _next_case(inbox, parent)) is not None:
        row, traj = work(case)
        retiring = me.memory_info().rss > budget
        outbox.put((slot, row, traj, retiring))
        if retiring:
            return


def run_processes(task: Task, cases, record, workers: int, memory_budget: int | None = None):
    """Local spawned worker processes, each running one case at a time. ``cases`` may be any
    iterable (a lazy one is read as workers free up). A worker whose resident memory passes
    ``memory_budget`` bytes (default ``worker_memory_budget``) after a case retires and a new one
    takes its place; a worker that dies during a case (killed, out of memory, a crash in native
    code) leaves that case a failed row with its exit code, and a new worker goes on with the
    rest. On Ctrl-C the workers are terminated and KeyboardInterrupt propagates; when this process
    is killed outright, each worker ends once its case in hand is done (``_next_case``)."""
    import queue as queue_module

    ctx = mp.get_context("spawn")
    budget = worker_memory_budget(workers) if memory_budget is None else int(memory_budget)
    outbox = ctx.Queue()
    pending = iter(cases)
    slots: dict[int, dict] = {}  # slot -> {"process", "inbox", "case" (None: idle)}

    def start(slot: int) -> None:
        inbox = ctx.Queue()
        process = ctx.Process(target=_process_worker, args=(task, inbox, outbox, slot, budget, os.getpid()),
                              daemon=True)
        process.start()
        slots[slot] = {"process": process, "inbox": inbox, "case": None}

    def feed(slot: int) -> None:
        slots[slot]["case"] = next(pending, None)
        if slots[slot]["case"] is not None:
            slots[slot]["inbox"].put(slots[slot]["case"])

    def answered(slot: int, row: dict, traj, retiring: bool) -> None:
        record(row, traj)
        if retiring:
            slots[slot]["process"].join(timeout=30)
            start(slot)
        feed(slot)

    finished = False
    try:
        for slot in range(workers):
            start(slot)
            feed(slot)
        while any(w["case"] is not None for w in slots.values()):
            try:
                answered(*outbox.get(timeout=1.0))
                continue
            except queue_module.Empty:
                pass
            for slot, w in list(slots.items()):  # a worker that died with a case in hand
                if w["case"] is None or w["process"].is_alive():
                    continue
                try:  # an answer it sent before it ended is taken first
                    while True:
                        answered(*outbox.get(timeout=0.2))
                except queue_module.Empty:
                    pass
                if slots[slot]["process"] is w["process"] and w["case"] is not None:
                    code = w["process"].exitcode
                    cause = " (killed: out of memory?)" if code == -9 else ""
                    record(failed_row(w["case"], f"worker process died during the case, exit code {code}{cause}"),
                           None)
                    start(slot)
                    feed(slot)
        finished = True
    finally:
        for w in slots.values():
            if finished:
                w["inbox"].put(None)
            else:
                w["process"].terminate()
        for w in slots.values():
            w["process"].join(timeout=30)


def _dask_task(task: Task, case: dict):
    """One case on a Dask worker; the state is built once per worker process and task."""
    if _WORKER.get("key") != task.key():
        init_worker(task)
    return work(case)


def run_dask(task: Task, cases, record, workers: int, scheduler: str | None):
    """Submit the cases to a Dask cluster. A LocalCluster is started with DASK_QUIET_WORKERS:
    the workers' statistical profiler and the event loop's 20 ms tick take the GIL from the
    CPU-bound Python cases (the profiler cost 18 % of throughput; with it off, the tick and
    monitors still cost 15-18 %, and 3-5 % at the intervals below). Start external workers
    with the same settings as environment variables (README)."""
    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError, TypeError) as e:
            from drake_entry.errors import ScenarioError

            reason = " ".join(str(e).split()) or type(e).__name__
            raise ScenarioError(f"--scheduler {scheduler}: no Dask scheduler answered within {SCHEDULER_TIMEOUT_S} s "
                                f"({reason[:200]}); start one (dask scheduler) or omit --scheduler for a local "
                                f"cluster") from None
        workers = max(workers, len(client.scheduler_info().get("workers", {})))
    else:
        # the cluster's processes start with SIGINT ignored (kept across exec, and Python and
        # asyncio leave an ignored SIGINT alone): Ctrl-C is the parent's, which ends the cluster
        # and log only critical messages (a task cancelled, a heartbeat lost at Ctrl-C are not news;
        # a worker that fails is a failed row of its case)
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        env = os.environ.get("DASK_LOGGING__DISTRIBUTED")
        os.environ["DASK_LOGGING__DISTRIBUTED"] = env or "critical"
        try:
            # no dashboard; the scheduler's own HTTP server (health, metrics) on a free port, as
            # its default 8787 is taken whenever another cluster runs (a warning on stderr)
            with dask.config.set(DASK_QUIET_WORKERS):
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"})
        finally:
            signal.signal(signal.SIGINT, previous)
            if env is None:
                del os.environ["DASK_LOGGING__DISTRIBUTED"]
        client = Client(cluster)
    try:
        pending = iter(cases)  # submitted a few per worker at a time: a lazy case list stays lazy
        futures = {}

        def submit_next(queue=None) -> None:
            case = next(pending, None)
            if case is not None:
                fut = client.submit(_dask_task, task, case, pure=False)
                futures[fut] = case
                if queue is not None:
                    queue.add(fut)

        for _ in range(IN_FLIGHT_PER_WORKER * max(workers, 1)):
            submit_next()
        queue = as_completed(list(futures))
        for fut in queue:
            case = futures.pop(fut)
            try:
                row, traj = fut.result()
            except Exception as e:  # the worker itself died: record and go on
                row, traj = failed_row(case, f"worker failure: {type(e).__name__}: {e}"), None
            record(row, traj)
            submit_next(queue)
    except KeyboardInterrupt:  # the cluster's own shutdown warnings would follow the one line
        import logging

        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_backend(backend: str, task: Task, cases: list, record, *, workers: int, scheduler: str | None = None):
    """Run ``cases`` of ``task`` on ``backend`` and ``record(row, trajectory)`` each as it finishes."""
    if backend == "serial" or (backend == "processes" and workers == 1):
        run_serial(task, cases, record)
    elif backend == "processes":
        run_processes(task, cases, record, workers)
    else:
        run_dask(task, cases, record, workers, scheduler)
