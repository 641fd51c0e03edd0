"""Several guidance methods flown on one mission with the same dispersions and seeds.

``run_comparison`` takes a comparison (drake_entry.comparison.spec: the mission and each method's
settings, or why a method cannot fly it) and, for every method that flies, writes the
scenario it flies (``scenarios/<label>.yaml``), times its pre-flight planning once, and runs
an ordinary Monte-Carlo campaign of it (``montecarlo.run_campaign``, resumable) into
``<label>/`` with the same seed: sample i of every method draws the same dispersions, because
a sample's draws come first from a generator seeded by (seed, i) alone (campaign.sample).
Then each campaign's report and the comparison's report (comparison.report).
"""
from __future__ import annotations

import dataclasses as dc
import hashlib
import json
import os
import time

from pydrake.common.yaml import yaml_dump_typed

from drake_entry.campaign.arguments import check_output_dir, check_run_arguments
from drake_entry.campaign.engine import session, versions
from drake_entry.campaign.montecarlo import TRAJECTORY_STEP_S, run_campaign
from drake_entry.campaign.preparation import prepare
from drake_entry.campaign.store import MANIFEST as CAMPAIGN_MANIFEST
from drake_entry.campaign.store import ROWS, write_atomic
from drake_entry.comparison.derive import value_text
from drake_entry.comparison.report import MANIFEST, read_comparison_manifest, write_comparison_report
from drake_entry.comparison.spec import (
    SCENARIOS,
    Comparison,
    load_comparison,
    method_scenario,
    needs_derivation,
)
from drake_entry.errors import DrakeEntryError, ScenarioError
from drake_entry.guidance.derivation import CannotFly
from drake_entry.scenario import load_scenario, stated_guidance

__all__ = ["SCENARIOS", "INTERRUPTED", "run_comparison", "comparison_identity", "check_comparison_dir"]

#: how the search flies each candidate, in words
SEARCH_DRAWS_TEXT = "a few dispersed draws of another seed"
#: a method's record while its campaign flies (what a directory left by an interrupted run says)
INTERRUPTED = "its campaign did not finish in this directory: run the same command to resume it"


def run_comparison(comparison, *, runs: int, out_dir: str, seed: int = 0, workers: int | None = None,
                   only: list[str] | None = None, progress: bool = True,
                   trajectory_step_s: float = TRAJECTORY_STEP_S, backend: str = "processes",
                   scheduler: str | None = None) -> str:
    """Fly every method of ``comparison`` (a Comparison, a packaged name or a file) that can fly
    its mission as a campaign of ``runs`` samples (seed ``seed``) into ``out_dir/<label>``, then
    write ``out_dir/report.md``; returns the report's path. ``only``: these labels only (the
    others keep what an earlier run left). A method whose planner cannot be built for the mission
    is recorded with its reason and the others still fly. The campaigns resume like any other.
    ``backend``, ``scheduler``: where the samples fly (montecarlo.run_campaign: local processes,
    serial, or a Dask cluster); the settings' searches and pre-flight plans run here."""
    from drake_entry.campaign.report import write_report
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup

    check_run_arguments(runs=runs, seed=seed, trajectory_step_s=trajectory_step_s, workers=workers, backend=backend,
                        scheduler=scheduler)
    out_dir = check_output_dir(out_dir, "out_dir")
    comp = comparison if isinstance(comparison, Comparison) else load_comparison(comparison)
    comp.validate()
    entries = comp.entries()
    labels = [m.label for m in entries]
    only = _checked_only(only, entries, comp.name)
    if not comp.flown():
        raise ScenarioError(f"comparison {comp.name} has nothing to fly: every method it lists is not_flown ("
                            + "; ".join(f"{m.label}: {m.not_flown}" for m in entries)[:300] + ")")
    mission = load_scenario(comp.mission)
    derived = {m.label for m in comp.flown() if needs_derivation(comp, m, mission)}
    scenarios = {m.label: method_scenario(comp, m) for m in comp.flown()
                 if m.label not in derived}  # every bad entry before any flight
    identity = comparison_identity(comp, mission)
    manifest = check_comparison_dir(out_dir, comp.name, identity, seed)  # before anything is written
    os.makedirs(os.path.join(out_dir, SCENARIOS), exist_ok=True)
    methods = dict(manifest.get("methods", {}))
    order = {label: i for i, label in enumerate(labels + [m.label for m in comp.not_configured()])}
    earlier_runs, sessions = int(manifest.get("runs", 0)), list(manifest.get("sessions", [])) + [session()]

    def save(methods: dict) -> None:
        record = {"comparison": comp.name, "description": comp.description, "mission": comp.mission,
                  "identity": identity, "comparison_yaml": yaml_dump_typed(comp), "runs": max(int(runs), earlier_runs),
                  "seed": int(seed), "versions": versions(), "sessions": sessions,
                  "methods": dict(sorted(methods.items(), key=lambda kv: order.get(kv[0], len(order))))}
        write_atomic(os.path.join(out_dir, MANIFEST), json.dumps(record, indent=2).encode())

    for entry in entries + comp.not_configured():
        if entry.not_flown:
            methods[entry.label] = {"method": entry.method, "flown": False, "reason": entry.not_flown,
                                    "mapping": entry.mapping}
            continue
        if only and entry.label not in only:
            reason = _cannot_fly(mission, entry) if entry.label in derived else ""
            earlier = methods.get(entry.label)
            if not reason and entry.label in derived and (earlier is None or not earlier.get("flown")):
                reason = (f"yet to fly in this directory: its settings derive from this mission (fly it with "
                          f"--only {entry.label})")  # an earlier run's reason may no longer hold
            if reason:  # known without flying: recorded whatever an earlier run left
                methods[entry.label] = {"method": entry.method, "flown": False, "mapping": entry.mapping,
                                        "reason": reason}
            else:
                methods.setdefault(entry.label, {"method": entry.method, "flown": False, "mapping": entry.mapping,
                                                 "reason": ""})  # not in this run; an earlier run's record stays
            continue
        path = os.path.join(out_dir, SCENARIOS, f"{entry.label}.yaml")
        record = {"method": entry.method, "flown": True, "mapping": entry.mapping,
                  "scenario": os.path.join(SCENARIOS, f"{entry.label}.yaml")}
        if entry.label in derived:
            try:
                scenario, derivation = _derived_scenario(comp, entry, mission, path, methods.get(entry.label),
                                                         progress)
            except CannotFly as e:
                methods[entry.label] = {"method": entry.method, "flown": False, "mapping": entry.mapping,
                                        "reason": f"cannot fly this mission: {e}"}
                if progress:
                    print(f"== {entry.label} (!{entry.method}): not flown: {e}", flush=True)
                continue
            record["derivation"] = derivation
            record["mapping"] = (entry.mapping + " " if entry.mapping else "") + _derivation_text(derivation)
        else:
            scenario = scenarios[entry.label]
        write_atomic(path, yaml_dump_typed(scenario).encode())
        # recorded before it flies (its derivation kept): an interrupted campaign resumes with the
        # same command, without searching again, and its finished samples are kept
        methods[entry.label] = {**record, "flown": False, "reason": INTERRUPTED}
        save(methods)
        if progress:
            print(f"== {entry.label} (!{entry.method}): pre-flight planning", flush=True)
        t = time.perf_counter()
        try:
            prepared = prepare(scenario, progress=progress)  # e.g. AMPI's database for this mission
            if prepared and progress:
                print(f"   {prepared}", flush=True)
            setup = ClosedLoopSetup.from_scenario(scenario)
        except DrakeEntryError as e:
            methods[entry.label] = {**record, "flown": False, "reason": f"its planner failed on this mission: {e}"}
            print(f"   {entry.label}: not flown: {e}", flush=True)
            continue
        record["preflight_planning_s"] = time.perf_counter() - t
        record["preflight_plan"] = getattr(setup.planner, "message", "") if setup.planner is not None else ""
        if progress:
            print(f"   {record['preflight_planning_s']:.1f} s; {runs} samples", flush=True)
        campaign_dir = os.path.join(out_dir, entry.label)
        run_campaign(path, runs=runs, out_dir=campaign_dir, seed=seed, workers=workers, progress=progress,
                     trajectory_step_s=trajectory_step_s, nominal_setup=setup,  # its nominal: no third plan
                     backend=backend, scheduler=scheduler)
        del setup
        write_report(campaign_dir, title=f"{comp.name}: {entry.label}")
        methods[entry.label] = {**record, "campaign": entry.label}
        save(methods)  # each method's record (its derivation) kept as soon as it is flown
    save(methods)
    return write_comparison_report(out_dir)


def _checked_only(only, entries, name: str) -> list[str] | None:
    """``only`` as a list of labels of flown entries, or a one-line ScenarioError."""
    if only is None:
        return None
    if isinstance(only, str) or not isinstance(only, (list, tuple)) or not all(isinstance(x, str) for x in only):
        raise ScenarioError(f"only = {only!r}: give a list of labels, e.g. only=[{only!r}]" if isinstance(only, str)
                            else f"only = {only!r}: give a list of labels (text)")
    labels = {m.label: m for m in entries}
    unknown = [x for x in only if x not in labels]
    if unknown:
        raise ScenarioError(f"only: {', '.join(unknown)} not in comparison {name}; allowed: {', '.join(labels)}")
    not_flown = [x for x in only if labels[x].not_flown]
    if not_flown and len(not_flown) == len(only):
        raise ScenarioError(f"only: {', '.join(not_flown)}: nothing to fly (not flown on this mission: "
                            f"{labels[not_flown[0]].not_flown[:200]})")
    return list(only)


def comparison_identity(comp: Comparison, mission) -> str:
    """What a comparison directory holds, as a SHA-256: the methods' settings and the mission's
    content (the scenario as loaded), not the comparison's name or where its files are."""
    from pydrake.common.yaml import yaml_dump_typed

    methods = yaml_dump_typed(dc.replace(comp, name="", description="", mission=""))
    return hashlib.sha256(json.dumps([methods, yaml_dump_typed(mission)]).encode()).hexdigest()


def check_comparison_dir(out_dir: str, name: str, identity: str, seed: int) -> dict:
    """The manifest of ``out_dir`` ({} when it is new or empty), or a ScenarioError when it holds
    something else: a campaign, other files, another comparison (other content or seed)."""
    if not os.path.isdir(out_dir) or not os.listdir(out_dir):
        return {}
    manifest = read_comparison_manifest(out_dir)
    if manifest is None:
        if os.path.exists(os.path.join(out_dir, CAMPAIGN_MANIFEST)) or os.path.exists(os.path.join(out_dir, ROWS)):
            raise ScenarioError(f"{out_dir} holds a campaign ({CAMPAIGN_MANIFEST}), not a comparison; give another "
                                f"directory")
        raise ScenarioError(f"{out_dir} is not empty and holds no comparison ({MANIFEST}); give a new or empty "
                            f"directory")
    if manifest.get("seed") != seed:
        raise ScenarioError(f"{out_dir} holds comparison {manifest.get('comparison')!r} with seed "
                            f"{manifest.get('seed')}; use another --out")
    held = manifest.get("identity")  # a directory written before identities: its name stands for it
    if (held != identity) if held else (manifest.get("comparison") != name):
        raise ScenarioError(f"{out_dir} holds comparison {manifest.get('comparison')!r} of other content (another "
                            f"mission or other methods' settings) than {name!r}; use another --out, or the same file")
    return manifest


def _spec_type(entry):
    """The registered spec class of ``entry``'s method (its tag, validated by Comparison.validate)."""
    from drake_entry.guidance import REGISTRY

    return next(spec for spec in REGISTRY if spec.__name__ == entry.method)


def _mission_for(mission, entry):
    """The mission as ``entry``'s method derives its settings from it: as it is for the mission's
    own method; for another, an alpha schedule in time rewritten in speed by the mission's
    open-loop flight (comparison.mission_alpha), with the Choice that says so (None when not)."""
    from drake_entry.comparison.mission_alpha import alpha_in_speed

    if type(stated_guidance(mission)) is _spec_type(entry):
        return mission, None
    return alpha_in_speed(mission)


def _derivation(mission, entry):
    """(the mission as the method sees it, its Derivation) (CannotFly when it cannot fly it)."""
    from drake_entry.guidance.derivation import derivation_for

    seen, alpha = _mission_for(mission, entry)
    derivation = derivation_for(seen, _spec_type(entry))
    if alpha is not None:
        derivation.choices.insert(0, alpha)
    return seen, derivation


def _cannot_fly(mission, entry) -> str:
    """Why ``entry``'s method cannot fly the mission, when its derivation says so without flying ('' else)."""
    try:
        _derivation(mission, entry)
    except CannotFly as e:
        return f"cannot fly this mission: {e}"
    return ""


def _derived_scenario(comp: Comparison, entry, mission, path: str, earlier: dict | None, progress: bool):
    """The scenario ``entry`` flies with its settings derived from the mission, and the
    derivation's record: an earlier run's (its scenario file and record, when both are there and
    the record was derived at this source commit: derivation is deterministic for one code), else
    derived and searched now (CannotFly when the method cannot fly the mission). A method flown
    again after its code changed is derived again: reusing the old settings flew SPHYNX's
    drag-energy cell with the pre-guidance bank its earlier code had no search for."""
    from drake_entry.campaign.engine import source_commit
    from drake_entry.comparison.derive import derive_settings

    commit = source_commit()
    if (earlier and earlier.get("derivation") and os.path.exists(path)
            and earlier["derivation"].get("commit") == commit):
        return method_scenario(comp, entry, load_scenario(path)), earlier["derivation"]
    mission, derivation = _derivation(mission, entry)
    if progress:
        print(f"== {entry.label} (!{entry.method}): settings derived from the mission"
              + (", searched on the nominal flight and dispersed draws" if derivation.search else ""), flush=True)
    chosen = derive_settings(mission, derivation, progress=(lambda text: print(f"   {text}", flush=True))
                             if progress else None)
    return method_scenario(comp, entry, chosen.scenario), {**chosen.record(), "commit": commit}


def _derivation_text(record: dict) -> str:
    """One paragraph for the mapping table: each setting taken from the mission, and the search's choices."""
    taken = "; ".join(f"{c['field'].replace('guidance.', '')} {c['value']} ({c['how']})" for c in record["choices"])
    chosen = ", ".join(f"{k.replace('guidance.', '')} {value_text(v)}" for k, v in record["chosen"].items())
    tried = len(record["trials"])
    text = f"Derived from the mission: {taken}."
    if tried:
        text += (f" Searched ({tried} candidates flown on the nominal entry and {SEARCH_DRAWS_TEXT}): {chosen}"
                 f" (table: 'Settings derived from the mission').")
    return text
