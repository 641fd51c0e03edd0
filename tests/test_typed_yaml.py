"""One typed loader for files and overrides (drake_entry.typed_yaml): the same value is
accepted or refused the same way from a scenario file, from ``--set`` and from the API, and
every refusal is one ScenarioError naming the full field path."""
import dataclasses as dc
import math
import re

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from drake_entry.errors import ScenarioError  # noqa: E402
from drake_entry.scenario import PACKAGED_SCENARIOS, Scenario, apply_overrides, load_scenario  # noqa: E402
from drake_entry.typed_yaml import check, load_yaml_typed, parse  # noqa: E402


def test_every_packaged_scenario_passes_the_field_checks():
    """The checker refuses nothing the packaged files hold (each loads and validates)."""
    for name in PACKAGED_SCENARIOS:
        assert isinstance(load_scenario(name), Scenario)


@pytest.mark.parametrize("key, text, expected", [
    ("guidance.period_s", "fast", "guidance.period_s: expected a number, got 'fast'"),
    ("entry.velocity_m_s", "fast", "entry.velocity_m_s: expected a number, got 'fast'"),
    ("planet.rotating", "maybe", "planet.rotating: expected true or false, got 'maybe'"),
    ("simulation.log_period_s", "[1", "not valid YAML"),
    ("guidance", "null", "guidance: expected a tagged block"),
    ("guidance", "3", "guidance: expected a tagged block"),
    ("entry", "7000", "entry: expected a block of fields (a mapping), got 7000"),
    ("guidance", "!NoSuchMethod {}", "guidance: unknown type tag '!NoSuchMethod'; allowed: !DragEnergy"),
    ("entry.velocty_m_s", "7000", "entry.velocty_m_s: unknown field 'velocty_m_s' in entry; did you mean velocity_m_s?"),
    ("nosuch.field", "1", "nosuch.field: unknown field 'nosuch'; allowed: aero, alpha"),
    ("entry.velocity_m_s.x", "1", "entry.velocity_m_s is a value"),
    ("entry..x", "1", "a field path is names joined by dots"),
    ("entry.velocity_m_s", "!!python/object:os.system {}", "not valid YAML"),
])
def test_a_bad_override_is_one_line_naming_the_field(key, text, expected):
    scenario = load_scenario("horus2b")
    with pytest.raises(ScenarioError) as e:
        apply_overrides(scenario, {key: text})
    assert expected in str(e.value) and "\n" not in str(e.value)


def test_an_integer_field_refuses_a_fraction_from_the_file_and_from_an_override():
    """``n_nodes: 40.5`` was refused in a file but ran from ``--set``: now refused by both."""
    scenario = load_scenario("horus2b")
    with pytest.raises(ScenarioError, match=r"guidance\.n_nodes: expected an integer, got 40\.5"):
        apply_overrides(scenario, {"guidance.n_nodes": "40.5"})
    text = re.sub(r"n_nodes: \d+", "n_nodes: 40.5", _packaged_text("horus2b"))
    assert "n_nodes: 40.5" in text
    with pytest.raises(ScenarioError, match=r"guidance\.n_nodes: expected an integer, got 40\.5"):
        load_yaml_typed(Scenario, text=text, where="f.yaml")


def test_an_override_sets_exactly_the_field_and_keeps_the_rest():
    scenario = load_scenario("sphynx_paper001")
    before = dc.asdict(scenario.entry)
    apply_overrides(scenario, {"entry.velocity_m_s": "7000.5", "planet.rotating": False,
                               "guidance.period_s": 2.0})
    assert scenario.entry.velocity_m_s == 7000.5 and scenario.planet.rotating is False
    assert scenario.guidance.period_s == 2.0 and type(scenario.guidance).__name__ == "Scvx"
    assert {k: v for k, v in dc.asdict(scenario.entry).items() if k != "velocity_m_s"} == \
           {k: v for k, v in before.items() if k != "velocity_m_s"}


def test_a_whole_block_by_its_tag_replaces_the_method():
    scenario = load_scenario("sphynx_paper001")
    apply_overrides(scenario, {"guidance": "!DragEnergy {n_nodes: 30}"})
    assert type(scenario.guidance).__name__ == "DragEnergy" and scenario.guidance.n_nodes == 30


def test_an_override_out_of_range_is_refused_by_the_same_validation_as_the_file():
    scenario = load_scenario("horus2b")
    with pytest.raises(ScenarioError, match="period_s"):
        apply_overrides(scenario, {"guidance.period_s": "-1"})


def test_file_errors_name_the_section_and_the_closest_field(tmp_path):
    cases = {
        "entry:\n  velocty_m_s: 7000\n": "entry.velocty_m_s: unknown field; did you mean velocity_m_s?",
        "entry:\n  altitude_km: high\n": "entry.altitude_km: expected a number, got 'high'",
        "# only a comment\n": "the file is empty",
        "guidance: 3\n": "guidance: expected a tagged block",
        "dispersions:\n  mass_scale: heavy\n": "dispersions.mass_scale: expected a number or a tagged block",
        "entry: [1, 2\n": "not valid YAML (line",
        "name: a\nname: b\n": "not valid YAML (line 2, column 1): the field 'name' is given twice",
    }
    for text, expected in cases.items():
        path = tmp_path / "s.yaml"
        path.write_text(text)
        with pytest.raises(ScenarioError) as e:
            load_scenario(str(path))
        assert expected in str(e.value), (text, str(e.value))
        assert str(e.value).startswith(str(path)) and "\n" not in str(e.value)


def test_tags_are_kept_and_never_constructed():
    data = parse("a: !Uniform {min: 0, max: 1}\nb: [1, 2]\n", "t")
    assert data["a"].tag == "Uniform" and data["a"].value == {"min": 0, "max": 1}
    with pytest.raises(ScenarioError, match="not valid YAML"):
        parse("a: !!python/object/apply:os.system ['true']\n", "t")


# -- fuzzing: random paths and values never give a traceback, and never a silent wrong type ---
_PATHS = st.sampled_from(["entry.velocity_m_s", "entry.altitude_km", "guidance.period_s", "guidance.n_nodes",
                          "planet.rotating", "planet.model", "simulation.integrator", "simulation.max_time_s",
                          "dispersions.mass_scale", "guidance", "entry", "name", "terminal.altitude_km",
                          "target.longitude_deg"]) | st.from_regex(r"[a-z_]{1,8}(\.[a-z_]{1,8}){0,2}", fullmatch=True)
_VALUES = st.one_of(
    st.sampled_from(["null", "~", "fast", "40.5", "-1", "0", "1e400", ".nan", "[1, 2]", "{a: 1}", "!Foo {}",
                     "true", "maybe", "''", "[", "{", "!!binary aGk=", "!DragEnergy {}", "7000", "1_000"]),
    st.text(max_size=12), st.integers(), st.floats(allow_nan=True), st.booleans(), st.none(),
    st.lists(st.integers(), max_size=3))


@settings(max_examples=150, deadline=None, derandomize=True, database=None)
@given(key=_PATHS, value=_VALUES)
def test_fuzzed_overrides_give_one_line_or_the_declared_type(key, value):
    scenario = load_scenario("horus2b")
    try:
        apply_overrides(scenario, {key: value})
    except ScenarioError as e:
        assert "\n" not in str(e) and str(e)
        return
    # accepted: the field holds a value of its declared kind
    obj = scenario
    for part in key.split("."):
        obj = getattr(obj, part)
    leaf = key.split(".")[-1]
    if leaf in ("velocity_m_s", "period_s", "max_time_s", "longitude_deg") or key == "entry.altitude_km":
        assert isinstance(obj, float)
    elif key == "terminal.altitude_km":  # Optional[float]
        assert obj is None or isinstance(obj, float)
    elif leaf == "n_nodes":
        assert isinstance(obj, int) and not isinstance(obj, bool)
    elif leaf == "rotating":
        assert isinstance(obj, bool)


def test_check_reports_nested_list_positions():
    @dc.dataclass
    class _L:
        values: list[float] = dc.field(default_factory=list)

    with pytest.raises(ScenarioError, match=r"values\[1\]: expected a number, got 'x'"):
        check(_L, {"values": [1.0, "x"]}, "")


def _packaged_text(name: str) -> str:
    from importlib import resources
    return resources.files("drake_entry").joinpath(f"scenarios/{name}.yaml").read_text()


def test_relative_files_are_read_beside_the_file_that_names_them(tmp_path, monkeypatch):
    """A user's mission folder (vehicle with its own aero tables, scenario, comparison), loaded
    from another working directory: every relative file name is read beside the YAML file that
    writes it; a file that is not there is refused naming where relative paths are read."""
    from importlib import resources

    from drake_entry.comparison.spec import load_comparison
    from drake_entry.models.vehicles import load_vehicle

    mission = tmp_path / "mission"
    (mission / "aero").mkdir(parents=True)
    data = resources.files("drake_entry").joinpath("data")
    for name in ("horus2b_clean_aero_m692.csv", "horus2b_clean_aero_fill_2024.csv"):
        (mission / "aero" / name).write_text(data.joinpath(name).read_text())
    vehicle = resources.files("drake_entry").joinpath("vehicles/horus2b.yaml").read_text()
    vehicle = vehicle.replace("table_csv: horus2b_clean_aero_m692.csv", "table_csv: aero/horus2b_clean_aero_m692.csv")
    vehicle = vehicle.replace("fill_csv: horus2b_clean_aero_fill_2024.csv",
                              "fill_csv: aero/horus2b_clean_aero_fill_2024.csv")
    assert vehicle.count("aero/") == 2
    (mission / "glider.yaml").write_text(vehicle.replace("name: horus2b", "name: glider"))
    (mission / "entry.yaml").write_text("based_on: horus2b\nvehicle: glider.yaml\naero: table\n")
    (mission / "compare.yaml").write_text("name: mine\nmission: entry.yaml\nmethods:\n"
                                          "  - {label: drag_energy, method: DragEnergy}\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)

    scenario = load_scenario(str(mission / "entry.yaml"))
    assert scenario.vehicle == str(mission / "glider.yaml")
    v = scenario.make_vehicle()
    packaged = load_vehicle("horus2b", aero="table")
    for alpha, mach in ((20.0, 5.0), (40.0, 15.0)):
        assert v.aero.coefficients(math.radians(alpha), mach) == pytest.approx(
            packaged.aero.coefficients(math.radians(alpha), mach), rel=1e-14)
    comparison = load_comparison(str(mission / "compare.yaml"))
    assert comparison.mission == str(mission / "entry.yaml")
    assert load_scenario(comparison.mission).vehicle == str(mission / "glider.yaml")

    (mission / "lost.yaml").write_text("based_on: horus2b\nvehicle: nowhere/glider.yaml\n")
    with pytest.raises(ScenarioError, match=r"vehicle 'nowhere/glider.yaml' is neither .* read beside that file"):
        load_scenario(str(mission / "lost.yaml"))
