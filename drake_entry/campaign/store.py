"""The durable campaign directory: a fingerprinted manifest, one writer at a time, rows and
trajectories streamed as samples finish.

  campaign.json          manifest: the scenario as flown (canonical YAML, overrides applied),
                         seed, trajectory step, versions, the fingerprint of all of these,
                         the number of samples requested so far, and one ``sessions`` record
                         per run (date, command, library versions, commit: not identity)
  campaign.json.copy     the same manifest, written with it (restores a damaged campaign.json)
  campaign.lock          held (flock) by the one process writing the directory, removed when it
                         closes
  samples.jsonl          one row per finished sample, appended and flushed at once
  trajectories.jsonl     its down-sampled trajectory, appended just before its row
  quarantine.jsonl       lines that were not rows or trajectories, moved aside on resume
  nominal.json           the undispersed flight of the scenario (not a sample), for the report
  samples.parquet, trajectories.parquet   written by ``finalise`` (sorted by sample index)

A sample counts as done when its row line is complete. An interrupted campaign resumes
without losing or repeating a sample: a cut last line is dropped and that sample runs
again; its earlier trajectory line (written before the row) is superseded by the new one.
A directory holding a campaign with another fingerprint is refused with one line; more
``runs`` with the same settings extend it.
"""
from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import os

from drake_entry.errors import CampaignError

__all__ = ["FORMAT", "ROWS", "TRAJECTORIES", "QUARANTINE", "MANIFEST", "LOCK", "MANIFEST_COPY", "MANIFEST_TYPES",
           "NOMINAL", "IDENTITY", "OPTIONAL_IDENTITY", "fingerprint", "CampaignStore", "write_atomic",
           "read_manifest", "read_rows", "write_nominal", "read_nominal", "read_trajectories", "repair", "finalise",
           "done_indices", "coverage"]

FORMAT = 2
ROWS, TRAJECTORIES, QUARANTINE, MANIFEST, LOCK = ("samples.jsonl", "trajectories.jsonl", "quarantine.jsonl",
                                                  "campaign.json", "campaign.lock")
#: a second copy of the manifest, written with it: a damaged campaign.json is restored from it
MANIFEST_COPY = "campaign.json.copy"
#: the types a sound manifest's fields have (checked when read)
MANIFEST_TYPES = {"runs": int, "seed": int, "trajectory_step_s": (int, float), "scenario_yaml": str,
                  "format": int, "fingerprint": str, "overrides": dict, "sessions": list, "versions": dict}
#: the undispersed flight of the campaign's scenario (trajectory columns), not a sample
NOMINAL = "nominal.json"
# what the fingerprint covers, and how a mismatch is named
IDENTITY = {"scenario_yaml": "scenario content", "vehicle_file_sha256": "vehicle file content",
            "seed": "seed", "trajectory_step_s": "trajectory step", "versions": "drake_entry/drake version",
            "atmosphere_file_sha256": "atmosphere table content", "task": "task settings",
            "cases_sha256": "case list"}
#: identity keys that count only when set (added after campaigns were written without them;
#: 'task' and 'cases_sha256' belong to campaigns of generic cases, campaign.engine)
OPTIONAL_IDENTITY = ("atmosphere_file_sha256", "task", "cases_sha256")


def fingerprint(manifest: dict) -> str:
    """sha256 of everything that defines a campaign's samples (IDENTITY)."""
    ident = {k: manifest.get(k) for k in IDENTITY if k not in OPTIONAL_IDENTITY or manifest.get(k) is not None}
    return hashlib.sha256(json.dumps(ident, sort_keys=True).encode()).hexdigest()


class CampaignStore:
    """One writer's handle on a campaign directory (a context manager holding the lock)."""

    def __init__(self, out_dir: str, manifest: dict):
        """Open (or create) ``out_dir`` for a campaign described by ``manifest`` (see
        IDENTITY; ``runs`` is the number requested). Raises CampaignError when the directory
        holds another campaign or another process writes it."""
        if os.path.exists(out_dir) and not os.path.isdir(out_dir):
            raise CampaignError(f"--out {out_dir} is a file, not a campaign directory")
        self.out_dir = out_dir
        os.makedirs(out_dir, exist_ok=True)
        self._lock = self._acquire_lock()
        os.ftruncate(self._lock, 0)
        os.write(self._lock, str(os.getpid()).encode())
        try:
            self.manifest = self._check_manifest(manifest)
            repair(out_dir)
        except BaseException:
            self.close()
            raise
        self._rows = self._traj = None

    def _acquire_lock(self) -> int:
        """The exclusive flock on campaign.lock (created if absent). The writer removes the file
        when it closes, so a lock taken on a file that was removed meanwhile is retaken on the
        new one (the inode must be the path's)."""
        path = self.path(LOCK)
        for _ in range(100):
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as e:
                os.close(fd)
                if e.errno in (errno.EWOULDBLOCK, errno.EACCES):
                    raise CampaignError(f"{self.out_dir} is being written by another campaign process; wait for it "
                                        f"to finish or use another --out") from None
                raise
            try:
                same = os.fstat(fd).st_ino == os.stat(path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                return fd
            os.close(fd)  # the previous writer removed it between our open and our lock: again
        raise CampaignError(f"{self.out_dir}: could not take the campaign lock (it kept being replaced)")

    def _check_manifest(self, manifest: dict) -> dict:
        manifest = dict(manifest, format=FORMAT)
        manifest["fingerprint"] = fingerprint(manifest)
        old = read_manifest(self.out_dir)
        if old is not None:
            if old.get("format") != FORMAT:
                raise CampaignError(f"{self.out_dir} holds a campaign written by an older drake_entry (format "
                                    f"{old.get('format', 1)}); `drake-entry report` still reads it; extend nothing "
                                    f"there: start afresh with another --out")
            if old.get("fingerprint") != manifest["fingerprint"]:
                differs = [name for key, name in IDENTITY.items() if old.get(key) != manifest.get(key)]
                raise CampaignError(
                    f"{self.out_dir} holds a campaign with another {', '.join(differs) or 'format'}; extend it "
                    f"with the same settings and a larger --runs, or start afresh with another --out")
            manifest["runs"] = max(int(old.get("runs", 0)), int(manifest["runs"]))
            manifest["sessions"] = list(old.get("sessions", [])) + list(manifest.get("sessions", []))
        data = json.dumps(manifest, indent=2).encode()
        write_atomic(self.path(MANIFEST), data)
        write_atomic(self.path(MANIFEST_COPY), data)
        return manifest

    def path(self, name: str) -> str:
        return os.path.join(self.out_dir, name)

    def done_indices(self) -> set:
        return done_indices(self.out_dir)

    def __enter__(self) -> "CampaignStore":
        flags = os.O_WRONLY | os.O_APPEND | os.O_CREAT
        self._rows = os.open(self.path(ROWS), flags, 0o644)
        self._traj = os.open(self.path(TRAJECTORIES), flags, 0o644)
        return self

    def __exit__(self, *exc):
        for fd in (self._rows, self._traj):
            if fd is not None:
                os.close(fd)
        self._rows = self._traj = None
        self.close()

    def close(self):
        """Release the lock and remove campaign.lock (removed while still held, so no other
        writer can hold a lock on a file that is gone: see ``_acquire_lock``)."""
        if self._lock is not None:
            try:
                os.unlink(self.path(LOCK))
            except FileNotFoundError:
                pass
            os.close(self._lock)  # releases the flock
            self._lock = None

    def record(self, row: dict, trajectory: dict | None):
        """Commit one finished sample: its trajectory line, then its row line (the row is
        what marks it done), each one write on an O_APPEND descriptor, then fsync."""
        if trajectory is not None:
            _append(self._traj, json.dumps(trajectory), self.path(TRAJECTORIES))
        _append(self._rows, json.dumps(row, default=float), self.path(ROWS))

    def finalise(self):
        finalise(self.out_dir)


def _append(fd: int, line: str, path: str):
    """Append one line to ``path`` (open as ``fd``) and fsync it. A short write (a full disk
    takes what fits) raises ENOSPC naming the file: the cut line is dropped on resume."""
    data = (line + "\n").encode()
    written = os.write(fd, data)
    if written != len(data):
        raise OSError(errno.ENOSPC, f"no space left on the device (wrote {written} of {len(data)} bytes of a line)",
                      path)
    os.fsync(fd)


def write_atomic(path: str, data: bytes):
    """Replace ``path`` by ``data`` atomically (write a temporary file, fsync, rename)."""
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _manifest_problem(path: str) -> tuple[dict | None, str]:
    """(manifest, '') from ``path``, or (None, what is wrong with it)."""
    try:
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        return None, f"not JSON ({e})"
    except IsADirectoryError:
        return None, "a directory"
    if not isinstance(manifest, dict):
        return None, "not a JSON object"
    for key, kinds in MANIFEST_TYPES.items():
        if key in manifest and (isinstance(manifest[key], bool) or not isinstance(manifest[key], kinds)):
            return None, f"its {key!r} is {manifest[key]!r}"
    if isinstance(manifest.get("runs"), int) and manifest["runs"] < 0:
        return None, f"its 'runs' is {manifest['runs']}"
    return manifest, ""


def read_manifest(out_dir: str) -> dict | None:
    """The campaign manifest of ``out_dir`` (None when there is none). A damaged campaign.json
    is replaced by its copy (campaign.json.copy, written with it) when that one is sound."""
    path, copy = os.path.join(out_dir, MANIFEST), os.path.join(out_dir, MANIFEST_COPY)
    if not os.path.exists(path):
        if os.path.exists(copy):
            manifest, _ = _manifest_problem(copy)
            return manifest
        return None
    manifest, problem = _manifest_problem(path)
    if manifest is not None:
        return manifest
    backup, _ = _manifest_problem(copy) if os.path.exists(copy) else (None, "")
    if backup is not None:
        try:
            write_atomic(path, json.dumps(backup, indent=2).encode())
        except OSError:
            pass  # read-only: the copy serves this time
        return backup
    raise CampaignError(f"{path} is not a campaign manifest ({problem}) and has no sound copy; its rows are in "
                        f"{ROWS}; start afresh with another --out") from None


def _is_row(r) -> bool:
    return isinstance(r, dict) and isinstance(r.get("index"), int) and "success" in r


def _is_trajectory(t) -> bool:
    return (isinstance(t, dict) and isinstance(t.get("sample"), list) and len(t["sample"]) > 0
            and all(isinstance(v, list) and len(v) == len(t["sample"]) for v in t.values()))


def _read_lines(path: str) -> tuple[list, bool]:
    """(complete lines, whether a cut last line was present)."""
    if not os.path.exists(path):
        return [], False
    with open(path, "rb") as f:
        data = f.read()
    cut = bool(data) and not data.endswith(b"\n")
    lines = data.split(b"\n")
    return [line for line in lines[:-1] if line.strip()], cut


def _parse(lines: list, valid) -> tuple[list, list]:
    """(parsed objects that pass ``valid``, raw lines that do not)."""
    good, bad = [], []
    for raw in lines:
        try:
            obj = json.loads(raw)
        except (json.JSONDecodeError, UnicodeDecodeError):
            obj = None
        if obj is not None and valid(obj):
            good.append(obj)
        else:
            bad.append(raw)
    return good, bad


def read_rows(out_dir: str) -> tuple[dict, dict]:
    """({index: row} of the complete rows (the first of duplicates), counts:
    {'cut': cut last lines, 'invalid': lines that are not rows, 'duplicates': ...})."""
    lines, cut = _read_lines(os.path.join(out_dir, ROWS))
    rows, bad = _parse(lines, _is_row)
    out, dup = {}, 0
    for r in rows:
        if r["index"] in out:
            dup += 1
        else:
            out[r["index"]] = r
    return out, {"cut": int(cut), "invalid": len(bad), "duplicates": dup}


def write_nominal(out_dir: str, columns: dict) -> None:
    """Keep the campaign's nominal flight (trajectory columns; atomically)."""
    write_atomic(os.path.join(out_dir, NOMINAL), json.dumps(columns).encode())


def read_nominal(out_dir: str) -> dict | None:
    """The campaign's nominal flight, or None when it was not flown (or not readable)."""
    try:
        with open(os.path.join(out_dir, NOMINAL)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def read_trajectories(out_dir: str, done: set) -> dict:
    """{sample: columns} of the samples in ``done``: the last trajectory line of each (a
    sample that re-ran after an interruption supersedes its earlier line)."""
    lines, _ = _read_lines(os.path.join(out_dir, TRAJECTORIES))
    trajs, _ = _parse(lines, _is_trajectory)
    out = {}
    for t in trajs:
        s = t["sample"][0]
        if s in done:
            out[s] = t
    return out


def repair(out_dir: str) -> dict:
    """Make the streams appendable again (under the writer's lock): drop cut last lines and
    move lines that are not rows or trajectories to quarantine.jsonl. Returns the counts."""
    report = {}
    for name, valid in ((ROWS, _is_row), (TRAJECTORIES, _is_trajectory)):
        path = os.path.join(out_dir, name)
        lines, cut = _read_lines(path)
        _, bad = _parse(lines, valid)
        report[name] = {"cut": int(cut), "quarantined": len(bad)}
        if not cut and not bad:
            continue
        bad_set = set(bad)
        keep = [line for line in lines if line not in bad_set]
        if bad:
            with open(os.path.join(out_dir, QUARANTINE), "ab") as q:
                for raw in bad:
                    q.write(json.dumps({"file": name, "line": raw.decode("utf-8", "replace")}).encode() + b"\n")
        write_atomic(path, b"".join(line + b"\n" for line in keep))
    return report


def finalise(out_dir: str):
    """Write samples.parquet (every complete row, sorted by index) and trajectories.parquet
    (the trajectory of each of those samples that kept one)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows, _ = read_rows(out_dir)
    ordered = [rows[k] for k in sorted(rows)]
    keys = sorted({k for r in ordered for k in r if k != "traceback"})
    pq.write_table(pa.table({k: [r.get(k) for r in ordered] for k in keys}), os.path.join(out_dir, "samples.parquet"))
    trajs = read_trajectories(out_dir, set(rows))
    path = os.path.join(out_dir, "trajectories.parquet")
    if trajs:
        cols = {}
        for s in sorted(trajs):
            for k, v in trajs[s].items():
                cols.setdefault(k, []).extend(v)
        n = len(cols["sample"])
        cols = {k: v for k, v in cols.items() if len(v) == n}  # columns every trajectory has
        pq.write_table(pa.table(cols), path)
    elif os.path.exists(path):
        os.remove(path)


def done_indices(out_dir: str) -> set:
    """Sample indices with a complete row."""
    return set(read_rows(out_dir)[0])


def coverage(out_dir: str, row_problem=None) -> dict:
    """What a campaign directory holds, for reports: requested runs, complete rows, cut and
    invalid lines still in the streams, quarantined lines. ``row_problem(row)``: why a row is
    not one of this campaign's (''), e.g. campaign.rows.row_problem; such rows are counted
    invalid. CampaignError when it holds no campaign, or rows of which none is one."""
    if not os.path.isdir(out_dir):
        raise CampaignError(f"{out_dir} is not a directory: no campaign to report")
    manifest = read_manifest(out_dir)
    rows, counts = read_rows(out_dir)
    if manifest is None and not rows:
        raise CampaignError(f"{out_dir} holds no campaign (no campaign.json, no rows): run `drake-entry campaign` first")
    if row_problem is not None:
        problems = {i: row_problem(r) for i, r in rows.items()}
        bad = sorted(i for i, p in problems.items() if p)
        if bad and len(bad) == len(rows):
            raise CampaignError(f"{os.path.join(out_dir, ROWS)}: none of its {len(rows)} row(s) is a campaign row "
                                f"(index {bad[0]}: {problems[bad[0]][:200]}); nothing to report")
        rows = {i: r for i, r in rows.items() if not problems[i]}
        counts["invalid"] += len(bad)
    quarantined = len(_read_lines(os.path.join(out_dir, QUARANTINE))[0])
    return {"manifest": manifest or {}, "rows": rows, "requested": int((manifest or {}).get("runs", len(rows))),
            "quarantined": quarantined, **counts}
