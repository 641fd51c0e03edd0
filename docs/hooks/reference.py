"""MkDocs hooks: the YAML reference pages, generated at build time from the schema dataclasses
(drake_entry.schema_doc), so they cannot drift from the code; and the source tree the API
reference reads, with ``systems/`` and ``diagrams/`` placed inside ``drake_entry/`` as they are
installed (the repository keeps them at its top level)."""
import atexit
import os
import shutil
import tempfile

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


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
    for name in ("systems", "diagrams"):
        os.symlink(os.path.join(ROOT, name), os.path.join(package, name))
    handlers = config["plugins"]["mkdocstrings"].config["handlers"]
    handlers.setdefault("python", {})["paths"] = [tree]
    return config

PAGES = {
    "reference/scenario.md": ("drake_entry.scenario", "Scenario", "Scenario YAML",
                              "A mission file (`drake-entry fly FILE.yaml`, `load_scenario(path)`). Packaged "
                              "scenarios live in `drake_entry/scenarios/`. Fields not in SI carry their unit in "
                              "the name; a bad value is a one-line error naming the field and the allowed range."),
    "reference/vehicle.md": ("drake_entry.vehicles", "VehicleSpec", "Vehicle YAML",
                             "A vehicle file (`vehicle: path/to/file.yaml` in a scenario; packaged vehicles live "
                             "in `drake_entry/vehicles/`). `aero` maps model names to aerodynamic models; "
                             "`default_aero` picks one."),
    "reference/problem.md": ("drake_entry.planning.ocp_yaml", "ProblemSpec", "Optimal-control problem YAML",
                             "A problem file for the NLP path (`drake-entry optimize FILE.yaml`, "
                             "`load_problem(path)`)."),
}


def on_files(files, config):
    import importlib

    from drake_entry.schema_doc import schema_markdown

    for uri, (module, cls, title, intro) in PAGES.items():
        root = getattr(importlib.import_module(module), cls)
        files.append(File.generated(config, uri, content=schema_markdown(root, title, intro=intro)))
    return files
