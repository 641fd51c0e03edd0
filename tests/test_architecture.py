"""The layers of docs/architecture.md, read from the import statements of every module.

  base        drake_entry/errors.py, typed_yaml.py, user_cache.py,  physics, data, the typed YAML reader,
              models/                                             the user's cache folders
  planning    drake_entry/ (all but the other rows): planning/,   shared planning, every method's spec
              guidance/ (specs, planners, laws), scenario,        and planner, the scenario, shared
              figures, tables                                     figures and tables
  systems     systems/                                            Drake LeafSystems
  methods     guidance/<method>/method.py, guidance/*_wiring.py   a method's wiring
  diagrams    diagrams/                                           diagram builders, the plan verifier
  campaign    campaign/, a method folder's studies                the campaign engine, store, report;
              (*study.py, report.py)                              a method's campaigns of its own cases
  comparison  comparison/                                         several methods on one mission
  cli         cli/                                                every command

A layer imports only the layers before it, without exceptions: planners that verify a plan by
flying its controls with the Drake Simulator receive the flight (diagrams.verification) as an
argument. No method's folder (drake_entry/guidance/<method>/) imports another method's, the
shared packages (models, planning, campaign) import no method's folder, and no module imports a
private name (``_x``) of another package.

``python tests/test_architecture.py`` prints the package import graph: packages, layers, edges
and the edges that point up.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ("base", "planning", "systems", "methods", "diagrams", "campaign", "comparison", "cli")
SHARED = ("drake_entry.models", "drake_entry.planning", "drake_entry.campaign", "drake_entry.errors",
          "drake_entry.typed_yaml", "drake_entry.figures", "drake_entry.tables", "drake_entry.scenario",
          "drake_entry.comparison", "drake_entry.diagrams")


def setuptools_config() -> dict:
    """pyproject's [tool.setuptools]: the package list and the ``package-dir`` mapping."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]


#: {repository directory: installed package} from ``package-dir`` (systems -> drake_entry.systems)
INSTALLED_AS = {directory: name for name, directory in setuptools_config()["package-dir"].items() if name}


def module_name(path: Path) -> str:
    """A source file's module name as installed."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[0] in INSTALLED_AS:
        parts = INSTALLED_AS[parts[0]].split(".") + parts[1:]
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def is_study(module: str) -> bool:
    """A method folder's campaign of its own cases or its report (campaign layer)."""
    last = module.rsplit(".", 1)[-1]
    return method_folder(module) is not None and (last == "study" or last.endswith("_study") or last == "report")


def layer(module: str) -> str:
    parts = module.split(".")
    if module in ("drake_entry.errors", "drake_entry.typed_yaml", "drake_entry.user_cache") or parts[:2] == [
            "drake_entry", "models"]:
        return "base"
    top = {"systems": "systems", "diagrams": "diagrams", "campaign": "campaign", "comparison": "comparison",
           "cli": "cli"}
    if len(parts) > 1 and parts[0] == "drake_entry" and parts[1] in top:
        return top[parts[1]]
    if is_study(module):
        return "campaign"
    if module in ("drake_entry.guidance.reversal_wiring", "drake_entry.guidance.replanning_wiring") or (
            parts[:2] == ["drake_entry", "guidance"] and parts[-1] == "method"):
        return "methods"
    return "planning"


def method_folder(module: str):
    """The method a module belongs to (``drake_entry.guidance.<method>.*``), else None."""
    parts = module.split(".")
    return parts[2] if parts[:2] == ["drake_entry", "guidance"] and len(parts) > 3 else None


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


def package_of(module: str, packages: set) -> str:
    """The package (directory) a module lives in: itself for a package's ``__init__``."""
    return module if module in packages else module.rpartition(".")[0]


def violations(module: str, imported: set, known: set, packages: frozenset = frozenset()) -> list:
    """Layer-rule violations of one module's imports (``known``: the project's modules;
    ``packages``: those of them that are packages)."""
    found = []
    mine = layer(module)
    for name in imported:
        if name.split(".")[0] in ("systems", "diagrams"):
            found.append(f"{module} imports '{name}': use drake_entry.{name}")
            continue
        target = name if name in known else name.rpartition(".")[0]
        if target not in known:
            continue
        if ORDER.index(layer(target)) > ORDER.index(mine):
            found.append(f"{module} ({mine}) imports {target} ({layer(target)})")
        mine_m, theirs_m = method_folder(module), method_folder(target)
        if theirs_m and mine_m and mine_m != theirs_m:
            found.append(f"{module} imports another method's folder: {target}")
        if theirs_m and module.startswith(SHARED):
            found.append(f"{module} (shared) imports a method's folder: {target}")
        last = name.rpartition(".")[2]
        if (name not in known and last.startswith("_") and not last.startswith("__")
                and package_of(target, packages) != package_of(module, packages)):
            found.append(f"{module} imports the private name {name} of another package")
    return found


def project_modules() -> dict:
    files = [p for d in ["drake_entry", *INSTALLED_AS] for p in (ROOT / d).rglob("*.py")]
    return {module_name(p): p for p in files}


def project_graph() -> tuple[dict, set, set]:
    """({module: path}, the set of packages, {(importer, imported module)}) of the project."""
    mods = project_modules()
    known = set(mods)
    packages = {m for m, p in mods.items() if p.name == "__init__.py"}
    edges = set()
    for module, path in mods.items():
        for name in imports(path.read_text(), module, path.name == "__init__.py"):
            target = name if name in known else name.rpartition(".")[0]
            if target in known and target != module:
                edges.add((module, target))
    return mods, packages, edges


def test_every_module_imports_only_the_layers_before_it():
    mods, packages, _ = project_graph()
    known = set(mods)
    found = []
    for module, path in mods.items():
        found += violations(module, imports(path.read_text(), module, path.name == "__init__.py"), known,
                            frozenset(packages))
    assert not found, "\n".join(sorted(found))


def declared_public(source: str) -> list | None:
    """A module's ``__all__`` (a list of string literals), None when it declares none."""
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign) and any(isinstance(x, ast.Name) and x.id == "__all__" for x in node.targets):
            return [e.value for e in node.value.elts]
    return None


def defined_names(source: str) -> set:
    """The names a module binds at its top level (definitions, assignments, imports)."""
    names = set()
    for node in ast.parse(source).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                names.update(n.id for n in ast.walk(target) if isinstance(n, ast.Name))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


def test_every_module_declares_its_public_names_and_other_packages_import_only_those():
    """Each module's ``__all__`` names what it defines (a package's: its modules, or what its
    ``__init__`` defines); a module of another package imports only names in that ``__all__``."""
    mods, packages, _ = project_graph()
    public = {}
    for module, path in mods.items():
        source = path.read_text()
        declared = declared_public(source)
        assert declared is not None, f"{module} declares no __all__"
        missing = [n for n in declared if n not in defined_names(source) and f"{module}.{n}" not in mods]
        assert not missing, f"{module}.__all__ names what it does not define: {missing}"
        public[module] = set(declared)
    found = []
    for module, path in mods.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom) or node.level or not node.module or node.module not in mods:
                continue
            if package_of(node.module, packages) == package_of(module, packages):
                continue
            for alias in node.names:
                if alias.name not in public[node.module] and f"{node.module}.{alias.name}" not in mods:
                    found.append(f"{module} imports {alias.name} from {node.module}, which does not declare it public")
    assert not found, "\n".join(sorted(found))


def test_the_layer_check_catches_violations():
    known = {"drake_entry.diagrams.closed_loop", "drake_entry.systems.vehicle", "drake_entry.planning.nlp",
             "drake_entry.campaign.store", "drake_entry.campaign.report",
             "drake_entry.guidance.drag_energy.planner", "drake_entry.guidance.bank_profile.method",
             "drake_entry.guidance.drag_energy.spec", "drake_entry.cli", "drake_entry.scenario",
             "drake_entry.guidance.scvx.engine"}
    cases = {
        ("drake_entry.scenario", "from .diagrams.closed_loop import fly"): "(planning) imports",
        ("drake_entry.models.vehicles", "from drake_entry.scenario import Scenario"): "(base) imports",
        ("drake_entry.systems.vehicle", "from drake_entry.diagrams.closed_loop import fly"): "(systems) imports",
        ("drake_entry.guidance.drag_energy.method", "from drake_entry.cli import main"): "(methods) imports",
        ("drake_entry.figures", "from systems.vehicle import EntryVehicle"): "use drake_entry.systems",
        ("drake_entry.guidance.drag_energy.method", "from ..bank_profile.method import METHOD"): "another method's",
        ("drake_entry.guidance.drag_energy.planner", "from ..scvx.engine import X"): "another method's",
        ("drake_entry.planning.tracking", "from drake_entry.guidance.scvx.engine import X"): "(shared) imports",
        ("drake_entry.campaign.report", "from drake_entry.guidance.drag_energy import spec"): "(shared) imports",
        ("drake_entry.guidance.drag_energy.planner", "from drake_entry.cli import main"): "(planning) imports",
        ("drake_entry.diagrams.closed_loop", "from drake_entry.campaign.store import X"): "(diagrams) imports",
        ("drake_entry.planning.nlp", "from drake_entry.campaign.store import X"): "(planning) imports",
        ("drake_entry.campaign.report", "from drake_entry.cli import main"): "(campaign) imports",
        ("drake_entry.campaign.report", "from drake_entry.scenario import _secret"): "private name",
    }
    for (module, source), message in cases.items():
        got = violations(module, imports(source, module, False), known)
        assert any(message in v for v in got), (module, source, got)
    for module, source in (("drake_entry.campaign.sample", "from ..systems.vehicle import X"),
                           ("drake_entry.guidance.drag_energy.planner", "from drake_entry.planning import nlp"),
                           ("drake_entry.guidance.drag_energy.planner", "from .spec import DragEnergy")):
        assert not violations(module, imports(source, module, False), known), (module, source)


@pytest.mark.parametrize("name", ["benchmark", "benchmarks"])
def test_benchmarks_live_outside_the_library(name):
    assert not (ROOT / "drake_entry" / f"{name}.py").exists()
    assert not any(n.startswith(name) for n in project_modules())


def test_every_package_directory_is_installed():
    """The package list is derived (setup.py: every package directory under drake_entry/ and the two
    that package-dir maps), so a new method folder needs no entry: every module and data file of
    the tree is in the installed package (a wheel in CI)."""
    import importlib.util

    import drake_entry

    installed = Path(drake_entry.__file__).resolve().parent
    for module in project_modules():
        spec = importlib.util.find_spec(module)
        assert spec is not None and spec.origin, f"{module} is not installed"
    data = [p.relative_to(ROOT / "drake_entry") for p in (ROOT / "drake_entry").rglob("*")
            if p.suffix in (".yaml", ".csv", ".npz")]
    assert data
    missing = [str(p) for p in data if not (installed / p).is_file()]
    assert not missing, missing
    assert "packages" not in setuptools_config(), "the package list is derived in setup.py"


def test_the_tests_run_against_the_installed_package():
    """The README's test command imports the installed package, not the working tree: a wheel
    install is tested as users get it (an editable install maps to this tree by design)."""
    import importlib.metadata
    import json

    import drake_entry
    import drake_entry.systems

    installs = [json.loads(d.read_text("direct_url.json") or "{}")
                for d in importlib.metadata.distributions(name="drake_entry")]  # a stray egg-info has none
    editable = any(i.get("dir_info", {}).get("editable", False) for i in installs)
    from_tree = Path(drake_entry.__file__).resolve().parent == ROOT / "drake_entry"
    assert from_tree == editable, (drake_entry.__file__, "editable" if editable else "wheel")
    systems_dir = Path(drake_entry.systems.__file__).resolve().parent
    assert systems_dir == (ROOT / "systems" if editable else Path(drake_entry.__file__).resolve().parent / "systems")


def test_loading_a_scenario_loads_specs_only():
    """Specs are pure data: reading any scenario imports no planner, no method wiring and no
    Drake solver or systems module (they load when a method builds its planner)."""
    import subprocess
    import sys

    code = ("import sys; from drake_entry.scenario import PACKAGED_SCENARIOS, load_scenario\n"
            "for name in PACKAGED_SCENARIOS: load_scenario(name)\n"
            "print(' '.join(sorted(n for n in sys.modules if n.startswith(('pydrake.solvers', 'pydrake.systems')) "
            "or (n.startswith('drake_entry.guidance.') and n.rsplit('.', 1)[1] not in "
            "('spec', 'settings', 'mission') and n.count('.') > 2))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == [], out


def test_the_cli_knows_no_method_and_finds_every_command():
    """drake_entry/cli/ imports no method's folder at its top level (a method's commands live in
    cli/methods/<folder>.py, found through the registry), and nothing below the CLI imports it."""
    from drake_entry.cli import commands

    for path in (ROOT / "drake_entry" / "cli").glob("*.py"):
        module = module_name(path)
        imported = imports(path.read_text(), module, path.name == "__init__.py")
        assert not [name for name in imported if method_folder(name)], (module, imported)
    names = {c.name for c in commands()}
    assert {"scenarios", "campaign", "report", "fly", "plan", "simulate", "results", "compare", "optimize",
            "fit-horus"} <= names
    assert not list((ROOT / "drake_entry").rglob("commands.py")), "commands live in drake_entry/cli/"


def node(module: str, packages: set) -> str:
    """A module's node in the package graph: its package, or itself at the top of drake_entry."""
    package = package_of(module, packages)
    return module if package == "drake_entry" else package


def package_graph() -> dict:
    """The package-level import graph: {(importer package, imported package): module edges}, the
    layer of each package (its lowest module's) and the edges whose modules point up."""
    mods, packages, edges = project_graph()
    graph = {}
    for a, b in edges:
        key = (node(a, packages), node(b, packages))
        if key[0] != key[1]:
            graph.setdefault(key, []).append((a, b))
    return graph


if __name__ == "__main__":  # the import graph, for the architecture notes
    mods, packages, edges = project_graph()
    graph = package_graph()
    up = [(a, b) for a, b in edges if ORDER.index(layer(b)) > ORDER.index(layer(a))]
    print(f"{len(mods)} modules, {len(packages)} packages, {len(edges)} module edges, "
          f"{len(graph)} package edges, {len(up)} module edges pointing up")
    for (pa, pb), pairs in sorted(graph.items()):
        print(f"  {pa:36s} -> {pb:36s} {len(pairs)}")
    for a, b in sorted(up):
        print(f"  UP {a} ({layer(a)}) -> {b} ({layer(b)})")
