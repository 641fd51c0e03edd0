"""Comparison files: one mission and the settings each guidance method flies it with.

A comparison (``drake_entry/comparisons/*.yaml`` or a user file) names a mission scenario and
lists every guidance method with either the settings it flies that mission with (its
``guidance:`` block and ``overrides`` of the method's own fields) or the reason it cannot fly
it (``not_flown``). The mission (vehicle, environment, entry state, target, terminal box,
dispersions, simulation) is the same for every method: an override may touch only the
method's settings, ``guidance.*`` and the open-loop ``alpha`` schedule (flown by the methods
that do not command alpha). ``method_scenario`` makes the scenario one method flies; the
campaign engine flies them all with the same seed, so sample i of every method draws the same
dispersions (``drake_entry.comparison.runner``). Pure data: loading one imports no solver.
"""
import dataclasses as dc
import re
from typing import Optional

from drake_entry.errors import ScenarioError
from drake_entry.guidance import REGISTRY, GuidanceSpec, known_tags
from drake_entry.scenario import Scenario, apply_overrides, load_scenario
from drake_entry.typed_yaml import load_packaged_or_file, packaged_names

__all__ = ["METHOD_FIELDS", "LABEL", "ComparedMethod", "Comparison", "PACKAGED_COMPARISONS", "load_comparison",
           "method_scenario"]

#: the scenario fields an entry may override: the method's settings, never the mission
METHOD_FIELDS = ("guidance", "alpha")
#: a label names a directory: letters, digits, '-' and '_'
LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,39}$")


@dc.dataclass
class ComparedMethod:
    """One guidance method in a comparison: how it is set up for the mission, or why it is not."""

    # short name of this entry (a directory name: letters, digits, '-', '_'), e.g. fnpeg
    label: str = ""
    # the method's YAML tag without '!' (DragEnergy, Fnpeg, ...): says which method the entry is
    method: str = ""
    # the method's settings for this mission (a tagged block, e.g. !Fnpeg {...}); absent: the
    # mission scenario's own guidance block
    guidance: Optional[GuidanceSpec] = None
    # further settings as dotted fields (guidance.* or alpha.*) -> YAML text, applied after guidance
    overrides: dict[str, str] = dc.field(default_factory=dict)
    # how the mission maps to these settings: one paragraph for the report's mapping table
    mapping: str = ""
    # non-empty: this method cannot fly the mission, and why (it is listed, not flown)
    not_flown: str = ""


@dc.dataclass
class Comparison:
    """Several guidance methods on one mission, with the same dispersions and seeds."""

    #: fields naming a file: a relative path is read beside the comparison file (typed_yaml.resolve_file_fields)
    FILE_FIELDS = ('mission',)

    name: str = ""  # short identifier, used in file names and reports
    description: str = ""  # one line for humans
    # the mission: a packaged scenario name or a scenario file (relative: beside this file; its guidance block is the
    # default settings of the entry that gives none)
    mission: str = ""
    methods: list[ComparedMethod] = dc.field(default_factory=list)  # every method, flown or not

    def validate(self) -> "Comparison":
        """One-line ScenarioErrors for unknown methods, duplicate or bad labels, an entry both
        flown and not flown, and overrides of the mission's own fields."""
        if not self.methods:
            raise ScenarioError("methods: a comparison needs at least one method")
        tags = {spec.__name__: spec for spec in REGISTRY}
        seen = set()
        for i, m in enumerate(self.methods):
            where = f"methods[{i}]"
            if not LABEL.match(m.label):
                raise ScenarioError(f"{where}.label = {m.label!r}: allowed: 1-40 letters, digits, '-' or '_', "
                                    f"starting with a letter or digit")
            if m.label in seen:
                raise ScenarioError(f"{where}.label = {m.label!r} is given twice; labels are directory names")
            seen.add(m.label)
            if m.method not in tags:
                raise ScenarioError(f"{where}.method = {m.method!r}; allowed: {known_tags().replace('!', '')}")
            if m.not_flown and (m.guidance is not None or m.overrides):
                raise ScenarioError(f"{where} ({m.label}): not_flown and settings (guidance, overrides) exclude each "
                                    f"other")
            if m.guidance is not None and type(m.guidance) is not tags[m.method]:
                raise ScenarioError(f"{where}.guidance is !{type(m.guidance).__name__} but method is {m.method}")
            for key in m.overrides:
                if key.split(".")[0] not in METHOD_FIELDS:
                    raise ScenarioError(f"{where}.overrides: {key}: only the method's settings may differ between "
                                        f"methods ({', '.join(f + '.*' for f in METHOD_FIELDS)}); the mission "
                                        f"(vehicle, entry, target, terminal box, dispersions, simulation) is shared")
        return self

    def flown(self) -> list[ComparedMethod]:
        return [m for m in self.methods if not m.not_flown]

    def not_configured(self) -> list[ComparedMethod]:
        """Every registered method this comparison does not list, as a not-flown entry with the
        reason (labelled by its folder's name): a new method shows in every comparison without a
        hand-written entry."""
        from drake_entry.guidance import folder_of

        listed = {m.method for m in self.methods}
        labels = {m.label for m in self.methods}
        out = []
        for spec in REGISTRY:
            if spec.__name__ in listed:
                continue
            label = folder_of(spec)
            label = label if label not in labels else f"{label}_not_configured"
            out.append(ComparedMethod(label=label, method=spec.__name__, not_flown=(
                f"not configured: this comparison gives no settings for !{spec.__name__} (add an entry with its "
                f"guidance block and a mapping, or not_flown with the reason)")))
        return out


#: the comparisons shipped in drake_entry/comparisons (``<name>.yaml``)
PACKAGED_COMPARISONS = packaged_names("comparisons")


def load_comparison(name_or_path) -> Comparison:
    """Read and validate a comparison: a packaged name or a YAML file path."""
    return load_packaged_or_file(Comparison, name_or_path, kind="comparison", folder="comparisons").validate()


def method_scenario(comparison: Comparison, entry: ComparedMethod) -> Scenario:
    """The scenario ``entry`` flies: the comparison's mission with the entry's guidance block
    (or the mission's own) and its overrides, named ``<mission>-<label>``. A ScenarioError names
    the entry when its settings do not fit the mission."""
    if entry.not_flown:
        raise ScenarioError(f"{entry.label} is not flown on this mission: {entry.not_flown}")
    scenario = load_scenario(comparison.mission)
    mission_name = scenario.name
    try:
        if entry.guidance is not None:
            scenario.guidance = dc.replace(entry.guidance)
        if type(scenario.guidance).__name__ != entry.method:
            raise ScenarioError(f"the mission flies !{type(scenario.guidance).__name__}; give this entry a "
                                f"guidance: !{entry.method} block")
        apply_overrides(scenario, dict(entry.overrides))
        scenario.validate()
    except ScenarioError as e:
        raise ScenarioError(f"comparison {comparison.name}, method {entry.label}: {e}") from None
    scenario.name = f"{mission_name}-{entry.label}"
    return scenario
