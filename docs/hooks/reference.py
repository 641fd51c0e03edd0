"""MkDocs hooks: the YAML reference pages, generated at build time from the schema dataclasses
(drake_entry.schema_doc), and the API pages, one per layer listing every module found in the
source tree, so neither can drift from the code; and the source tree the API reference reads,
with ``systems/`` and ``diagrams/`` placed inside ``drake_entry/`` as pyproject's
``package-dir`` installs them (the repository keeps them at its top level)."""
import atexit
import functools
import os
import shutil
import tempfile

import tomllib
from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@functools.cache
def installed_subpackages() -> dict:
    """{name inside drake_entry: repository directory}, read from pyproject's ``package-dir``."""
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
        mapping = tomllib.load(f)["tool"]["setuptools"]["package-dir"]
    return {k.split(".", 1)[1]: v for k, v in mapping.items() if k.startswith("drake_entry.")}


@event_priority(100)  # before mkdocstrings reads its handler settings
def on_config(config):
    """Point mkdocstrings at a temporary tree of symbolic links: drake_entry/* plus
    drake_entry/systems and drake_entry/diagrams (made fresh at every build)."""
    tree = tempfile.mkdtemp(prefix="drake_entry_api_")
    atexit.register(shutil.rmtree, tree, ignore_errors=True)
    package = os.path.join(tree, "drake_entry")
    os.mkdir(package)
    for entry in os.listdir(os.path.join(ROOT, "drake_entry")):
        os.symlink(os.path.join(ROOT, "drake_entry", entry), os.path.join(package, entry))
    for name, directory in installed_subpackages().items():
        os.symlink(os.path.join(ROOT, directory), os.path.join(package, name))
    handlers = config["plugins"]["mkdocstrings"].config["handlers"]
    handlers.setdefault("python", {})["paths"] = [tree]
    for section in config["nav"]:
        if isinstance(section, dict) and "Methods" in section:
            section["Methods"] = methods_nav()
    return config


def methods_nav() -> list:
    """The Methods section: every page of docs/methods/, titled by its first heading, the papers'
    in paper order first (a new method's page needs no line in mkdocs.yml)."""
    folder = os.path.join(ROOT, "docs", "methods")
    pages = []
    for name in os.listdir(folder):
        if name.endswith(".md"):
            with open(os.path.join(folder, name)) as f:
                title = f.readline().lstrip("#").strip()
            pages.append({title: f"methods/{name}"})
    return sorted(pages, key=lambda page: (not next(iter(page)).startswith("Paper"), next(iter(page))))

PAGES = {
    "reference/scenario.md": ("drake_entry.scenario", "Scenario", "Scenario YAML",
                              "A mission file (`drake-entry fly FILE.yaml`, `load_scenario(path)`). Packaged "
                              "scenarios live in `drake_entry/scenarios/`. Fields not in SI carry their unit in "
                              "the name; a bad value is a one-line error naming the field and the allowed range. "
                              "A file with `based_on: NAME` starts from that scenario (a packaged name, or a path "
                              "relative to the file) and states only what it changes; blocks merge field by field, "
                              "and a guidance block there carries the base's tag (`guidance: !Fnpeg`), as in the "
                              "packaged flight-like twins (`horus2b_flight.yaml`)."),
    "reference/vehicle.md": ("drake_entry.models.vehicles", "VehicleSpec", "Vehicle YAML",
                             "A vehicle file (`vehicle: path/to/file.yaml` in a scenario; packaged vehicles live "
                             "in `drake_entry/vehicles/`). `aero` maps model names to aerodynamic models; "
                             "`default_aero` picks one."),
    "reference/comparison.md": ("drake_entry.comparison.spec", "Comparison", "Comparison YAML",
                                "A comparison file (`drake-entry compare FILE.yaml`, `load_comparison(path)`): one "
                                "mission and every guidance method's settings for it, or why it cannot fly it. "
                                "Packaged comparisons live in `drake_entry/comparisons/`; see "
                                "[Comparing methods](../comparisons.md)."),
    "reference/problem.md": ("drake_entry.planning.ocp_yaml", "ProblemSpec", "Optimal-control problem YAML",
                             "A problem file for the NLP path (`drake-entry optimize FILE.yaml`, "
                             "`load_problem(path)`)."),
}


#: API pages: (uri, title, introduction, source folders relative to drake_entry/ in the installed
#: layout, single modules); every module of the folders is listed, in the order found
API_PAGES = (
    ("api/models.md", "Models",
     "The physics layer: plain Python and numpy (float, array, AutoDiffXd and, where noted, symbolic "
     "`Expression` inputs), SI units inside. It imports nothing else of the project but its errors and the "
     "typed YAML reader.",
     ("models",), ("drake_entry.errors", "drake_entry.typed_yaml")),
    ("api/planning.md", "Shared planning",
     "What several methods share: the plan result, the optimal-control problem and its YAML form, the "
     "LGL operators, the NLP transcriptions and solver, time-varying LQR tracking; the shared figures and "
     "trajectory tables.",
     ("planning",), ("drake_entry.figures", "drake_entry.tables")),
    ("api/guidance.md", "Guidance methods",
     "The guidance-method interface and registry, then one section per method folder: its spec, "
     "planner, plots, wiring and studies (see [Architecture](../architecture.md) for how to add a method).",
     ("guidance",), ()),
    ("api/systems.md", "Drake systems",
     "The Drake `LeafSystem`s of the plant, guidance and control (import them as "
     "`drake_entry.systems.<module>`). Each docstring lists the system's ports with their units.",
     ("systems",), ()),
    ("api/diagrams.md", "Diagrams",
     "Diagram builders (open and closed loop) and the plan verifier, the one Drake flight of a plan's "
     "controls (import them as `drake_entry.diagrams.<module>`).",
     ("diagrams",), ()),
    ("api/campaign.md", "Scenarios, campaigns, comparisons and reports",
     "The scenario file; the campaign engine (backends, Monte-Carlo samples), the campaign directory, the "
     "reports and their figures; comparisons of several methods on one mission; the examples' claims.",
     ("campaign", "comparison"), ("drake_entry.scenario", "drake_entry.claims")),
    ("api/cli.md", "Command line",
     "The `drake-entry` command: one module per command family, and the methods' own commands in "
     "`drake_entry.cli.methods`, found through the registry.",
     ("cli",), ()),
)


def _modules(folder: str) -> list:
    """Dotted names of every module under drake_entry/<folder> (installed layout), packages first."""
    directory = installed_subpackages().get(folder, os.path.join("drake_entry", folder))
    names = []
    for here, dirs, files in sorted(os.walk(os.path.join(ROOT, directory))):
        dirs[:] = sorted(d for d in dirs if not d.startswith(("_", ".")))
        if "__init__.py" not in files:
            continue
        rel = os.path.relpath(here, os.path.join(ROOT, directory))
        package = ".".join(["drake_entry", folder] + ([] if rel == "." else rel.split(os.sep)))
        names.append(package)
        names += [f"{package}.{f[:-3]}" for f in sorted(files) if f.endswith(".py") and not f.startswith("_")]
    return names


def api_markdown(title: str, intro: str, folders, singles) -> str:
    lines = [f"# {title}", "", intro, ""]
    for name in list(singles) + [m for folder in folders for m in _modules(folder)]:
        lines.append(f"::: {name}")
    return "\n".join(lines) + "\n"


def on_files(files, config):
    import importlib

    from drake_entry.schema_doc import schema_markdown

    for uri, (module, cls, title, intro) in PAGES.items():
        root = getattr(importlib.import_module(module), cls)
        files.append(File.generated(config, uri, content=schema_markdown(root, title, intro=intro)))
    for uri, title, intro, folders, singles in API_PAGES:
        files.append(File.generated(config, uri, content=api_markdown(title, intro, folders, singles)))
    return files
