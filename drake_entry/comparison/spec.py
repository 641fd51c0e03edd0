"""Comparison files: one mission and the settings each guidance method flies it with.

A comparison (``drake_entry/comparisons/*.yaml`` or a user file) names a mission scenario and
lists guidance methods with the settings each flies that mission with (its ``guidance:`` block
and ``overrides`` of the method's own fields), or none: the mission's own method flies the
mission's settings, another method derives its settings from the mission
(drake_entry.guidance.derivation, searched by drake_entry.comparison.derive), or the reason it
cannot fly it (``not_flown``). A comparison that lists no method flies every registered one,
each with derived settings (``mission_comparison``: a mission alone). The mission (vehicle,
environment, entry state, target, terminal box, dispersions, simulation) is the same for every
method: an override may touch only the method's settings, ``guidance.*`` and the open-loop
``alpha`` schedule (flown by the methods that do not command alpha). ``method_scenario`` makes
the scenario one method flies; the campaign engine flies them all with the same seed, so sample
i of every method draws the same dispersions (``drake_entry.comparison.runner``). Pure data:
loading one imports no solver."""
import dataclasses as dc
import os
import re
from typing import Optional

from drake_entry.errors import ScenarioError
from drake_entry.guidance import REGISTRY, GuidanceSpec, known_tags
from drake_entry.scenario import Scenario, apply_overrides, load_scenario, stated_guidance
from drake_entry.typed_yaml import load_packaged_or_file, packaged_names

__all__ = ["METHOD_FIELDS", "LABEL", "NAME", "SCENARIOS", "ComparedMethod", "Comparison", "PACKAGED_COMPARISONS",
           "load_comparison", "needs_derivation", "method_scenario", "mission_comparison",
           "load_comparison_or_mission"]

#: the scenario fields an entry may override: the method's settings, never the mission
METHOD_FIELDS = ("guidance", "alpha")
#: a label names a directory: letters, digits, '-' and '_'
LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,39}$")
#: a comparison's name names its default directory (out/compare/<name>): one path component
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,79}$")
#: the folder of a comparison directory that holds the scenario each method flew (no label may take it)
SCENARIOS = "scenarios"


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
    # the methods, flown or not; none: every registered method, its settings derived from the mission
    methods: list[ComparedMethod] = dc.field(default_factory=list)

    def validate(self) -> "Comparison":
        """One-line ScenarioErrors for a missing mission, unknown methods, duplicate or bad labels,
        an entry both flown and not flown, and overrides of the mission's own fields."""
        from drake_entry.guidance import folder_of

        if not isinstance(self.name, str) or not NAME.match(self.name) or ".." in self.name:
            raise ScenarioError(f"name = {self.name!r}: allowed: 1-80 letters, digits, '.', '-' or '_', starting with "
                                f"a letter or digit, without '..' (it names the directory out/compare/<name>)")
        if not isinstance(self.mission, str) or not self.mission:
            raise ScenarioError("mission: missing; give a packaged scenario name or a scenario file")
        tags = {spec.__name__: spec for spec in REGISTRY}
        folders = {folder_of(spec): spec.__name__ for spec in REGISTRY}
        seen = set()
        for i, m in enumerate(self.methods):
            where = f"methods[{i}]"
            if not isinstance(m.label, str) or not LABEL.match(m.label):
                raise ScenarioError(f"{where}.label = {m.label!r}: allowed: 1-40 letters, digits, '-' or '_', "
                                    f"starting with a letter or digit")
            if m.label == SCENARIOS:
                raise ScenarioError(f"{where}.label = {m.label!r} is the comparison directory's own folder (the "
                                    f"scenarios each method flew); give another label")
            if m.label in seen:
                raise ScenarioError(f"{where}.label = {m.label!r} is given twice; labels are directory names")
            seen.add(m.label)
            if m.method not in tags:
                raise ScenarioError(f"{where}.method = {m.method!r}; allowed: {known_tags().replace('!', '')}")
            if folders.get(m.label, m.method) != m.method:
                raise ScenarioError(f"{where}.label = {m.label!r} names !{folders[m.label]} but method is {m.method}; "
                                    f"give a label that is not another method's name")
            tag = _override_tag(m.overrides.get("guidance"))
            if tag is not None and tag != m.method:
                raise ScenarioError(f"{where}.overrides.guidance is !{tag} but method is {m.method}: an entry flies "
                                    f"the method its 'method' names (give !{m.method} settings, or list !{tag} as "
                                    f"its own entry)")
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

    def entries(self) -> list[ComparedMethod]:
        """The methods of this comparison: the file's list, or, when it names none (a comparison
        of the mission alone), every registered method, each with its settings derived from the
        mission (labelled by its folder's name)."""
        from drake_entry.guidance import folder_of

        if self.methods:
            return list(self.methods)
        return [ComparedMethod(label=folder_of(spec), method=spec.__name__) for spec in REGISTRY]

    def flown(self) -> list[ComparedMethod]:
        return [m for m in self.entries() if not m.not_flown]

    def not_configured(self) -> list[ComparedMethod]:
        """Every registered method a comparison that lists methods does not list, as a not-flown
        entry with the reason (labelled by its folder's name): a new method shows in every
        comparison without a hand-written entry."""
        from drake_entry.guidance import folder_of

        if not self.methods:
            return []
        listed = {m.method for m in self.methods}  # a listed label is never an unlisted method's folder (validate)
        out = []
        for spec in REGISTRY:
            if spec.__name__ in listed:
                continue
            out.append(ComparedMethod(label=folder_of(spec), method=spec.__name__, not_flown=(
                f"not configured: this comparison does not list !{spec.__name__} (list it without a guidance "
                f"block to derive its settings from the mission, with one to set them, or with not_flown and the "
                f"reason)")))
        return out


def _override_tag(text) -> str | None:
    """The !Tag of an override's YAML text (None: no text, or untagged)."""
    from drake_entry.typed_yaml import Tagged, parse

    if not isinstance(text, str):
        return None
    value = parse(text, "overrides.guidance")
    return value.tag if isinstance(value, Tagged) else None


#: the comparisons shipped in drake_entry/comparisons (``<name>.yaml``)
PACKAGED_COMPARISONS = packaged_names("comparisons")


def load_comparison(name_or_path) -> Comparison:
    """Read and validate a comparison: a packaged name or a YAML file path."""
    comparison = load_packaged_or_file(Comparison, name_or_path, kind="comparison", folder="comparisons")
    try:
        return comparison.validate()
    except ScenarioError as e:
        raise ScenarioError(f"comparison '{name_or_path}': {e}") from None


def needs_derivation(comparison: Comparison, entry: ComparedMethod, mission: Scenario | None = None) -> bool:
    """Whether ``entry``'s settings are derived from the mission: it is flown, gives no guidance
    block, and the mission states no block of its method (``mission``: the loaded mission, else
    loaded; drake_entry.scenario.stated_guidance)."""
    if entry.not_flown or entry.guidance is not None:
        return False
    mission = mission if mission is not None else load_scenario(comparison.mission)
    return type(stated_guidance(mission)).__name__ != entry.method


def method_scenario(comparison: Comparison, entry: ComparedMethod,
                    guidance_scenario: Scenario | None = None) -> Scenario:
    """The scenario ``entry`` flies: the comparison's mission with the entry's guidance block (or
    the mission's own, or ``guidance_scenario``'s guidance and alpha: the settings derived from the
    mission, drake_entry.comparison.derive) and its overrides, named ``<mission>-<label>``. A
    ScenarioError names the entry when its settings do not fit the mission."""
    if entry.not_flown:
        raise ScenarioError(f"{entry.label} is not flown on this mission: {entry.not_flown}")
    scenario = load_scenario(comparison.mission)
    mission_name = scenario.name
    try:
        if guidance_scenario is not None:
            scenario.guidance = dc.replace(guidance_scenario.guidance)
            scenario.alpha = dc.replace(guidance_scenario.alpha)
        elif entry.guidance is not None:
            scenario.guidance = dc.replace(entry.guidance)
        if type(scenario.guidance).__name__ != entry.method:
            raise ScenarioError(f"the mission flies !{type(scenario.guidance).__name__} and this entry gives no "
                                f"guidance: !{entry.method} block: its settings are derived from the mission when the "
                                f"comparison runs (drake_entry.comparison.derive), or give the block")
        apply_overrides(scenario, dict(entry.overrides))
        if type(scenario.guidance).__name__ != entry.method:
            raise ScenarioError(f"its settings are !{type(scenario.guidance).__name__} but method is {entry.method}")
        scenario.validate()
    except ScenarioError as e:
        raise ScenarioError(f"comparison {comparison.name}, method {entry.label}: {e}") from None
    scenario.name = f"{mission_name}-{entry.label}"
    return scenario


def mission_comparison(mission: str) -> Comparison:
    """The comparison of a mission alone (a packaged scenario name or a scenario file): every
    registered method, each with its settings derived from the mission; named after it."""
    scenario = load_scenario(mission)
    name = re.sub(r"[^A-Za-z0-9._-]+", "_", scenario.name).replace("..", "_").lstrip("._-")[:80] or "mission"
    return Comparison(name=name, description=f"every guidance method on {scenario.name}, settings derived "
                      f"from the mission", mission=mission).validate()


def load_comparison_or_mission(name_or_path: str) -> Comparison:
    """A comparison (a packaged name or a comparison file), or the comparison of a mission alone
    (a packaged scenario name or a scenario file: ``mission_comparison``). A packaged comparison
    wins over a packaged scenario of the same name; a file is a comparison when it has a
    ``mission`` field."""
    from drake_entry.scenario import PACKAGED_SCENARIOS
    from drake_entry.typed_yaml import parse

    if name_or_path in PACKAGED_COMPARISONS:
        return load_comparison(name_or_path)
    if name_or_path in PACKAGED_SCENARIOS:
        return mission_comparison(name_or_path)
    if isinstance(name_or_path, str) and os.path.isfile(name_or_path):
        try:
            with open(name_or_path, encoding="utf-8") as f:
                data = parse(f.read(), name_or_path)
        except (OSError, UnicodeDecodeError):
            data = None
        if isinstance(data, dict) and "mission" not in data:
            if "entry" in data or "based_on" in data:
                return mission_comparison(name_or_path)
            raise ScenarioError(f"{name_or_path} is neither a comparison file (it has no 'mission' field) nor a "
                                f"scenario file (no 'entry' or 'based_on' field)"
                                + ("; it looks like a vehicle file: name it in a scenario's 'vehicle' field"
                                   if "mass_kg" in data or "aero" in data else ""))
    try:
        return load_comparison(name_or_path)
    except ScenarioError as e:
        if "is neither a packaged" in str(e):
            raise ScenarioError(f"'{name_or_path}' is neither a packaged comparison "
                                f"({', '.join(PACKAGED_COMPARISONS)}), a packaged scenario "
                                f"({', '.join(PACKAGED_SCENARIOS)}) nor a file") from None
        raise
