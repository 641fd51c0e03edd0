import math

import numpy as np
import pytest

from drake_entry.errors import ScenarioError
from drake_entry.models.vehicles import PACKAGED_VEHICLES, load_vehicle
from drake_entry.scenario import PACKAGED_SCENARIOS, load_scenario


@pytest.mark.parametrize("name", PACKAGED_VEHICLES)
def test_packaged_vehicles_load_with_positive_properties(name):
    v = load_vehicle(name)
    assert v.mass > 0 and v.reference_area > 0 and v.nose_radius > 0
    cl, cd = v.aero.coefficients(np.radians(20.0), 8.0)
    assert cd > 0


def test_horus2b_is_paper000_table1():
    v = load_vehicle("horus2b")
    assert (v.mass, v.reference_area, v.nose_radius) == (26029.0, 110.0, 0.8)
    assert v.limits.heat_flux_max == 530e3 and v.limits.normal_load_max == 2.5
    assert v.limits.dynamic_pressure_max == 1e4
    assert not v.representative
    assert load_vehicle("shefex3").representative and load_vehicle("sphynx").representative


def test_user_vehicle_yaml_with_polynomial_aero(tmp_path):
    f = tmp_path / "v.yaml"
    f.write_text("name: my\nmass_kg: 500\nreference_area_m2: 2\nnose_radius_m: 0.3\n"
                 "aero:\n  poly: {model: polynomial, alpha_unit: deg, CL: [[0.0, 0.0], [0.03, 0.1]], "
                 "CD: [[0.05, 0.2], [0.0, 0.0], [0.0005, 0.0]]}\n")
    v = load_vehicle(str(f))
    cl, cd = v.aero.coefficients(np.radians(10.0), 5.0)
    assert cl == pytest.approx(0.3 + 0.1 * 10 / 5)
    assert cd == pytest.approx(0.05 + 0.2 / 5 + 0.05)


@pytest.mark.parametrize("cl, needle", [("[[]]", "PolynomialAero.CL = [[]] must be a non-empty rectangular"),
                                        ("[[.nan]]", "aero.poly.CL[0][0] = nan is not a finite number"),
                                        ("[[0.0], [0.03, 1.0]]", "rectangular"),
                                        ("[[0.0], [.inf]]", "aero.poly.CL[1][0] = inf is not a finite number")])
def test_an_empty_ragged_or_non_finite_polynomial_is_refused_naming_the_entry(tmp_path, cl, needle):
    """CL: [[]] flew with zero lift and a NaN coefficient reached the solvers before (a
    non-finite number is now refused by the loader, typed_yaml.check_numbers)."""
    f = tmp_path / "v.yaml"
    f.write_text("name: my\nmass_kg: 500\nreference_area_m2: 2\nnose_radius_m: 0.3\n"
                 f"aero:\n  poly: {{model: polynomial, CL: {cl}, CD: [[0.05]]}}\n")
    with pytest.raises(ScenarioError, match="aero.poly") as raised:
        load_vehicle(str(f))
    assert needle in str(raised.value) and "\n" not in str(raised.value)


def test_negative_mass_names_the_field_and_range(tmp_path):
    f = tmp_path / "v.yaml"
    f.write_text("name: bad\nmass_kg: -5\nreference_area_m2: 1\nnose_radius_m: 1\naero: {a: {model: cav_h}}\n")
    with pytest.raises(ScenarioError, match=r"mass_kg = -5.0 is out of range; allowed: \(0, 1e\+06\] kg"):
        load_vehicle(str(f))


def test_an_alpha_actuator_limit_is_optional_and_a_bad_one_names_its_field(tmp_path):
    """SHEFEX-3's file states paper 003 Table 2's alpha actuator (5 deg/s, 4 deg/s^2); a vehicle
    stating none has None; zero is refused naming the field."""
    v = load_vehicle("shefex3")
    assert (math.degrees(v.alpha_rate_limit), math.degrees(v.alpha_accel_limit)) == pytest.approx((5.0, 4.0))
    assert load_vehicle("horus2b").alpha_rate_limit is None
    f = tmp_path / "v.yaml"
    f.write_text("name: bad\nmass_kg: 5\nreference_area_m2: 1\nnose_radius_m: 1\naero: {a: {model: cav_h}}\n"
                 "alpha_rate_limit_deg_s: 0\n")
    with pytest.raises(ScenarioError, match=r"alpha_rate_limit_deg_s = 0(\.0)? is out of range: must be > 0"):
        load_vehicle(str(f))


@pytest.mark.parametrize("name", PACKAGED_SCENARIOS)
def test_packaged_scenarios_validate(name):
    """Each packaged scenario loads, validates, and survives the round trip a campaign manifest
    makes (Drake's yaml_dump_typed, then load: the same text again); its mission is physical:
    the entry interface lies above the terminal altitude with more specific energy than the
    guidance's terminal interface (closed-loop scenarios), and the target is a point on Earth."""
    from pydrake.common.yaml import yaml_dump_typed

    from drake_entry.scenario import Scenario, closed_loop_scenarios
    from drake_entry.typed_yaml import load_yaml_typed

    s = load_scenario(name)
    dumped = yaml_dump_typed(s)
    assert yaml_dump_typed(load_yaml_typed(Scenario, text=dumped, where=name).validate()) == dumped
    x0 = s.initial_state()
    assert x0.shape == (6,) and np.all(np.isfinite(x0))
    assert -90.0 <= s.target.latitude_deg <= 90.0 and -360.0 <= s.target.longitude_deg <= 360.0
    if s.terminal.altitude_km is not None:
        assert s.entry.altitude_km > s.terminal.altitude_km
    if name in closed_loop_scenarios():
        h_f, V_f, E_f = s.guidance_terminal_state()
        assert x0[0] > h_f and x0[3] > V_f and s.entry_energy() > E_f


def test_horus_scenario_is_paper000_table1():
    x0 = load_scenario("horus2b").initial_state()
    assert np.allclose(x0, [122e3, np.radians(-106.7), np.radians(-22.3), 7435.5, np.radians(-1.43),
                            np.radians(70.75)])


def _write(tmp_path, text):
    f = tmp_path / "s.yaml"
    f.write_text(text)
    return str(f)


def test_misspelled_field_is_one_clear_line(tmp_path):
    p = _write(tmp_path, "name: x\nvehicle: horus2b\nentry: {altitude_km: 120, velocty_m_s: 7000}\n")
    with pytest.raises(ScenarioError, match=r"s\.yaml: entry\.velocty_m_s: unknown field; did you mean velocity_m_s\?$"):
        load_scenario(p)


def test_altitude_outside_model_range(tmp_path):
    p = _write(tmp_path, "name: x\nvehicle: horus2b\nentry: {altitude_km: 1500, velocity_m_s: 7000}\n"
                         "terminal: {altitude_km: 25}\n")
    with pytest.raises(ScenarioError, match=r"entry.altitude_km = 1500.0 is out of range; allowed \[-5, 1000\]"):
        load_scenario(p)


def test_missing_file():
    with pytest.raises(ScenarioError, match="neither a packaged scenario"):
        load_scenario("/nope/missing.yaml")


def test_paper000_table2_dispersion_is_reproducible_bounded_and_uniform():
    from pydrake.common import RandomGenerator

    from drake_entry.models.dispersions import DispersionSpec, draw

    spec = DispersionSpec.paper000_table2()
    half = np.array([250.0, np.radians(0.1), np.radians(0.1), 15.0, np.radians(0.01), np.radians(0.01)])
    draws = np.array([draw(spec, RandomGenerator(i)).entry_delta for i in range(2000)])
    assert np.array_equal(draws[17], draw(spec, RandomGenerator(17)).entry_delta)
    assert np.all(np.abs(draws) <= half)
    # uniform on [-a, a]: standard deviation a / sqrt(3)
    assert np.allclose(draws.std(axis=0) / (half / np.sqrt(3)), 1.0, atol=0.05)
    assert load_scenario("horus2b").dispersions.entry.altitude_m.max == 250.0


def test_closed_loop_step_must_divide_the_guidance_period(tmp_path):
    p = _write(tmp_path, "name: x\nvehicle: horus2b\nentry: {altitude_km: 120, velocity_m_s: 7000}\n"
                         "terminal: {altitude_km: 25}\nsimulation: {closed_loop_step_s: 0.3}\n")
    with pytest.raises(ScenarioError, match=r"simulation.closed_loop_step_s = 0.3 s must be 0 \(error control\) "
                                            r"or divide guidance.period_s = 1 s"):
        load_scenario(p)


def test_closed_loop_runs_fixed_steps_and_open_loop_keeps_error_control():
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.primitives import ConstantVectorSource

    from drake_entry.diagrams.common import make_simulator

    sc = load_scenario("horus2b")
    builder = DiagramBuilder()
    builder.AddSystem(ConstantVectorSource([1.0]))
    diagram = builder.Build()
    closed = make_simulator(diagram, sc, closed_loop=True).get_integrator()
    assert closed.get_fixed_step_mode() and closed.get_maximum_step_size() == sc.simulation.closed_loop_step_s == 0.5
    opened = make_simulator(diagram, sc).get_integrator()
    assert not opened.get_fixed_step_mode() and opened.get_target_accuracy() == sc.simulation.accuracy


@pytest.mark.parametrize("name, old, new", [("capsule_lu2008", "corrector_period_s", "replan_period_s"),
                                            ("cav_h_paper004", "resolve_until_e", "replan_until_e"),
                                            ("cav_h_paper004", "resolve_scaling", "acceleration_scaling")])
def test_a_campaign_stored_before_the_replan_renames_reports_its_scenario(name, old, new):
    """A manifest written with a guidance field's old name (before one re-plan concept) is read
    with today's name: the report keeps the flown scenario instead of losing it."""
    from pydrake.common.yaml import yaml_dump_typed

    from drake_entry.campaign.report import flown_scenario

    scenario = load_scenario(name)
    stored = yaml_dump_typed(scenario).replace(f"{new}:", f"{old}:")
    assert f"  {old}:" in stored
    flown = flown_scenario({"scenario_yaml": stored})
    assert flown is not None and getattr(flown.guidance, new) == getattr(scenario.guidance, new)


def test_a_flight_twin_is_its_paper_scenario_plus_the_flight_environment():
    """Every closed-loop NAME has NAME_flight: the same mission and method settings (but the
    stated latency), the paper's dispersions kept, every flight-like model added."""
    import dataclasses as dc

    from pydrake.common.yaml import yaml_dump_typed

    from drake_entry.scenario import closed_loop_scenarios

    names = closed_loop_scenarios()
    for name in [n for n in names if not n.endswith("_flight")]:
        assert f"{name}_flight" in names
        paper, twin = load_scenario(name), load_scenario(f"{name}_flight")
        assert twin.based_on == name and twin.name == f"{name}_flight"
        assert (twin.vehicle, twin.aero, twin.vehicle_limits) == (paper.vehicle, paper.aero, paper.vehicle_limits)
        for field in ("entry", "target", "terminal", "alpha", "planet", "atmosphere", "simulation"):
            assert yaml_dump_typed(getattr(twin, field)) == yaml_dump_typed(getattr(paper, field)), (name, field)
        guidance = dc.replace(twin.guidance, replan_latency_s=getattr(paper.guidance, "replan_latency_s", 0.0)) \
            if hasattr(paper.guidance, "replan_latency_s") else twin.guidance
        assert yaml_dump_typed(guidance) == yaml_dump_typed(paper.guidance), name
        assert yaml_dump_typed(twin.dispersions.entry) == yaml_dump_typed(paper.dispersions.entry)
        d = twin.dispersions
        assert None not in (d.aero_regimes, d.atmosphere_perturbations, d.winds, d.inertial_navigation), name


def test_based_on_resolves_relative_to_the_file_and_refuses_loops_and_untagged_method_blocks(tmp_path):
    (tmp_path / "a.yaml").write_text("based_on: horus2b\nname: a\nguidance: !DragEnergy\n  replan_period_s: 40.0\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "b.yaml").write_text("based_on: ../a.yaml\nname: b\n")
    b = load_scenario(str(tmp_path / "sub" / "b.yaml"))
    assert b.name == "b" and b.guidance.replan_period_s == 40.0 and b.guidance.terminal_altitude_km == 26.5
    (tmp_path / "c.yaml").write_text("based_on: d.yaml\nname: c\n")
    (tmp_path / "d.yaml").write_text("based_on: c.yaml\nname: d\n")
    with pytest.raises(ScenarioError, match="based_on makes a loop"):
        load_scenario(str(tmp_path / "c.yaml"))
    (tmp_path / "e.yaml").write_text("based_on: capsule_lu2008\nname: e\nguidance:\n  period_s: 2.0\n")
    with pytest.raises(ScenarioError, match=r"guidance: write the tag of the block it changes \(the base "
                                            r"'capsule_lu2008' has !Fnpeg\)"):
        load_scenario(str(tmp_path / "e.yaml"))
