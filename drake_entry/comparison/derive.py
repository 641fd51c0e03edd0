"""A method's settings for a mission, chosen by flying: a method's Derivation
(drake_entry.guidance.derivation: what it takes from the mission, and its free settings with
their candidates) searched on the nominal flight and a few dispersed draws.

The search runs its steps one after the other. In a step, each candidate (in the derivation's
order) is flown by the Drake closed loop: the nominal entry and ``draws`` dispersed samples of
the mission's own dispersions, drawn with SEARCH_SEED (never a campaign's seed: the campaign is
not tuned on its own samples). The first candidate whose every flight succeeds within
GOOD_ENOUGH of every box tolerance is kept; when none does (or the step is exhaustive: every
candidate flown), the best: most successes, then the smallest mean box ratio (a flight's largest
|error| / tolerance; one that breaches a limit or stops short counts LIMIT_PENALTY or
SHORT_PENALTY more). The same mission gives the same settings.
"""
from __future__ import annotations

import dataclasses as dc
import math
import time

from drake_entry.errors import DrakeEntryError
from drake_entry.guidance.derivation import Choice, Derivation
from drake_entry.models.verdict import acceptance_box

__all__ = ["SEARCH_SEED", "SEARCH_DRAWS", "GOOD_ENOUGH", "Flight", "Trial", "DerivedSettings", "derive_settings",
           "apply_derivation", "value_text"]

#: the campaign seed of a search's dispersed draws (apart from the seeds campaigns use)
SEARCH_SEED = 918_273_645
#: dispersed draws per candidate, besides the nominal flight
SEARCH_DRAWS = 2
#: a candidate whose every flight succeeds with a box ratio at most this is kept at once
GOOD_ENOUGH = 0.75
#: added to a flight's box ratio when it breaches a path limit / does not reach its interface
LIMIT_PENALTY, SHORT_PENALTY = 10.0, 100.0


@dc.dataclass
class Flight:
    """One search flight: 'nominal' or the draw's index, its verdict, box ratio and why not a success."""

    sample: str
    success: bool
    box_ratio: float
    why: str = ""

    @property
    def merit(self) -> float:
        return self.box_ratio if math.isfinite(self.box_ratio) else SHORT_PENALTY * 10


@dc.dataclass
class Trial:
    """One candidate of a search step: the step's name, the fields it set, its flights and its
    wall time [s]."""

    step: str
    values: dict
    flights: list[Flight]
    wall_s: float
    setup_failure: str = ""
    nominal_row: dict | None = None  # the nominal flight's campaign row (a later calibrated step reads it)

    @property
    def successes(self) -> int:
        return sum(f.success for f in self.flights)

    @property
    def mean_ratio(self) -> float:
        return sum(f.merit for f in self.flights) / len(self.flights) if self.flights else math.inf

    def score(self) -> tuple:
        return (-self.successes, self.mean_ratio)

    def good_enough(self) -> bool:
        return bool(self.flights) and all(f.success and f.box_ratio <= GOOD_ENOUGH for f in self.flights)


@dc.dataclass
class DerivedSettings:
    """A method's settings for a mission: the scenario it flies (the mission with the derived
    guidance block and alpha), what it took from the mission, and the search that chose the rest."""

    scenario: object
    choices: list[Choice]
    trials: list[Trial]
    chosen: dict

    def record(self) -> dict:
        """JSON-ready: the choices, the chosen values and every trial with its flights."""
        return {"choices": [dc.asdict(c) | {"value": str(c.value)} for c in self.choices],
                "chosen": {k: v for k, v in self.chosen.items()},
                "trials": [{"step": t.step, "values": t.values, "successes": t.successes, "flights": len(t.flights),
                            "mean_box_ratio": t.mean_ratio if math.isfinite(t.mean_ratio) else None,
                            "wall_s": round(t.wall_s, 2), "setup_failure": t.setup_failure,
                            "why": [f.why for f in t.flights if f.why][:3]} for t in self.trials]}


def value_text(value) -> str:
    """A searched setting's value as the reports write it: a number in %g, anything else as it is."""
    return f"{value:g}" if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)


def apply_derivation(mission, derivation: Derivation, values: dict | None = None):
    """The mission scenario flying ``derivation``'s spec (and its alpha) with ``values``
    ({'guidance.<field>': value}) set on it."""
    scenario = dc.replace(mission)
    spec = derivation.spec
    fields = {k.split(".", 1)[1]: v for k, v in (values or {}).items()}
    scenario.guidance = dc.replace(spec, **fields)
    if derivation.alpha is not None:
        scenario.alpha = dc.replace(derivation.alpha)
    scenario.validate()
    return scenario


def _flight(sample: str, row: dict, tolerances: dict) -> Flight:
    """One search flight from its campaign row (drake_entry.campaign.sample.campaign_row): its
    box ratio, the largest |error| / tolerance over the box's criteria (``tolerances``: each
    criterion's tolerance), plus LIMIT_PENALTY when it breached a limit and SHORT_PENALTY when it
    stopped short of its interface."""
    ratios = [abs(row.get(f"box_{k}_error", math.nan)) / t for k, t in tolerances.items() if t > 0]
    ratio = max(ratios) if ratios and all(math.isfinite(r) for r in ratios) else math.inf
    ratio += (0.0 if row.get("within_limits", False) else LIMIT_PENALTY) + (
        0.0 if row.get("reached_terminal", False) else SHORT_PENALTY)
    success, message = bool(row.get("success", False)), str(row.get("message") or "")
    return Flight(sample, success, ratio, "" if success or not message else message.splitlines()[0][:200])


def _fly_candidate(scenario, draws: int) -> tuple[list[Flight], str, dict | None]:
    """The nominal flight and ``draws`` dispersed samples of ``scenario``: (flights, '' or the
    pre-flight failure, the nominal flight's campaign row or None)."""
    from drake_entry.campaign.preparation import prepare
    from drake_entry.campaign.sample import campaign_row, run_sample
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly

    try:
        prepare(scenario)  # nothing, or built once and cached (e.g. AMPI's database for the mission)
        setup = ClosedLoopSetup.from_scenario(scenario)
    except DrakeEntryError as e:
        return [], f"pre-flight planning failed: {str(e).splitlines()[0][:300]}", None
    tolerances = {k: b["tolerance"] for k, b in
                  acceptance_box(scenario.terminal, altitude_m=math.nan, mach=math.nan, distance_m=math.nan).items()}
    nominal = None
    try:
        nominal = campaign_row(fly(setup), setup)
        flights = [_flight("nominal", nominal, tolerances)]
    except (DrakeEntryError, RuntimeError) as e:
        flights = [Flight("nominal", False, math.inf, str(e).splitlines()[0][:200])]
    return flights + [_flight(str(i), run_sample(setup, SEARCH_SEED, i, trajectory_step_s=0)[0], tolerances)
                      for i in range(draws)], "", nominal


def _calibrated(step, mission, derivation: Derivation, chosen: dict, before: Trial | None) -> tuple:
    """``step``'s candidates, its measured one first when it is calibrated: measured on the
    nominal row of ``before`` (the trial that chose the settings so far), or of a nominal flight
    flown now when there is none; the fixed candidates alone when the nominal flight fails to
    give the measure."""
    if step.calibrate is None:
        return step.candidates
    row = before.nominal_row if before is not None else None
    if row is None:
        _, _, row = _fly_candidate(apply_derivation(mission, derivation, chosen), 0)
    try:
        measured = step.calibrate(row) if row is not None else None
    except (KeyError, TypeError, ValueError):
        measured = None
    if measured is None or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in measured.values()):
        return step.candidates
    return (measured, *(c for c in step.candidates if c != measured))


def derive_settings(mission, derivation: Derivation, *, draws: int = SEARCH_DRAWS, progress=None) -> DerivedSettings:
    """Choose ``derivation``'s free settings on ``mission`` (module doc); ``progress(text)``
    is told each trial."""
    chosen, trials, best = {}, [], None
    for step in derivation.search:
        step_trials = []
        for values in _calibrated(step, mission, derivation, chosen, best):
            t0 = time.perf_counter()
            try:
                scenario = apply_derivation(mission, derivation, {**chosen, **values})
            except DrakeEntryError as e:
                step_trials.append(Trial(step.name, values, [], time.perf_counter() - t0,
                                         f"refused: {str(e).splitlines()[0][:300]}"))
                continue
            flights, failure, nominal = _fly_candidate(scenario, draws)
            trial = Trial(step.name, values, flights, time.perf_counter() - t0, failure, nominal)
            step_trials.append(trial)
            if progress:
                shown = ", ".join(f"{k.split('.')[-1]} {value_text(v)}" for k, v in values.items())
                progress(f"{step.name}: {shown}: {trial.successes}/{len(flights)} successful, mean box ratio "
                         f"{trial.mean_ratio:.2f} ({trial.wall_s:.1f} s){' ' + failure if failure else ''}")
            if trial.good_enough() and not step.exhaustive:
                break
        trials += step_trials
        flown = [t for t in step_trials if t.flights]
        best = min(flown, key=Trial.score) if flown else step_trials[0]
        chosen.update(best.values)
    return DerivedSettings(apply_derivation(mission, derivation, chosen), list(derivation.choices), trials, chosen)
