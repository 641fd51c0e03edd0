"""The mission x method matrix: several comparison directories (one mission each) in one table.

Each cell is one method's campaign on one mission: successes of samples with the one-sided 90 %
lower Clopper-Pearson bound on the success probability, the miss distance's median and 95th
percentile over the samples that reached the interface, and the core seconds per sample; or why
the method was not flown (its first clause). Read from each directory's ``comparison.json`` and
``comparison_summary.json`` (drake_entry.comparison.report), so the matrix is regenerated from
the directories, never typed. Beside it, each mission's page ``derivations/<mission>.md`` (every
derived method's search: the candidates flown and which were kept) and the scenario each method
flew (``derivations/<mission>/<label>.yaml``: fly a cell again with ``drake-entry campaign``).

Rewriting a matrix file from directories of some of its missions keeps the other missions' rows
as the file had them, marked as carried (a row is only ever replaced by its mission's directory),
so a matrix too long to fly in one sitting is regenerated mission by mission, each row naming the
commits its derivation page gives.
"""
from __future__ import annotations

import json
import os
import re
import shutil

from drake_entry.campaign import statistics
from drake_entry.campaign.store import write_atomic
from drake_entry.comparison.report import derivation_tables, read_comparison_manifest
from drake_entry.errors import CampaignError

__all__ = ["LEVEL", "DERIVATIONS", "CARRIED", "success_lower_bound", "read_comparison", "read_matrix_rows",
           "matrix_markdown", "write_derivations", "write_matrix"]

#: the one-sided confidence of the success bound
LEVEL = 0.90
#: the folder, beside the matrix, of each mission's derivation page and flown scenarios
DERIVATIONS = "derivations"
#: the mark after a row's mission when the row is carried from the matrix file being rewritten
CARRIED = "(carried)"
_ROW = re.compile(r"^\| \[([^\]]+)\]\(" + DERIVATIONS + r"/[^)]+\.md\)(?: " + re.escape(CARRIED)
                  + r")? (\([^)]*\)) \| (.*) \|$")
_COMMIT = r"[0-9a-f]+(?:\+changes)?"
_ROW_COMMITS = re.compile(rf"in the matrix's row, commit ({_COMMIT}(?:, {_COMMIT})*) \(fly")


def success_lower_bound(successes: int, runs: int, level: float = LEVEL) -> float:
    """The matrix's bound: the one-sided ``level`` lower Clopper-Pearson bound on a success
    probability (campaign.statistics.success_lower_bound), 0 for a cell of no runs."""
    return statistics.success_lower_bound(successes, runs, level) if runs > 0 else 0.0


def read_comparison(folder: str) -> dict:
    """A comparison directory's manifest and summary: {'mission', 'name', 'runs', 'seed',
    'commits' (of every session that flew into it), 'methods': {label: {'method', 'flown', 'reason',
    'summary'}}}; CampaignError when it holds none."""
    paths = [os.path.join(folder, name) for name in ("comparison.json", "comparison_summary.json")]
    if not all(os.path.isfile(p) for p in paths):
        raise CampaignError(f"{folder} holds no comparison report (comparison.json and comparison_summary.json): "
                            f"run `drake-entry compare` into it first")
    with open(paths[0]) as f:
        manifest = json.load(f)
    with open(paths[1]) as f:
        summary = json.load(f)
    methods = {}
    for label, info in manifest["methods"].items():
        methods[label] = {"method": info["method"], "flown": bool(info.get("flown")),
                          "reason": info.get("reason") or "", "summary": summary["methods"].get(label),
                          "derived": bool(info.get("derivation"))}
    return {"mission": os.path.splitext(os.path.basename(manifest["mission"]))[0], "name": manifest["comparison"],
            "runs": manifest["runs"], "seed": manifest["seed"],
            "commits": [str(session.get("git_commit")) for session in manifest.get("sessions") or [{}]],
            "methods": methods}


def _cell(m: dict) -> str:
    s = m["summary"]
    if not m["flown"] or s is None:
        reason = m["reason"] or "not flown yet"
        short = reason.split(": ", 1)[1] if reason.startswith("cannot fly this mission: ") else reason
        first = short.split(";")[0].split(" (")[0]
        return "not flown: " + (first if len(first) <= 90 else first[:90].rsplit(" ", 1)[0] + " ...")
    k, n = s["successful"], s["samples"]
    text = f"**{k}/{n}** (>= {100 * success_lower_bound(k, n):.0f} %)"
    miss = s.get("miss_km")
    if miss:
        text += f", miss {miss['median']:.3g} / {miss['p95']:.3g} km"
    wall = s.get("wall_time_s")
    if wall:
        text += f", {wall['mean']:.2g} s"
    return text + (" *" if m["derived"] else "")


def _runs_text(comparison: dict) -> str:
    """'N runs' when every flown cell has N samples, 'runs per cell' when they differ (``--only``
    may fly an expensive method with fewer samples into the same directory), 'none flown'."""
    counts = {m["summary"]["samples"] for m in comparison["methods"].values() if m["flown"] and m["summary"]}
    return f"{counts.pop()} runs" if len(counts) == 1 else "runs per cell" if counts else "none flown"


def read_matrix_rows(path: str) -> dict:
    """The rows of a matrix file ``write_matrix`` wrote: {mission: {'runs': '(100 runs, seed 2026)',
    'cells': {label: cell text}, 'commits': [the commits its derivation page names]}} in the
    file's order; {} when there is no file."""
    if not os.path.isfile(path):
        return {}
    labels, rows = [], {}
    for line in open(path).read().splitlines():
        if line.startswith("| mission | "):
            labels = [c.strip() for c in line.strip("|").split("|")[1:]]
            continue
        match = _ROW.match(line)
        if not match or not labels:
            continue
        mission, runs, cells = match.groups()
        texts = [c.strip() for c in cells.split(" | ")]
        if len(texts) != len(labels):
            raise CampaignError(f"{path}: the row of {mission} has {len(texts)} cells against {len(labels)} methods "
                                f"in the header: not a matrix file drake-entry wrote; remove it or fix the row")
        page = os.path.join(os.path.dirname(os.path.abspath(path)), DERIVATIONS, f"{mission}.md")
        found = _ROW_COMMITS.search(open(page).read()) if os.path.isfile(page) else None
        rows[mission] = {"runs": runs, "cells": dict(zip(labels, texts)),
                         "commits": [c.strip() for c in found.group(1).split(",")] if found else []}
    return rows


def matrix_markdown(folders: list[str], *, links: bool = False, carried: dict | None = None) -> str:
    """The matrix of these comparison directories (rows: missions; columns: methods); with
    ``links`` each row names its mission's derivation page (``write_matrix`` writes them);
    ``carried``: the rows of an earlier matrix (``read_matrix_rows``): those of missions with no
    directory here are kept, marked CARRIED, in the earlier order, the directories' missions in
    place of their old rows (new missions last)."""
    comparisons = {c["name"]: c for c in (read_comparison(f) for f in folders)}
    earlier = carried or {}
    carried = {m: row for m, row in earlier.items() if m not in comparisons}
    order = list(earlier) + [name for name in comparisons if name not in earlier]
    labels = []
    for c in comparisons.values():
        labels += [label for label in c["methods"] if label not in labels]
    for row in carried.values():
        labels += [label for label in row["cells"] if label not in labels]
    out = ["| mission | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for name in order:
        link = f"[{name}]({DERIVATIONS}/{name}.md)" if links else name
        if name in comparisons:
            c = comparisons[name]
            cells = [_cell(c["methods"][label]) if label in c["methods"] else "—" for label in labels]
            out.append(f"| {link} ({_runs_text(c)}, seed {c['seed']}) | " + " | ".join(cells) + " |")
        else:
            row = carried[name]
            cells = [row["cells"].get(label, "—") for label in labels]
            out.append(f"| {link} {CARRIED} {row['runs']} | " + " | ".join(cells) + " |")
    out += ["", f"Each cell: successful/samples (the one-sided {100 * LEVEL:.0f} % lower Clopper-Pearson bound on the "
            f"success probability), the miss distance's median / 95th percentile over the samples that reached the "
            f"interface, core seconds per sample; * settings derived from the mission (the mission's own method "
            f"flies the mission's settings). Not flown: the method's own reason (its comparison report has it whole)."]
    if carried:
        out += ["", f"{CARRIED}: the row as the matrix had it before its mission was flown again into a kept "
                f"comparison directory (`drake-entry publish --missions MISSION`); its derivation page names the "
                f"commits it was flown at."]
    return "\n".join(out)


def write_derivations(folder: str, out_dir: str) -> str:
    """Write ``folder``'s derivation page, ``out_dir/<mission>.md`` (each derived method's search,
    drake_entry.comparison.report.derivation_tables; the scenario each method flew, copied to
    ``out_dir/<mission>/<label>.yaml``); returns the page's path."""
    c, meta = read_comparison(folder), read_comparison_manifest(folder)
    name = c["name"]
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    flown = []
    for label, info in meta["methods"].items():
        source = os.path.join(folder, info.get("scenario") or "")
        if info.get("flown") and os.path.isfile(source):
            shutil.copyfile(source, os.path.join(out_dir, name, f"{label}.yaml"))
            flown.append(f"- {label}: [{name}/{label}.yaml]({name}/{label}.yaml)"
                         + (" (derived)" if info.get("derivation") else " (the mission's own settings)"))
    text = "\n".join([
        f"# Settings of every method on {name}", "",
        f"The scenario each method flew in the matrix's row, commit {', '.join(sorted(set(c['commits'])))} (fly a "
        f"cell again: `drake-entry campaign {name}/LABEL.yaml --runs N --seed {c['seed']}`, N its samples):",
        "", *(flown or ["- none flown"]), "",
        derivation_tables(meta) or "No method's settings were derived on this mission.", ""])
    path = os.path.join(out_dir, f"{name}.md")
    write_atomic(path, text.encode())
    return path


def write_matrix(folders: list[str], path: str, *, title: str = "Every method on every mission",
                 carry: bool = True) -> str:
    """Write the matrix of ``folders`` to the Markdown file ``path`` and each mission's derivation
    page beside it (``write_derivations`` into DERIVATIONS); with ``carry`` the rows of missions
    with no directory among ``folders`` are kept from the file already at ``path`` (module doc).
    Returns ``path``."""
    earlier = read_matrix_rows(path) if carry else {}
    comparisons = [read_comparison(f) for f in folders]
    carried = {m: row for m, row in earlier.items() if m not in {c["name"] for c in comparisons}}
    commits = sorted({commit for c in comparisons for commit in c["commits"]}  # every session's: --only mixes
                     | {commit for row in carried.values() for commit in row["commits"]})
    for folder in folders:
        write_derivations(folder, os.path.join(os.path.dirname(os.path.abspath(path)), DERIVATIONS))
    source = f"{len(folders)} comparison directories (`drake-entry compare MISSION`)"
    if carried:
        source += f" and {len(carried)} row{'s' if len(carried) > 1 else ''} carried from the earlier matrix"
    text = (f"# {title}\n\nFrom {source}, commit {', '.join(commits)}. Each mission links to the settings every "
            f"method flew there and the search that chose them.\n\n"
            + matrix_markdown(folders, links=True, carried=earlier) + "\n")
    write_atomic(path, text.encode())
    return path
