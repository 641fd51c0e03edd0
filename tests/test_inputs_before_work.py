"""Inputs checked where they enter, before any work: non-finite and out-of-range numbers in
files and overrides, run arguments shared by the CLI and the API, comparison files and
directories with an identity, reports that need a campaign row. Each test is a hostile input
that used to end in a traceback, a silent acceptance, a refusal after the pre-flight planning,
a mixed directory or a report of nothing; it now ends in one line naming the field and leaves
the disk as it was."""
import json
import os
from pathlib import Path

import pytest

from drake_entry.campaign.rows import row_problem
from drake_entry.cli import main
from drake_entry.comparison.runner import check_comparison_dir, comparison_identity, run_comparison
from drake_entry.comparison.spec import ComparedMethod, Comparison, load_comparison
from drake_entry.errors import ScenarioError
from drake_entry.guidance.bank_profile.spec import BankProfile
from drake_entry.models.vehicles import load_vehicle
from drake_entry.scenario import Scenario, load_scenario
from drake_entry.typed_yaml import load_yaml_typed

ROOT = Path(__file__).resolve().parents[1]
APOLLO = (ROOT / "drake_entry/vehicles/apollo_cm.yaml").read_text()
BANK = BankProfile(terminal_altitude_km=26.5, bank_start_deg=66.0, bank_end_deg=50.0)


def _files(folder) -> dict:
    """Every file below ``folder`` with its size and modification time (what 'nothing changed' compares)."""
    return {str(p): (p.stat().st_size, p.stat().st_mtime_ns) for p in Path(folder).rglob("*")}


def _vehicle(tmp_path, old: str, new: str) -> str:
    assert old in APOLLO, old
    path = tmp_path / "v.yaml"
    path.write_text(APOLLO.replace(old, new))
    return str(path)


@pytest.fixture
def no_planning(monkeypatch):
    """Any pre-flight planning fails the test: the refusals come first."""
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup

    def refuse(*args, **kwargs):
        raise AssertionError("planned before the inputs were checked")
    monkeypatch.setattr(ClosedLoopSetup, "from_scenario", classmethod(refuse))


def _comparison(name="t", mission="horus2b", label="bp", **entry) -> Comparison:
    return Comparison(name=name, mission=mission, methods=[
        ComparedMethod(label=label, method="BankProfile", guidance=BANK, **entry)])


# -- numbers: finite and in range where they enter -------------------------------------------
@pytest.mark.parametrize("old, new, needle", [
    ("CL: [[0.40815]]", "CL: [[.nan]]", "aero.trim.CL[0][0] = nan is not a finite number"),
    ("form: sutton_graves", "form: chapman\n  velocity_exponent: .nan",
     "heat_flux.velocity_exponent = nan is not a finite number"),
    ("form: sutton_graves", "form: sutton_graves\n  velocity_exponent: 3.2",
     "velocity_exponent applies to forms chapman, normalised and lumped"),
    ("form: sutton_graves", "form: chapman\n  velocity_exponent: 50.0", "velocity_exponent = 50.0 is out of range"),
    ("form: sutton_graves", "form: sutton_graves\n  coefficient: -1.0", "heat_flux.coefficient = -1.0 is out of range"),
    ("reference_area_m2: 12.017", "reference_area_m2: 1.0e308", "reference_area_m2 = 1e+308 is out of range; "
                                                                 "allowed: (0, 10000] m^2"),
    ("mass_kg: 5498.22", "mass_kg: .inf", "mass_kg = inf is not a finite number (this field has no unbounded value)"),
    ("nose_radius_m: 4.694", "nose_radius_m: 1000.0", "nose_radius_m = 1000.0 is out of range"),
])
def test_a_vehicle_number_out_of_range_is_one_line_naming_it(tmp_path, old, new, needle):
    """A NaN heat-flux exponent was ignored (Sutton-Graves has its own) or reached the root
    finder; an area of 1e308 overflowed to NaN there."""
    with pytest.raises(ScenarioError) as raised:
        load_vehicle(_vehicle(tmp_path, old, new))
    assert needle in str(raised.value) and "\n" not in str(raised.value), str(raised.value)


def test_an_unbounded_limit_stays_allowed_where_the_default_is_unbounded(tmp_path):
    v = load_vehicle(_vehicle(tmp_path, "dynamic_pressure_max_kPa: 30.0", "dynamic_pressure_max_kPa: .inf"))
    assert v.limits.dynamic_pressure_max == float("inf")
    with pytest.raises(ScenarioError, match=r"heat_flux_max_kW_m2 = -inf is not a finite number"):
        load_vehicle(_vehicle(tmp_path, "heat_flux_max_kW_m2: 6000.0", "heat_flux_max_kW_m2: -.inf"))


def test_an_override_is_held_to_the_same_numbers_as_a_file():
    from drake_entry.scenario import apply_overrides

    s = load_scenario("horus2b")
    for field, value in (("entry.altitude_km", ".nan"), ("terminal.distance_tolerance_km", ".inf"),
                         ("guidance.period_s", "-.inf")):
        with pytest.raises(ScenarioError, match=f"{field} = -?(nan|inf) is not a finite number"):
            apply_overrides(s, {field: value})


def test_yaml_text_must_be_text():
    with pytest.raises(ScenarioError, match="text must be YAML text .a str., got dict; to build a Scenario"):
        load_yaml_typed(Scenario, text={"name": "x"})


def test_a_table_that_is_a_directory_names_the_field(tmp_path):
    (tmp_path / "t.csv").mkdir()
    path = _vehicle(tmp_path, "    model: polynomial          # constant coefficients (one term each): the trimmed "
                    "capsule\n    CL: [[0.40815]]\n    CD: [[1.2569]]", "    model: table\n    table_csv: t.csv")
    with pytest.raises(ScenarioError, match=r"aero.trim: table_csv = '.*/t.csv' is a directory; give a CSV file"):
        load_vehicle(path)


# -- run arguments: checked before planning, nothing written ---------------------------------
@pytest.mark.parametrize("change, needle", [
    ({"runs": 0}, "runs = 0 is out of range; allowed: an integer in [1, 10000000]"),
    ({"runs": -1}, "runs = -1 is out of range"),
    ({"runs": 2.5}, "runs = 2.5 is not an integer"),
    ({"seed": "x"}, "seed = 'x' is not an integer; allowed: an integer in [0, "),
    ({"seed": -3}, "seed = -3 is out of range"),
    ({"trajectory_step_s": float("nan")}, "trajectory_step_s = nan is out of range; allowed: >= 0 s"),
    ({"workers": 0}, "workers = 0 is out of range; allowed: an integer in [1, 4096]"),
    ({"only": "bp"}, "only = 'bp': give a list of labels, e.g. only=['bp']"),
    ({"only": ["nope"]}, "only: nope not in comparison t; allowed: bp"),
    ({"out_dir": "FILE/sub"}, "out_dir {tmp}/FILE/sub: {tmp}/FILE is a file, not a directory; choose another out_dir"),
    ({"out_dir": 3}, "out_dir must be a directory path (text); got int"),
])
def test_run_comparison_refuses_bad_arguments_before_planning_and_writes_nothing(tmp_path, no_planning, change,
                                                                                 needle):
    """runs=-1 and seed='x' were refused after 19.6 s of planning, leaving scenarios/ behind;
    an out_dir below a file raised NotADirectoryError; only='bp' listed its letters."""
    (tmp_path / "FILE").write_text("x")
    args = {"runs": 1, "seed": 0, "out_dir": str(tmp_path / "o"), "workers": 1, "progress": False}
    args.update({k: (str(tmp_path / v) if k == "out_dir" and isinstance(v, str) else v) for k, v in change.items()})
    before = _files(tmp_path)
    with pytest.raises(ScenarioError) as raised:
        run_comparison(_comparison(), **args)
    assert needle.format(tmp=tmp_path) in str(raised.value) and "\n" not in str(raised.value), str(raised.value)
    assert _files(tmp_path) == before


def test_the_cli_refuses_runs_0_before_planning_and_writes_nothing(tmp_path, no_planning, capsys):
    (tmp_path / "c.yaml").write_text("name: t\nmission: horus2b\nmethods:\n  - {label: bp, method: BankProfile}\n")
    assert main(["compare", str(tmp_path / "c.yaml"), "--runs", "0", "--out", str(tmp_path / "o")]) == 2
    assert "runs = 0 is out of range" in capsys.readouterr().err and not (tmp_path / "o").exists()


# -- comparison files: labels, tags and names that agree --------------------------------------
@pytest.mark.parametrize("comparison, needle", [
    (_comparison(name="../../escape"), "name = '../../escape': allowed: 1-80 letters"),
    (_comparison(name="/tmp/abs"), "name = '/tmp/abs'"),
    (_comparison(name=""), "name = ''"),
    (_comparison(label="scenarios"), "label = 'scenarios' is the comparison directory's own folder"),
    (_comparison(label="fnpeg"), "label = 'fnpeg' names !Fnpeg but method is BankProfile"),
    (Comparison(name="t", mission="horus2b", methods=[ComparedMethod(
        label="drag_energy", method="DragEnergy", overrides={"guidance": "!BankProfile {bank_start_deg: 60.0}"})]),
     "overrides.guidance is !BankProfile but method is DragEnergy"),
])
def test_a_comparison_whose_names_or_tags_disagree_is_refused(comparison, needle):
    """A DragEnergy entry overriding its guidance with !BankProfile flew the bank profile under
    the drag-energy label; a name with '..' or an absolute path wrote outside out/compare/."""
    with pytest.raises(ScenarioError) as raised:
        comparison.validate()
    assert needle in str(raised.value), str(raised.value)


def test_a_comparison_file_error_names_the_file(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("name: t\nmission: horus2b\nmethods:\n  - {label: scenarios, method: BankProfile}\n")
    with pytest.raises(ScenarioError, match=f"comparison '{path}': methods.0..label = 'scenarios'"):
        load_comparison(str(path))


def test_a_mission_alone_is_named_inside_its_directory(tmp_path):
    from drake_entry.comparison.spec import mission_comparison

    path = tmp_path / "s.yaml"
    path.write_text("based_on: horus2b\nname: ../my mission\n")
    assert mission_comparison(str(path)).name == "my_mission"


# -- comparison directories: an identity, a refused resume changes nothing ----------------------
def _held(tmp_path, comp: Comparison, seed: int = 0) -> Path:
    """A comparison directory that holds ``comp`` (its manifest and a scenario file)."""
    out = tmp_path / "o"
    (out / "scenarios").mkdir(parents=True)
    (out / "scenarios" / "bp.yaml").write_text("held\n")
    identity = comparison_identity(comp, load_scenario(comp.mission))
    (out / "comparison.json").write_text(json.dumps({"comparison": comp.name, "seed": seed, "identity": identity,
                                                     "methods": {}}))
    return out


@pytest.mark.parametrize("other, needle", [
    (_comparison(mission="horus2b_flight"), "holds comparison 't' of other content"),
    (Comparison(name="t", mission="horus2b", methods=[ComparedMethod(
        label="bp", method="BankProfile", guidance=BankProfile(terminal_altitude_km=26.5, bank_start_deg=60.0,
                                                               bank_end_deg=50.0))]), "of other content"),
])
def test_a_directory_of_another_comparison_is_refused_and_left_as_it_was(tmp_path, no_planning, other, needle):
    """The same name with another mission shared the directory (and its report said every
    method shared the mission); the refused resume had rewritten scenarios/<label>.yaml."""
    out = _held(tmp_path, _comparison())
    before = _files(tmp_path)
    with pytest.raises(ScenarioError, match=needle):
        run_comparison(other, runs=1, out_dir=str(out), workers=1, progress=False)
    assert _files(tmp_path) == before and (out / "scenarios" / "bp.yaml").read_text() == "held\n"


def test_the_same_comparison_is_recognised_by_content_not_by_name_or_place(tmp_path):
    comp = _comparison()
    out = _held(tmp_path, comp)
    renamed = _comparison(name="another_name")
    assert check_comparison_dir(str(out), renamed.name, comparison_identity(renamed, load_scenario("horus2b")), 0)
    with pytest.raises(ScenarioError, match="with seed 0"):
        check_comparison_dir(str(out), comp.name, comparison_identity(comp, load_scenario("horus2b")), 1)


@pytest.mark.parametrize("held, needle", [({"campaign.json": "{}"}, "holds a campaign (campaign.json), not a comparison"),
                                          ({"notes.txt": "mine"}, "is not empty and holds no comparison"),
                                          ({"comparison.json": "{not json"}, "is not a comparison manifest (not JSON")])
def test_a_directory_holding_something_else_is_refused(tmp_path, no_planning, held, needle):
    """compare --out into a campaign directory replaced its report."""
    out = tmp_path / "o"
    out.mkdir()
    for name, text in held.items():
        (out / name).write_text(text)
    before = _files(tmp_path)
    with pytest.raises((ScenarioError, Exception)) as raised:
        run_comparison(_comparison(), runs=1, out_dir=str(out), workers=1, progress=False)
    assert needle in str(raised.value) and "\n" not in str(raised.value), str(raised.value)
    assert _files(tmp_path) == before


# -- nothing to fly, nothing to report ---------------------------------------------------------
def test_a_comparison_with_nothing_to_fly_is_refused(tmp_path, no_planning, capsys):
    (tmp_path / "c.yaml").write_text("name: t\nmission: horus2b\nmethods:\n"
                                     "  - {label: ampi, method: Ampi, not_flown: no database}\n")
    assert main(["compare", str(tmp_path / "c.yaml"), "--runs", "1", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "comparison t has nothing to fly: every method it lists is not_flown (ampi: no database)" in err
    assert not (tmp_path / "o").exists()
    with pytest.raises(ScenarioError, match="only: ampi: nothing to fly"):
        run_comparison(Comparison(name="t", mission="horus2b", methods=[
            ComparedMethod(label="ampi", method="Ampi", not_flown="no database"),
            ComparedMethod(label="bp", method="BankProfile", guidance=BANK)]),
            runs=1, out_dir=str(tmp_path / "o"), only=["ampi"], progress=False)


@pytest.mark.parametrize("row, problem", [
    ({"index": 0, "success": True}, "seed (missing), message (missing), reached_terminal (missing)"),
    ({"index": 0, "seed": 1, "success": "yes", "message": ""}, "success = 'yes' (want true or false)"),
    ({"index": 0, "seed": 1, "success": True, "message": "", "reached_terminal": True, "inside_box": False,
      "within_limits": True, "err_distance_m": 10.0, "flight_time_s": 1.0}, "inside_box = False (want true)"),
    ({"index": 0, "seed": 1, "success": True, "message": "", "reached_terminal": True, "inside_box": True,
      "within_limits": True, "err_distance_m": float("nan"), "flight_time_s": 1.0}, "err_distance_m = nan"),
    ({"index": -1, "seed": 1, "success": False, "message": "x"}, "index = -1"),
])
def test_a_row_is_a_campaign_row_only_with_its_verdict(row, problem):
    assert problem in row_problem(row)


def test_a_failed_sample_row_meets_the_schema():
    from drake_entry.campaign.backends import failed_row

    assert row_problem(failed_row({"index": 3, "seed": 9}, "worker set-up failed")) == ""
    # the rows of flown samples: tests/test_method_campaigns.py


def test_report_of_a_bare_row_is_refused_in_one_line(tmp_path, capsys):
    """It said '1 successful' of a row holding nothing but index and success."""
    out = tmp_path / "o"
    out.mkdir()
    (out / "samples.jsonl").write_text('{"index": 0, "success": true}\n')
    assert main(["report", str(out)]) == 2
    err = capsys.readouterr().err
    assert "none of its 1 row(s) is a campaign row (index 0: seed (missing)" in err and "nothing to report" in err
    assert sorted(os.listdir(out)) == ["samples.jsonl"]


def test_a_scenario_changed_in_python_is_held_to_the_same_numbers():
    s = load_scenario("horus2b")
    s.entry.velocity_m_s = float("nan")
    with pytest.raises(ScenarioError, match=r"^entry.velocity_m_s = nan is not a finite number$"):
        s.validate()
