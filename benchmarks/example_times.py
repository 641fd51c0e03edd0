"""Benchmark: every example's wall time, exit status and last line, measured now and put beside
the time docs/examples.md gives for it (ratio measured / documented; more than 2x off is a
finding to report, not to paper over). ``--write`` puts the measured times into the docs table.

    python benchmarks/run.py examples [--mode quick|full|both] [--only 05 07] [--write]

Each example runs as a user runs it, ``python examples/NAME.py [--quick] --out DIR`` in a fresh
process (so Drake's import is counted), one at a time; its exit status is its claims' verdict
(``drake_entry.claims``).
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples")
DOCS = os.path.join(ROOT, "docs", "examples.md")
#: a docs row: | `NAME.py` | what | QUICK / FULL |
ROW = re.compile(r"^(?P<head>\| `(?P<name>\d\d_\w+)\.py` \|.*\| )(?P<quick>[^|/]+?) / (?P<full>[^|/]+?)(?P<end> \|)$")


def parse_time(text: str) -> float:
    """Seconds of '2.7 s', '33 s', '1 min', '1.5 min' (nan when unreadable)."""
    m = re.fullmatch(r"\s*([\d.]+)\s*(s|min)\s*", text)
    if not m:
        return float("nan")
    return float(m.group(1)) * (60.0 if m.group(2) == "min" else 1.0)


def format_time(seconds: float) -> str:
    """The docs' form: one decimal under 10 s, whole seconds under 2 min, then minutes."""
    if seconds < 10.0:
        return f"{seconds:.1f} s"
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    return f"{seconds / 60.0:.1f} min"


def documented() -> dict:
    """{name: {'quick': s, 'full': s}} from docs/examples.md."""
    out = {}
    for line in open(DOCS).read().splitlines():
        m = ROW.match(line)
        if m:
            out[m.group("name")] = {"quick": parse_time(m.group("quick")), "full": parse_time(m.group("full"))}
    return out


def run_example(name: str, mode: str, out_dir: str) -> dict:
    """Run one example in a fresh process: wall time [s], exit status, last output line."""
    cmd = [sys.executable, os.path.join(EXAMPLES, f"{name}.py"), "--out", os.path.join(out_dir, f"{name}_{mode}")]
    if mode == "quick":
        cmd.append("--quick")
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    out = [s for s in proc.stdout.splitlines() if s.strip()]
    lines = out + [s for s in proc.stderr.splitlines() if s.strip()]
    warnings = [s for s in lines if "Warning" in s or "nan" in s.split() or "verified False" in s]
    failed = [s.strip() for s in out if "[FAILED]" in s]
    return {"name": name, "mode": mode, "wall_s": wall, "exit": proc.returncode, "last": out[-1] if out else "",
            "warnings": warnings + failed}


def write_docs(measured: list) -> None:
    """Replace the documented times of the measured examples in docs/examples.md."""
    by = {(m["name"], m["mode"]): m["wall_s"] for m in measured}
    lines = open(DOCS).read().splitlines()
    for i, line in enumerate(lines):
        m = ROW.match(line)
        if not m:
            continue
        quick = by.get((m.group("name"), "quick"))
        full = by.get((m.group("name"), "full"))
        q = format_time(quick) if quick is not None else m.group("quick")
        f = format_time(full) if full is not None else m.group("full")
        lines[i] = f"{m.group('head')}{q} / {f}{m.group('end')}"
    with open(DOCS, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def examples_benchmark(mode: str = "both", only=None, write: bool = False) -> list:
    names = sorted(f[:-3] for f in os.listdir(EXAMPLES) if re.match(r"\d\d_\w+\.py$", f))
    if only:
        names = [n for n in names if n.split("_")[0] in only or n in only]
    docs = documented()
    modes = ("quick", "full") if mode == "both" else (mode,)
    print("examples: wall time (fresh process, one at a time) against docs/examples.md; exit = the example's claims")
    print(f"{'example':24s} {'mode':5s} {'exit':>4s} {'wall':>9s} {'documented':>10s} {'ratio':>6s}  last line")
    measured = []
    with tempfile.TemporaryDirectory() as out_dir:
        for name in names:
            for m in modes:
                r = run_example(name, m, out_dir)
                doc = docs.get(name, {}).get(m, float("nan"))
                ratio = r["wall_s"] / doc if doc == doc else float("nan")
                flag = "  FINDING: more than 2x off" if ratio == ratio and not 0.5 <= ratio <= 2.0 else ""
                print(f"{name:24s} {m:5s} {r['exit']:4d} {format_time(r['wall_s']):>9s} "
                      f"{format_time(doc) if doc == doc else '-':>10s} {ratio:6.2f}  {r['last'][:90]}{flag}")
                for w in r["warnings"][:3]:
                    print(f"{'':24s} warning: {w[:120]}")
                measured.append({**r, "documented_s": doc, "ratio": ratio})
    failed = [r for r in measured if r["exit"] != 0]
    print(f"{len(measured) - len(failed)} of {len(measured)} runs exit 0"
          + (": FAILED " + ", ".join(f"{r['name']} ({r['mode']})" for r in failed) if failed else ""))
    if write:
        write_docs(measured)
        print(f"wrote the measured times into {os.path.relpath(DOCS, ROOT)}")
    return measured
