"""Benchmark: cost per sample of the paper-000 closed-loop campaign, this checkout against a
baseline commit (default: the last commit before the guidance-method interface), measured
side by side in one run.

Each side runs the same samples (horus2b, Table 2 dispersions, seed 7) serially in a fresh
process, interleaved over ``rounds``; each keeps its best round (timing on a shared 2-core
machine drifts by about 20 % from minute to minute). The rows of both sides are compared
too: the interface must not change them. Goal: cost per sample within 5 % of the baseline.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tarfile
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASELINE = "0032fd2"  # main before the guidance-method interface 
TIMING = ("wall_time_s", "planning_wall_s")

_SCRIPT = """
import json, sys, time
from drake_entry.scenario import load_scenario
n, seed = int(sys.argv[1]), int(sys.argv[2])
try:  # the guidance-method interface
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup
    from drake_entry.campaign.sample import run_sample
    args = (ClosedLoopSetup.from_scenario(load_scenario("horus2b")),)
except ImportError:  # before it (the planner's module path of that time)
    from drake_entry.campaign.montecarlo import run_sample
    from drake_entry.planning.drag_energy import DragEnergyPlanner
    s = load_scenario("horus2b")
    args = (s, DragEnergyPlanner.from_scenario(s))
t0 = time.perf_counter()
rows = [run_sample(*args, seed, i, trajectory_step_s=10.0)[0] for i in range(n)]
print(json.dumps({"wall": time.perf_counter() - t0, "rows": rows}, default=float))
"""


def _checkout(revision: str, into: str) -> str:
    """The tree of ``revision`` extracted into a directory (no worktree metadata)."""
    archive = os.path.join(into, "tree.tar")
    subprocess.run(["git", "-C", ROOT, "archive", "-o", archive, revision], check=True)
    tree = os.path.join(into, "tree")
    with tarfile.open(archive) as tar:
        tar.extractall(tree, filter="data")
    return tree


def _installed_layout(tree: str, into: str) -> str:
    """A directory importable as the tree installs: drake_entry/ with systems/ and diagrams/
    inside it (pyproject's package-dir), made of symbolic links in ``into``."""
    site = os.path.join(into, os.path.basename(tree) + "_site")
    package = os.path.join(site, "drake_entry")
    if not os.path.isdir(package):
        os.makedirs(package)
        for entry in os.listdir(os.path.join(tree, "drake_entry")):
            os.symlink(os.path.join(tree, "drake_entry", entry), os.path.join(package, entry))
        for name in ("systems", "diagrams"):
            if not os.path.exists(os.path.join(package, name)):
                os.symlink(os.path.join(tree, name), os.path.join(package, name))
    return site


def _run(site: str, samples: int, seed: int) -> dict:
    """The samples run by the tree laid out in ``site`` (its working directory and import path)."""
    env = dict(os.environ, PYTHONPATH=site)
    out = subprocess.run([sys.executable, "-c", _SCRIPT, str(samples), str(seed)], cwd=site, env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def interface_cost_benchmark(*, baseline: str | None = None, rounds: int = 3, samples: int = 20,
                             seed: int = 7) -> dict:
    baseline = baseline or BASELINE
    with tempfile.TemporaryDirectory() as tmp:
        trees = {f"baseline {baseline}": _installed_layout(_checkout(baseline, tmp), tmp),
                 "this checkout": _installed_layout(ROOT, tmp)}
        walls = {k: [] for k in trees}
        rows = {}
        print(f"paper-000 campaign cost per sample: {samples} samples (seed {seed}) serially per side, "
              f"{rounds} interleaved round(s)")
        for r in range(rounds):
            for label, tree in trees.items():
                res = _run(tree, samples, seed)
                walls[label].append(res["wall"] / samples)
                rows[label] = res["rows"]
                print(f"round {r + 1}: {label:24s} {walls[label][-1]:.3f} s per sample")
    (base_label, base), (cur_label, cur) = ((k, min(v)) for k, v in walls.items())
    same = all({k: v for k, v in a.items() if k in b and k not in TIMING}
               == {k: v for k, v in b.items() if k in a and k not in TIMING}
               for a, b in zip(*rows.values()))
    print(f"best: {base_label} {base:.3f} s, {cur_label} {cur:.3f} s per sample; ratio {cur / base:.3f} "
          f"(goal <= 1.05); rows identical in their common columns: {'yes' if same else 'NO'}")
    return {"baseline_s": base, "current_s": cur, "ratio": cur / base, "rows_identical": same}
