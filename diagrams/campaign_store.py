"""The durable campaign directory: settings, rows and trajectories streamed as they finish.

  campaign.json         the settings (scenario, seed, overrides, runs, trajectory step)
  samples.jsonl         one row per finished sample, appended and flushed at once
  trajectories.jsonl    its down-sampled trajectory (when kept)
  samples.parquet, trajectories.parquet   written by ``finalise`` (sorted by sample index)

An interrupted campaign resumes without losing or repeating a sample: a last line cut by
the interruption is dropped and that sample runs again.
"""
from __future__ import annotations

import json
import os

from drake_entry.errors import ScenarioError

IDENTITY_KEYS = ("scenario", "seed", "overrides")  # settings a resumed campaign must share


class CampaignStore:
    def __init__(self, out_dir: str, settings: dict):
        """Open (or create) ``out_dir`` for a campaign with ``settings``; a directory holding a
        campaign with other identity settings raises ValueError."""
        self.out_dir = out_dir
        os.makedirs(out_dir, exist_ok=True)
        meta_path = self.path("campaign.json")
        if os.path.exists(meta_path):
            with open(meta_path) as f:
                old = json.load(f)
            if {k: old.get(k) for k in IDENTITY_KEYS} != {k: settings.get(k) for k in IDENTITY_KEYS}:
                raise ScenarioError(f"{out_dir} holds a campaign with other settings ({old}); use another --out")
        with open(meta_path, "w") as f:
            json.dump(settings, f, indent=2)
        for name in ("samples.jsonl", "trajectories.jsonl"):
            _trim_partial_line(self.path(name))
        self._rows = self._traj = None

    def path(self, name: str) -> str:
        return os.path.join(self.out_dir, name)

    def done_indices(self) -> set:
        return done_indices(self.out_dir)

    def __enter__(self) -> "CampaignStore":
        self._rows = open(self.path("samples.jsonl"), "a")
        self._traj = open(self.path("trajectories.jsonl"), "a")
        return self

    def __exit__(self, *exc):
        self._rows.close()
        self._traj.close()

    def record(self, row: dict, trajectory: dict | None):
        """Append one finished sample (row, then its trajectory) and flush."""
        self._rows.write(json.dumps(row, default=float) + "\n")
        self._rows.flush()
        if trajectory is not None:
            self._traj.write(json.dumps(trajectory) + "\n")
            self._traj.flush()

    def finalise(self):
        finalise(self.out_dir)


def _trim_partial_line(path: str):
    """Drop a last line cut by an interruption, so appended rows start on a fresh line."""
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return
    with open(path, "rb+") as f:
        data = f.read()
        if data.endswith(b"\n"):
            return
        f.truncate(data.rfind(b"\n") + 1)


def done_indices(out_dir: str) -> set:
    """Sample indices with a complete row in ``out_dir``/samples.jsonl."""
    path = os.path.join(out_dir, "samples.jsonl")
    if not os.path.exists(path):
        return set()
    done = set()
    with open(path) as f:
        for line in f:
            try:
                done.add(json.loads(line)["index"])
            except (json.JSONDecodeError, KeyError):
                continue  # a line cut by an interruption: that sample runs again
    return done


def finalise(out_dir: str):
    """Convert the JSONL streams to Parquet tables (sorted by sample index)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = {}
    with open(os.path.join(out_dir, "samples.jsonl")) as f:
        for line in f:
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                continue
            rows[r["index"]] = r
    ordered = [rows[k] for k in sorted(rows)]
    keys = sorted({k for r in ordered for k in r if k != "traceback"})
    table = {k: [r.get(k) for r in ordered] for k in keys}
    pq.write_table(pa.table(table), os.path.join(out_dir, "samples.parquet"))
    cols = {}
    path = os.path.join(out_dir, "trajectories.jsonl")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                try:
                    t = json.loads(line)
                except json.JSONDecodeError:
                    continue
                for k, v in t.items():
                    cols.setdefault(k, []).extend(v)
        if cols:
            pq.write_table(pa.table(cols), os.path.join(out_dir, "trajectories.parquet"))
