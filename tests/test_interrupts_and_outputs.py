"""Ctrl-C, output locations, full disks and runaway sizes: one line, the right exit code, no
process left behind, no finished sample lost."""
import errno
import json
import os
import signal
import subprocess
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drake_entry.campaign.arguments import MAX_RUNS, check_output_dir
from drake_entry.campaign.montecarlo import run_campaign
from drake_entry.campaign.store import done_indices
from drake_entry.cli import main
from drake_entry.cli.common import os_error_line
from drake_entry.errors import ScenarioError


def _rows(out: str) -> int:
    try:
        with open(os.path.join(out, "samples.jsonl")) as f:
            return sum(1 for line in f if line.endswith("}\n"))
    except FileNotFoundError:
        return 0


def _group_ended(pgid: int, within_s: float) -> bool:
    """True once no process of the group is left (a zombie waits for init to reap it)."""
    deadline = time.monotonic() + within_s
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


def _running_campaign(tmp_path, out: str, extra: list, sigint) -> subprocess.Popen:
    """A 12-sample horus2b campaign in its own process group with SIGINT at ``sigint``, once its
    first sample has landed. Its cwd is outside the repository: `python -m` puts the cwd first on
    the path, and the working tree is not the installed package."""
    argv = [sys.executable, "-m", "drake_entry.cli", "campaign", "horus2b", "--runs", "12", "--workers", "2",
            "--trajectory-step", "0", "--out", out, *extra]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            cwd=str(tmp_path), preexec_fn=lambda: signal.signal(signal.SIGINT, sigint))
    deadline = time.monotonic() + 300
    while _rows(out) < 1 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, ("the campaign ended before the signal could land", proc.communicate()[1][-2000:])
    return proc


def _stopped(proc: subprocess.Popen, send) -> tuple[str, list[str]]:
    """``send(pid)``, then the campaign's stderr and its lines other than the progress bar, once it
    exited 130."""
    send(proc.pid)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    return err, [line for line in err.replace("\r", "\n").splitlines() if line.strip() and "campaign:" not in line]


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
@pytest.mark.parametrize("backend", ["processes", "dask"])
def test_ctrl_c_ends_a_campaign_with_one_line_exit_130_and_no_worker_left(tmp_path, backend):
    """SIGINT to the whole process group (what a terminal's Ctrl-C does) once a sample has
    landed and before the last: exit 130, one line naming the finished count, no traceback,
    no pool worker alive afterwards; the rows on disk are the count the line names, and the
    same command resumes to the full campaign. Under Dask too (a LocalCluster's processes start
    with SIGINT ignored, so only the parent's one line is printed)."""
    if backend == "dask":
        pytest.importorskip("dask.distributed")
    out = str(tmp_path / "c")
    # SIGINT at its default in the child, as in a terminal's foreground job: a test run started in
    # the background of a shell without job control inherits SIGINT ignored
    proc = _running_campaign(tmp_path, out, ["--backend", backend], signal.SIG_DFL)
    err, lines = _stopped(proc, lambda pid: os.killpg(pid, signal.SIGINT))
    assert "Traceback" not in err and len(lines) == 1, lines
    finished = _rows(out)
    assert 1 <= finished < 12, finished  # the interrupt landed mid-campaign
    assert f"interrupted after {finished} of 12 campaign cases" in lines[0] and "same command to resume" in lines[0]
    left = subprocess.run(["ps", "-o", "pid,stat,args", "-g", str(proc.pid)], capture_output=True, text=True).stdout
    assert _group_ended(proc.pid, within_s=30.0), left  # nothing of the group survives (workers ended)
    assert not os.path.exists(os.path.join(out, "campaign.lock"))
    run_campaign("horus2b", runs=12, out_dir=out, workers=2, progress=False, trajectory_step_s=0)
    assert done_indices(out) == set(range(12))


@pytest.mark.slow  # a campaign: out of the default run, in CI's -m "slow and not long" set
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_campaign_started_in_the_background_stops_on_sigint_or_sigterm_keeping_its_samples(tmp_path, signum):
    """A campaign started as a shell's background job (SIGINT ignored, which Python leaves
    ignored) and signalled alone, as `kill -INT PID` or `kill PID` does: exit 130 with the one
    line naming the finished count, its workers ended, the lock released, the samples kept."""
    out = str(tmp_path / "c")
    proc = _running_campaign(tmp_path, out, [], signal.SIG_IGN)
    err, lines = _stopped(proc, lambda pid: os.kill(pid, signum))
    finished = _rows(out)
    assert "Traceback" not in err and len(lines) == 1 and f"interrupted after {finished} of 12" in lines[0], lines
    assert _group_ended(proc.pid, within_s=30.0)
    assert not os.path.exists(os.path.join(out, "campaign.lock")) and 1 <= finished < 12


def test_a_full_disk_keeps_finished_rows_and_names_the_file(tmp_path, monkeypatch, capsys):
    """The third row's write comes back short (what a full disk does): exit 2 with one line
    naming samples.jsonl and the cause; the two finished rows are intact and resume works."""
    import drake_entry.campaign.store as store

    real_write, rows_written = os.write, []

    def write(fd, data):
        if data.startswith(b'{"index"'):
            rows_written.append(fd)
            if len(rows_written) == 3:
                return real_write(fd, data[: len(data) // 2])
        return real_write(fd, data)

    monkeypatch.setattr(store.os, "write", write)
    out = str(tmp_path / "c")
    code = main(["campaign", "horus2b", "--runs", "4", "--workers", "1", "--trajectory-step", "0", "--out", out])
    err = capsys.readouterr().err
    tail = [line for line in err.replace("\r", "\n").splitlines() if line.startswith("drake-entry")]
    assert code == 2 and "Traceback" not in err and len(tail) == 1, err
    assert f"cannot use {out}/samples.jsonl: no space left on the device" in tail[0] and "resumes" in tail[0]
    assert done_indices(out) == {0, 1}
    monkeypatch.setattr(store.os, "write", real_write)
    run_campaign("horus2b", runs=4, out_dir=out, workers=1, progress=False, trajectory_step_s=0)
    assert done_indices(out) == {0, 1, 2, 3}
    with open(os.path.join(out, "samples.jsonl")) as f:
        kept = [json.loads(line) for line in f if line.endswith("}\n")]
    assert sorted(r["index"] for r in kept) == [0, 1, 2, 3]


@pytest.mark.parametrize("command", [["campaign", "horus2b", "--runs", "1"], ["fly", "horus2b"],
                                     ["simulate", "horus2b"], ["plan", "horus2b"]])
def test_out_below_a_regular_file_is_one_line_before_any_work(tmp_path, capsys, command):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    t0 = time.perf_counter()
    code = main(command + ["--out", str(blocker / "sub" / "dir")])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"{blocker} is a file, not a directory" in err
    assert time.perf_counter() - t0 < 5.0  # refused before flying anything


def test_an_os_error_from_any_command_is_one_line_naming_the_path(tmp_path, capsys, monkeypatch):
    """A read-only file system (simulated: os.makedirs refused with EROFS) in the report."""
    import drake_entry.cli.campaigns as campaigns

    def refuse(*a, **k):
        raise OSError(errno.EROFS, "Read-only file system", str(tmp_path / "r"))

    monkeypatch.setattr(campaigns, "write_and_print_report", refuse)
    (tmp_path / "r").mkdir()
    code = main(["report", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 2 and err.strip() == (f"drake-entry: error: cannot use {tmp_path / 'r'}: Read-only file system; "
                                         f"choose a writable --out")


def test_a_runaway_campaign_size_is_refused_at_once(tmp_path):
    t0 = time.perf_counter()
    with pytest.raises(ScenarioError, match=r"runs = 1000000000000 is out of range; allowed: an integer in \[1, 10000000\]"):
        run_campaign("horus2b", runs=10 ** 12, out_dir=str(tmp_path / "c"), progress=False)
    assert time.perf_counter() - t0 < 5.0 and MAX_RUNS == 10 ** 7
    assert not (tmp_path / "c").exists()


def test_an_unreachable_dask_scheduler_is_one_line(tmp_path, monkeypatch):
    pytest.importorskip("dask.distributed")
    import drake_entry.campaign.backends as backends

    monkeypatch.setattr(backends, "SCHEDULER_TIMEOUT_S", 1)
    with pytest.raises(ScenarioError, match=r"--scheduler tcp://127\.0\.0\.1:9: no Dask scheduler answered within 1 s"):
        run_campaign("horus2b", runs=1, out_dir=str(tmp_path / "c"), progress=False, backend="dask",
                     scheduler="tcp://127.0.0.1:9")


def test_a_scheduler_address_implies_the_dask_backend_in_the_engine_itself(tmp_path, monkeypatch):
    """An address with the default backend flies on Dask (the engine's rule, so a campaign, a
    comparison and publish all follow it); with backend 'serial' it is a contradiction, refused."""
    from drake_entry.campaign.engine import resolve_backend

    assert resolve_backend("processes", "tcp://host:8786") == "dask"
    assert resolve_backend("dask", "tcp://host:8786") == "dask"
    assert resolve_backend("processes", None) == "processes" and resolve_backend("serial", "") == "serial"
    with pytest.raises(ScenarioError, match=r"backend 'serial' with the Dask scheduler tcp://host:8786"):
        resolve_backend("serial", "tcp://host:8786")
    from drake_entry.comparison.runner import run_comparison

    for run in (run_campaign, run_comparison):  # refused before any search, plan or directory
        with pytest.raises(ScenarioError, match=r"backend 'serial' with the Dask scheduler"):
            run("horus2b", runs=1, out_dir=str(tmp_path / "s"), progress=False, backend="serial",
                scheduler="tcp://host:8786")
    assert not (tmp_path / "s").exists()
    pytest.importorskip("dask.distributed")
    import drake_entry.campaign.backends as backends

    monkeypatch.setattr(backends, "SCHEDULER_TIMEOUT_S", 1)  # the default backend reaches the Dask client
    with pytest.raises(ScenarioError, match=r"--scheduler tcp://127\.0\.0\.1:9: no Dask scheduler answered"):
        run_campaign("horus2b", runs=1, out_dir=str(tmp_path / "c"), progress=False, scheduler="tcp://127.0.0.1:9")


@settings(max_examples=60, deadline=None, derandomize=True, database=None)
@given(parts=st.lists(st.text(st.characters(blacklist_characters="/\0", blacklist_categories=("Cs",)), max_size=40)
                      .filter(lambda p: p not in (".", "..")), min_size=1, max_size=4),
       below_file=st.booleans(), long_name=st.booleans())
def test_fuzzed_output_locations_are_accepted_or_refused_in_one_line(tmp_path_factory, parts, below_file, long_name):
    """Any names as --out components (no '/', NUL, '.' or '..'): accepted (then created, or the
    OSError the CLI prints as one line) or one ScenarioError; below a regular file, always
    refused; never another exception."""
    base = tmp_path_factory.mktemp("out")
    if below_file:
        (base / "f").write_text("x")
        parts = ["f"] + parts
    if long_name:
        parts = parts + ["n" * 300]
    out = os.path.join(str(base), *parts)
    try:
        check_output_dir(out)
    except ScenarioError as e:
        assert "\n" not in str(e)
        return
    assert not below_file
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:  # what the CLI turns into one line (os_error_line)
        assert "cannot use" in os_error_line(e, out)


def slow_setup(config):
    """A toy campaign worker's state (killed-parent test)."""
    return {"pause_s": float(config["pause_s"])}


def slow_run(state, case):
    time.sleep(state["pause_s"])
    return {"index": case["index"], "success": True}, None


_KILLED_PARENT = """
import sys
sys.path.insert(0, sys.argv[1])
from drake_entry.campaign.backends import Task, run_processes
task = Task("test_interrupts_and_outputs:slow_setup", "test_interrupts_and_outputs:slow_run", {"pause_s": 0.5})
run_processes(task, [{"index": i} for i in range(1000)], lambda row, trajectory: print(row["index"], flush=True),
              workers=2)
"""


def test_the_workers_of_a_killed_campaign_end_on_their_own():
    """A campaign's main process killed outright (SIGKILL: no Ctrl-C handling, no clean-up) once
    its two local workers are flying cases: both workers end within a few seconds instead of
    waiting for ever for their next case (they check that their parent still runs)."""
    proc = subprocess.Popen([sys.executable, "-c", _KILLED_PARENT, os.path.dirname(os.path.abspath(__file__))],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    first = proc.stdout.readline()  # a case answered: the workers are up and flying
    assert first.strip().isdigit(), proc.stderr.read()[-2000:]
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    left = subprocess.run(["ps", "-o", "pid,stat,args", "-g", str(proc.pid)], capture_output=True, text=True).stdout
    assert _group_ended(proc.pid, within_s=15.0), left
