"""The documentation stays true: README's commands are the ones CI runs, the YAML reference
covers every schema field, and every page in the site's navigation exists (the site itself is
built with ``mkdocs build --strict`` in .ci/run)."""
import dataclasses as dc
import os
import re
import typing
from pathlib import Path

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _read(path):
    with open(os.path.join(ROOT, path)) as f:
        return f.read()


def test_readme_test_command_is_the_one_ci_runs():
    readme, ci = _read("README.md"), _read(".ci/run")
    commands = re.findall(r"```bash\n(.*?)\n```", readme)
    test_cmd = next(c for c in commands if "pytest" in c)
    assert test_cmd.split(" && ", 2)[2] in ci  # pip install ".[test]" && python -m pytest
    assert any("drake-entry campaign" in c for c in commands)


def _schemas(root):
    seen, queue = [], [root]
    while queue:
        cls = queue.pop()
        if cls in seen:
            continue
        seen.append(cls)
        for t in typing.get_type_hints(cls).values():
            for member in typing.get_args(t) or (t,):
                for inner in typing.get_args(member) or (member,):
                    if dc.is_dataclass(inner) and isinstance(inner, type) and not inner.__module__.startswith("pydrake"):
                        queue.append(inner)
    return seen


@pytest.mark.parametrize("module, name", [("drake_entry.scenario", "Scenario"), ("drake_entry.models.vehicles", "VehicleSpec"),
                                          ("drake_entry.planning.ocp_yaml", "ProblemSpec"),
                                          ("drake_entry.comparison.spec", "Comparison")])
def test_yaml_reference_has_every_schema_field(module, name):
    import importlib

    from drake_entry.schema_doc import schema_markdown

    root = getattr(importlib.import_module(module), name)
    page = schema_markdown(root, name)
    schemas = _schemas(root)
    assert len(schemas) >= 3
    for cls in schemas:
        assert f"## {cls.__name__}" in page
        for f in dc.fields(cls):
            assert f"| `{f.name}` |" in page, (cls.__name__, f.name)
    if name == "Scenario":  # every registered guidance method is documented with its tag
        from drake_entry.guidance import REGISTRY

        for spec in REGISTRY:
            assert f"## {spec.__name__} (YAML tag `!{spec.__name__}`)" in page


def test_field_descriptions_come_from_the_comments_beside_the_fields():
    from drake_entry.guidance.swarm_bank.spec import SwarmBank
    from drake_entry.scenario import AtmosphereSpec, SimulationSpec
    from drake_entry.schema_doc import field_comments

    assert field_comments(SimulationSpec)["max_time_s"] == "hard stop [s] if no terminal condition triggers"
    assert field_comments(AtmosphereSpec)["model"] == "us76 | exponential | table | nrlmsis"
    assert "eq. 17" in field_comments(SwarmBank)["bank_start_deg"]


def test_every_page_in_the_navigation_exists():
    import yaml

    config = yaml.safe_load(_read("mkdocs.yml").replace("!!python", "#"))
    generated = set(re.findall(r'^    "(reference/\w+\.md)"', _read("docs/hooks/reference.py"), re.M))  # YAML pages
    assert {"reference/scenario.md", "reference/vehicle.md", "reference/problem.md"} <= generated
    generated |= set(re.findall(r'\("(api/\w+\.md)"', _read("docs/hooks/reference.py")))  # the API pages
    assert {"api/models.md", "api/guidance.md"} <= generated

    def pages(nav):
        for item in nav:
            for value in (item.values() if isinstance(item, dict) else [item]):
                yield from (pages(value) if isinstance(value, list) else [value])

    found = list(pages(config["nav"]))
    assert len(found) >= 15
    for page in found:
        assert page in generated or os.path.isfile(os.path.join(ROOT, "docs", page)), page


def test_readme_and_getting_started_name_every_example_and_scenario():
    """The lists a newcomer reads are complete: every example in README.md, every packaged
    scenario in getting-started.md (drake-entry scenarios lists them from the files)."""
    root = Path(ROOT)
    readme = (root / "README.md").read_text()
    missing = [p.name for p in sorted((root / "examples").glob("[0-9]*.py")) if p.name not in readme]
    assert not missing, f"README.md does not name {missing}"
    start = (root / "docs" / "getting-started.md").read_text()
    names = [p.stem for p in sorted((root / "drake_entry" / "scenarios").glob("*.yaml"))]
    assert not [n for n in names if f"`{n}`" not in start], names
