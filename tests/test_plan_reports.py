"""``drake-entry plan`` for the SCvx (paper 001) and database (paper 003) guidance: the plan the
guidance would fly, its controls flown by the Drake Simulator, checked against the papers' own
boxes and limits (not against the planner's own verdict)."""
import dataclasses as dc
import json

import pytest
from pydrake.common.yaml import yaml_dump_typed

from drake_entry.cli import main
from drake_entry.scenario import Scenario, load_scenario


def test_scvx_plan_report_flies_into_paper001_drs_box(tmp_path, capsys):
    """The pre-flight plan of sphynx_paper001, flown: its DRS point is inside paper 001's box
    (eq. 64: geodetic altitude 10-13 km; eq. 65: Mach 0.1-1.0; eq. 66: descending) and within the
    scenario's 15 km of the Azores site, and the exit code says so."""
    out = tmp_path / "plan"
    code = main(["plan", "sphynx_paper001", "--out", str(out)])
    s = json.loads((out / "plan.json").read_text())
    assert code == 0 and s["success"], capsys.readouterr().err
    drs = s["flown_drs"]
    assert 10e3 <= drs["altitude_m"] <= 13e3 and 0.1 <= drs["mach"] <= 1.0 and drs["vertical_speed_m_s"] < 0.0
    assert s["flown_from_site_m"] <= 15e3 and s["flown_within_limits"] and s["flown_drs_box_met"]
    assert s["max_defect"] <= 1e-6
    assert {p.name for p in out.iterdir()} >= {"scvx_entry.png", "heat_flux.png", "groundtrack.png"}
    assert "paper 001 Table 6 form" in capsys.readouterr().out


def _shefex3(tmp_path, **terminal):
    s = load_scenario("shefex3_ampi")
    path = tmp_path / "shefex3.yaml"
    path.write_text(yaml_dump_typed(dc.replace(s, terminal=dc.replace(s.terminal, **terminal)), schema=Scenario))
    return str(path)


def test_ampi_plan_report_flies_the_reference_inside_paper003_limits(tmp_path, capsys):
    """The database reference for the nominal entry, flown open loop from the LD nodes: inside
    Table 1's terminal altitude window (21-26 km geodetic) and within the scenario's 25 km of the
    target, under eq. 3's limits (50 kPa, 6.5 MW/m^2, 10 g); the 729 cases verified."""
    out = tmp_path / "plan"
    assert main(["plan", "shefex3_ampi", "--out", str(out)]) == 0, capsys.readouterr().err
    s = json.loads((out / "plan.json").read_text())
    assert s["database_ok"] and s["database"].startswith("729/729 cases verified")
    assert 21e3 <= s["flown_geodetic_altitude_m"] <= 26e3 and s["flown"]["miss_m"] <= 25e3
    peaks = s["path_peaks"]
    assert peaks["dynamic_pressure"]["peak"] <= 50e3 and peaks["heat_flux"]["peak"] <= 6.5e6
    assert peaks["normal_load"]["peak"] <= 10.0
    assert s["inside_box"] is True and s["within_limits"] is True
    # a tighter acceptance box than the reconstruction reaches (5.7 km measured) fails the plan
    assert main(["plan", _shefex3(tmp_path, distance_tolerance_km=1.0), "--out", str(tmp_path / "tight")]) == 1
    assert "the reference is not verified" in capsys.readouterr().err
    assert json.loads((tmp_path / "tight" / "plan.json").read_text())["inside_box"] is False



@pytest.mark.slow
def test_lgl_terminal_plan_report_refuses_an_under_resolved_plan_with_its_figures(tmp_path, capsys):
    """paper 002's pre-flight plan on 40 LGL nodes (marv_guidance has 80) without mesh refinement
    (refine_mesh false): SNOPT converges but the
    dynamics between the nodes miss by more than the 1e-3 tolerance, so the plan is not a success,
    is not flown through the actuators, and the report says so by its exit code, its words and
    plan.json (the figures still show the solution against its Drake propagation)."""
    s = load_scenario("marv_guidance")
    path = tmp_path / "marv40.yaml"
    path.write_text(yaml_dump_typed(dc.replace(s, guidance=dc.replace(s.guidance, nodes=40, refine_mesh=False)), schema=Scenario))
    out = tmp_path / "plan"
    code = main(["plan", str(path), "--out", str(out)])
    summary = json.loads((out / "plan.json").read_text())
    err = capsys.readouterr().err
    assert code == 1 and not summary["success"] and "converged but inaccurate" in err
    v = summary["verification"]
    assert not v["verified"] and v["dynamics_error"] > v["dynamics_tolerance"] == 1e-3
    assert "actuator_flight" not in summary and summary["nodes"] == 40
    assert (out / "fig01_altitude.png").exists()
