"""Benchmark: a campaign worker's memory, this checkout against a baseline commit (default: the
previous one), measured side by side in one run.

For each scenario and side, in a fresh process: the campaign worker's set-up (models and the
method's planner), then ``samples`` campaign samples (seed 7) through ``run_sample``, with
the resident memory and the number of live Python systems (LeafSystem instances written in
Python, after a full garbage collection) read after the set-up and after each sample. The
growth per sample is the least-squares slope of the resident memory over samples 2..N (the
first warms caches). A worker that keeps what its samples built grows without bound: before
the flown diagrams were released (systems/lifetime.py), an SCvx worker grew by about 0.2 GB a
sample. The rows of both sides are compared (verdicts and terminal distances): memory is never
bought with accuracy.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from interface_cost import _checkout, _installed_layout

#: the scenarios measured by default and their samples: a drag-energy SOCP worker, the SCvx and
#: LGL re-planning workers (which built a verification diagram per plan), paper 004's swarm
DEFAULT_SAMPLES = {"horus2b": 8, "sphynx_paper001_flight": 4, "marv_guidance": 4, "cav_h_paper004_flight": 4}

_SCRIPT = r"""
import gc, json, sys
import psutil
from pydrake.systems.framework import LeafSystem
from drake_entry.scenario import load_scenario
from drake_entry.diagrams.closed_loop import ClosedLoopSetup
from drake_entry.campaign.sample import run_sample

def state():
    gc.collect()
    live = sum(1 for o in gc.get_objects()
               if isinstance(o, LeafSystem) and not type(o).__module__.startswith("pydrake."))
    return psutil.Process().memory_info().rss / 1e6, live

name, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
setup = ClosedLoopSetup.from_scenario(load_scenario(name))
after = [state()]
rows = []
for i in range(n):
    rows.append(run_sample(setup, seed, i, trajectory_step_s=10.0)[0])
    after.append(state())
print(json.dumps({"rss_mb": [a[0] for a in after], "live": [a[1] for a in after],
                  "rows": [{k: r.get(k) for k in ("success", "err_distance_m")} for r in rows]}, default=float))
"""


def _run(site: str, scenario: str, samples: int, seed: int) -> dict:
    env = dict(os.environ, PYTHONPATH=site)
    out = subprocess.run([sys.executable, "-c", _SCRIPT, scenario, str(samples), str(seed)], cwd=site, env=env,
                         capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(f"measuring {scenario} in {site} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def growth_mb_per_sample(rss_mb: list) -> float:
    """Least-squares slope [MB/sample] of the resident memory after samples 2..N (rss_mb[0]:
    after the set-up; rss_mb[i]: after sample i)."""
    after = np.asarray(rss_mb[2:], float)
    if after.size < 2:
        return float("nan")
    return float(np.polyfit(np.arange(after.size), after, 1)[0])


def memory_benchmark(*, baseline: str = "HEAD~1", only: list | None = None, seed: int = 7) -> dict:
    """Print and return {scenario: {side: {rss_mb, live, rows, growth_mb}}, ratio}; ``only``:
    packaged scenarios (default DEFAULT_SAMPLES's)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    names = only or list(DEFAULT_SAMPLES)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        sides = {f"baseline {baseline}": _installed_layout(_checkout(baseline, tmp), tmp),
                 "this checkout": _installed_layout(root, tmp)}
        print(f"campaign worker memory, {baseline} against this checkout (seed {seed}): resident MB after the "
              "set-up and after the last sample, growth per sample (slope over samples 2..N), live Python systems")
        print(f"{'scenario':24s} {'side':22s} {'samples':>7s} {'setup MB':>9s} {'last MB':>8s} {'MB/sample':>10s} "
              f"{'systems':>8s}")
        for name in names:
            n = DEFAULT_SAMPLES.get(name, 4)
            res = {label: _run(site, name, n, seed) for label, site in sides.items()}
            for label, r in res.items():
                r["growth_mb"] = growth_mb_per_sample(r["rss_mb"])
                print(f"{name:24s} {label:22s} {n:7d} {r['rss_mb'][0]:9.0f} {r['rss_mb'][-1]:8.0f} "
                      f"{r['growth_mb']:10.1f} {r['live'][-1]:8d}")
            (_, a), (_, b) = res.items()
            same = all(x["success"] == y["success"] for x, y in zip(a["rows"], b["rows"]))
            diff = max((abs((x["err_distance_m"] or 0.0) - (y["err_distance_m"] or 0.0))
                        for x, y in zip(a["rows"], b["rows"])), default=0.0)
            grown = (b["rss_mb"][-1] - b["rss_mb"][0]) / max(a["rss_mb"][-1] - a["rss_mb"][0], 1e-9)
            print(f"{'':24s} growth over the samples, this/baseline {grown:.3f}; verdicts equal: {same}; largest "
                  f"terminal-distance difference {diff:.3g} m")
            out[name] = {**res, "ratio": grown, "verdicts_equal": same, "max_distance_difference_m": diff}
    return out
