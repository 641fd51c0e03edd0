"""The layers of docs/architecture.md, read from the import statements of every module.

  model     drake_entry/ (models, planning, scenario, guidance specs and registry, report)
  systems   systems/           Drake LeafSystems
  methods   drake_entry/guidance/<method>/method.py, guidance/reversal.py: a method's wiring
  diagrams  diagrams/          builders, campaign runner
  cli       drake_entry/cli.py, drake_entry/guidance/<method>/commands.py

A layer imports only the layers before it. Two deliberate exceptions:
planning/nlp/dircol.py imports systems.ocp_plant (Drake's DirectCollocation takes a System), and
planning/nlp/verify.py imports diagrams.propagation (an NLP's success is verified by flying its
controls with the Drake Simulator).
No method's package imports another method's.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ("model", "systems", "methods", "diagrams", "cli")
EXCEPTIONS = {("drake_entry.planning.nlp.dircol", "drake_entry.systems.ocp_plant"),
              ("drake_entry.planning.nlp.verify", "drake_entry.diagrams.propagation")}
METHOD_PLANNERS = ("drake_entry.planning.drag_energy", "drake_entry.planning.nlp", "drake_entry.planning.swarm",
                   "drake_entry.planning.ampi",
                   "drake_entry.planning.scvx")


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[0] in ("systems", "diagrams"):  # installed inside the drake_entry namespace
        parts = ["drake_entry"] + parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def layer(module: str) -> str:
    parts = module.split(".")
    if parts[:2] == ["drake_entry", "systems"]:
        return "systems"
    if parts[:2] == ["drake_entry", "diagrams"]:
        return "diagrams"
    if module == "drake_entry.cli" or (parts[:2] == ["drake_entry", "guidance"] and parts[-1] == "commands"):
        return "cli"
    if module == "drake_entry.guidance.reversal" or (parts[:2] == ["drake_entry", "guidance"]
                                                      and parts[-1] == "method"):
        return "methods"
    return "model"


def imports(source: str, module: str, is_package: bool) -> set:
    """Absolute names of the project modules a source imports (top level or in functions)."""
    out = set()
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return {n for n in out if n.split(".")[0] in ("drake_entry", "systems", "diagrams")}


def violations(module: str, imported: set, known: set) -> list:
    """Layer-rule violations of one module's imports (``known``: the project's modules)."""
    found = []
    mine = layer(module)
    for name in imported:
        if name.split(".")[0] in ("systems", "diagrams"):
            found.append(f"{module} imports '{name}': use drake_entry.{name}")
            continue
        target = name if name in known else name.rpartition(".")[0]
        if target not in known or (module, target) in EXCEPTIONS:
            continue
        if ORDER.index(layer(target)) > ORDER.index(mine):
            found.append(f"{module} ({mine}) imports {target} ({layer(target)})")
        mp, tp = module.split("."), target.split(".")
        if mp[:2] == tp[:2] == ["drake_entry", "guidance"] and len(mp) > 3 and len(tp) > 3 and mp[2] != tp[2]:
            found.append(f"{module} imports another method's package: {target}")
        for a in METHOD_PLANNERS:
            for b in METHOD_PLANNERS:
                if a != b and module.startswith(a) and target.startswith(b):
                    found.append(f"{module} imports another method's planner: {target}")
    return found


def project_modules() -> dict:
    files = [p for d in ("drake_entry", "systems", "diagrams") for p in (ROOT / d).rglob("*.py")]
    return {module_name(p): p for p in files}


def test_every_module_imports_only_the_layers_before_it():
    mods = project_modules()
    known = set(mods)
    found = []
    for module, path in mods.items():
        found += violations(module, imports(path.read_text(), module, path.name == "__init__.py"), known)
    assert not found, "\n".join(sorted(found))


def test_the_layer_check_catches_violations():
    known = {"drake_entry.diagrams.closed_loop", "drake_entry.systems.vehicle", "drake_entry.planning.nlp",
             "drake_entry.planning.drag_energy", "drake_entry.guidance.bank_profile.method",
             "drake_entry.guidance.drag_energy.spec", "drake_entry.cli"}
    cases = {
        ("drake_entry.scenario", "from .diagrams.closed_loop import fly"): "(model) imports",
        ("drake_entry.systems.vehicle", "from drake_entry.diagrams.closed_loop import fly"): "(systems) imports",
        ("drake_entry.guidance.drag_energy.method", "from drake_entry.cli import main"): "(methods) imports",
        ("drake_entry.plots", "from systems.vehicle import EntryVehicle"): "use drake_entry.systems",
        ("drake_entry.guidance.drag_energy.method", "from ..bank_profile.method import METHOD"): "another method's",
        ("drake_entry.planning.drag_energy", "from .nlp import solve"): "another method's planner",
    }
    for (module, source), message in cases.items():
        got = violations(module, imports(source, module, False), known)
        assert any(message in v for v in got), (module, source, got)
    assert not violations("drake_entry.diagrams.sample", imports("from ..systems.vehicle import X",
                                                                 "drake_entry.diagrams.sample", False), known)


@pytest.mark.parametrize("name", ["benchmark", "benchmarks"])
def test_benchmarks_live_outside_the_library(name):
    assert not (ROOT / "drake_entry" / f"{name}.py").exists()
    assert not any(n.startswith(name) for n in project_modules())


def test_every_package_directory_is_installed():
    """pyproject lists its packages explicitly (package-dir maps systems/ and diagrams/):
    a new package directory missing from the list would be absent from the wheel."""
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    code = {module_name(p.parent / "__init__.py") for d in ("drake_entry", "systems", "diagrams")
            for p in (ROOT / d).rglob("__init__.py")}
    assert code <= listed, sorted(code - listed)
