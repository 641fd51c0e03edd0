"""The layers of docs/architecture.md, read from the import statements of every module.

  models    drake_entry/errors.py, typed_yaml.py,          physics and the typed YAML reader; import nothing
            drake_entry/models/                            else of the project
  planning  drake_entry/ (all but the other rows)          shared planning, method planners and specs,
                                                           scenario, campaign outputs
  systems   systems/                                       Drake LeafSystems
  methods   drake_entry/guidance/<method>/method.py,       a method's wiring
            drake_entry/guidance/reversal_wiring.py, replanning_wiring.py
  diagrams  diagrams/                                      builders, campaign runner
  cli       drake_entry/cli.py, */commands.py              commands

A layer imports only the layers before it, without exceptions: planners that verify a plan by
flying its controls with the Drake Simulator receive the flight (diagrams.verification) as an
argument.
No method's folder (drake_entry/guidance/<method>/) imports another method's, and the shared
packages (models, planning, campaign) import no method's folder.
"""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ("models", "planning", "systems", "methods", "diagrams", "cli")
SHARED = ("drake_entry.models", "drake_entry.planning", "drake_entry.campaign", "drake_entry.errors",
          "drake_entry.typed_yaml")


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


def layer(module: str) -> str:
    parts = module.split(".")
    if module in ("drake_entry.errors", "drake_entry.typed_yaml") or parts[:2] == ["drake_entry", "models"]:
        return "models"
    if parts[:2] == ["drake_entry", "systems"]:
        return "systems"
    if parts[:2] == ["drake_entry", "diagrams"]:
        return "diagrams"
    if module == "drake_entry.cli" or parts[-1] == "commands":
        return "cli"
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


def violations(module: str, imported: set, known: set) -> list:
    """Layer-rule violations of one module's imports (``known``: the project's modules)."""
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
    return found


def project_modules() -> dict:
    files = [p for d in ["drake_entry", *INSTALLED_AS] for p in (ROOT / d).rglob("*.py")]
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
             "drake_entry.guidance.drag_energy.planner", "drake_entry.guidance.bank_profile.method",
             "drake_entry.guidance.drag_energy.spec", "drake_entry.cli", "drake_entry.scenario",
             "drake_entry.guidance.scvx.engine"}
    cases = {
        ("drake_entry.scenario", "from .diagrams.closed_loop import fly"): "(planning) imports",
        ("drake_entry.models.vehicles", "from drake_entry.scenario import Scenario"): "(models) imports",
        ("drake_entry.systems.vehicle", "from drake_entry.diagrams.closed_loop import fly"): "(systems) imports",
        ("drake_entry.guidance.drag_energy.method", "from drake_entry.cli import main"): "(methods) imports",
        ("drake_entry.campaign.plots", "from systems.vehicle import EntryVehicle"): "use drake_entry.systems",
        ("drake_entry.guidance.drag_energy.method", "from ..bank_profile.method import METHOD"): "another method's",
        ("drake_entry.guidance.drag_energy.planner", "from ..scvx.engine import X"): "another method's",
        ("drake_entry.planning.tracking", "from drake_entry.guidance.scvx.engine import X"): "(shared) imports",
        ("drake_entry.campaign.report", "from drake_entry.guidance.drag_energy import spec"): "(shared) imports",
    }
    for (module, source), message in cases.items():
        got = violations(module, imports(source, module, False), known)
        assert any(message in v for v in got), (module, source, got)
    for module, source in (("drake_entry.diagrams.sample", "from ..systems.vehicle import X"),
                           ("drake_entry.guidance.drag_energy.planner", "from drake_entry.planning import nlp"),
                           ("drake_entry.guidance.drag_energy.planner", "from .spec import DragEnergy")):
        assert not violations(module, imports(source, module, False), known), (module, source)


@pytest.mark.parametrize("name", ["benchmark", "benchmarks"])
def test_benchmarks_live_outside_the_library(name):
    assert not (ROOT / "drake_entry" / f"{name}.py").exists()
    assert not any(n.startswith(name) for n in project_modules())


def test_every_package_directory_is_installed():
    """pyproject lists its packages explicitly (package-dir maps systems/ and diagrams/): a new
    package directory missing from the list would be absent from the wheel, a stale entry would
    install nothing."""
    setuptools = setuptools_config()
    listed = set(setuptools["packages"])
    code = {module_name(p.parent / "__init__.py") for d in ["drake_entry", *INSTALLED_AS]
            for p in (ROOT / d).rglob("__init__.py")}
    assert code <= listed, sorted(code - listed)
    for name in listed:
        directory = setuptools["package-dir"].get(name, name.replace(".", "/"))
        assert (ROOT / directory).is_dir(), f"pyproject lists {name}, but {directory}/ does not exist"
    for name, patterns in setuptools["package-data"].items():  # every data file ships
        assert name in listed, f"package-data names {name}, which is not a listed package"
        assert any(any((ROOT / name.replace(".", "/")).glob(p)) for p in patterns), (name, patterns)
    data_dirs = {p.parent.relative_to(ROOT).as_posix().replace("/", ".") for p in (ROOT / "drake_entry").rglob("*")
                 if p.suffix in (".yaml", ".csv", ".npz")}
    assert data_dirs <= set(setuptools["package-data"]), sorted(data_dirs - set(setuptools["package-data"]))


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
    """drake_entry/cli.py imports no method's folder; the commands a method folder contributes
    (COMMANDS in its commands.py) are found without a list kept by hand."""
    from drake_entry.cli import contributed_commands

    module = "drake_entry.cli"
    imported = imports((ROOT / "drake_entry" / "cli.py").read_text(), module, False)
    assert not [name for name in imported if method_folder(name)], imported
    names = {c.name for c in contributed_commands()}
    assert {"optimize", "fit-horus"} <= names
    folders = [p.parent.name for p in (ROOT / "drake_entry" / "guidance").glob("*/commands.py")]
    assert "drag_energy" in folders
