"""Settings a method derives from a mission (drake_entry.guidance.derivation) and the search that
chooses its free ones by flying (drake_entry.comparison.derive)."""
import dataclasses as dc
import math

import numpy as np
import pytest

from drake_entry.comparison.derive import GOOD_ENOUGH, Flight, Trial, apply_derivation, derive_settings
from drake_entry.comparison.spec import (
    PACKAGED_COMPARISONS,
    Comparison,
    load_comparison_or_mission,
    mission_comparison,
)
from drake_entry.errors import ScenarioError
from drake_entry.guidance import REGISTRY, folder_of
from drake_entry.guidance.derivation import (
    CannotFly,
    Derivation,
    SearchStep,
    alpha_rewritten,
    derivation_for,
    interface_altitudes,
    terminal_interface,
)
from drake_entry.scenario import PACKAGED_SCENARIOS, load_scenario, stated_guidance


@pytest.mark.parametrize("mission", PACKAGED_SCENARIOS)
def test_every_method_derives_settings_that_fit_the_mission_or_says_why_not(mission):
    """On every packaged mission each registered method gives settings the mission accepts (its own
    method: the mission's block as it is), every search candidate accepted too, or one line
    saying why it cannot fly it."""
    scenario = load_scenario(mission)
    flyable = 0
    for spec in REGISTRY:
        try:
            d = derivation_for(scenario, spec)
        except CannotFly as e:
            assert "\n" not in str(e) and len(str(e)) > 40, (spec.__name__, str(e))
            continue
        flyable += 1
        assert type(d.spec) is spec
        flown = apply_derivation(scenario, d)
        assert type(flown.guidance) is spec and flown.vehicle == scenario.vehicle and flown.entry == scenario.entry
        if type(stated_guidance(scenario)) is spec:
            assert d.spec == scenario.guidance and not d.search
        for step in d.search:
            assert step.candidates and all(isinstance(c, dict) and c for c in step.candidates), step.name
            for candidate in step.candidates:
                apply_derivation(scenario, d, candidate)  # validates
    assert flyable >= 1


def test_a_mission_without_a_guidance_block_states_no_method():
    """A mission file without a guidance block gets the first method's defaults, which state
    nothing: every method, that one included, derives its settings (closed_loop_scenarios agrees)."""
    from drake_entry.guidance.drag_energy.spec import DragEnergy
    from drake_entry.scenario import closed_loop_scenarios

    for name in PACKAGED_SCENARIOS:
        assert (stated_guidance(load_scenario(name)) is not None) == (name in closed_loop_scenarios()), name
    cav_h = load_scenario("cav_h")  # open loop: no guidance block
    assert stated_guidance(cav_h) is None and derivation_for(cav_h, DragEnergy).search


def test_drag_energy_re_plans_in_the_sensed_air_where_the_mission_disperses_the_forces():
    """replan_model_scales follows the mission's dispersions: paper 004's CAV-H disperses the
    density, lift and drag (its re-plans take the sensed vehicle's corridor), HORUS-2B only the
    entry state (the nominal corridor is the flight's)."""
    from drake_entry.guidance.drag_energy.spec import DragEnergy

    assert derivation_for(load_scenario("cav_h_paper004"), DragEnergy).spec.replan_model_scales
    assert not derivation_for(load_scenario("horus2b"), DragEnergy).spec.replan_model_scales


def test_drag_energy_re_plans_from_its_reference_kept_off_the_corridor_bounds_with_a_wider_reversal_corridor():
    """The derived drag-energy guidance re-plans from the reference (not paper 000's flown drag),
    keeps its profile off the corridor's bounds (weight 1000, then 0 searched) and tries its
    reversal corridor widened at the upper speed first, then the mission's own (Lu 2014's CAV-H:
    FNPEG's 3-15 deg tried as 3-25 first)."""
    from drake_entry.guidance.drag_energy.derive import CENTRING_CANDIDATES
    from drake_entry.guidance.drag_energy.spec import DragEnergy

    d = derivation_for(load_scenario("cav_h_fnpeg"), DragEnergy)
    assert d.spec.replan_start == "reference" and d.spec.corridor_centring == 1000.0
    steps = {s.name: s for s in d.search}
    assert [c["guidance.corridor_centring"] for c in steps["guidance.corridor_centring"].candidates] == list(
        CENTRING_CANDIDATES) == [1000.0, 0.0]
    corridors = [c["guidance.reversal_heading_deg"] for c in steps["guidance.reversal_heading_deg"].candidates]
    assert corridors == [[3.0, 25.0], [3.0, 15.0]] and d.spec.reversal_heading_deg == [3.0, 25.0]


def test_derivation_is_deterministic():
    scenario = load_scenario("horus2b")
    for spec in REGISTRY:
        try:
            a, b = derivation_for(scenario, spec), derivation_for(load_scenario("horus2b"), spec)
        except CannotFly:
            continue
        assert a == b, spec.__name__


def test_fnpeg_on_horus2b_takes_the_box_centre_the_limits_and_the_alpha_ramp():
    from drake_entry.guidance.fnpeg.derive import LIMIT_MARGINS
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    scenario = load_scenario("horus2b")
    d = derivation_for(scenario, Fnpeg)
    a25 = float(scenario.make_atmosphere().speed_of_sound(25e3))
    assert d.spec.terminal_altitude_km == 25.0 and d.spec.terminal_velocity_m_s == pytest.approx(2.5 * a25, abs=1e-3)
    assert (d.spec.heat_rate_limit_kW_m2, d.spec.load_limit_g, d.spec.dynamic_pressure_limit_kPa) == pytest.approx(
        (LIMIT_MARGINS[0] * 530.0, LIMIT_MARGINS[0] * 2.5, LIMIT_MARGINS[0] * 10.0))
    assert d.spec.alpha_deg == [15.0, 40.0] and d.spec.reversal_heading_deg == [5.0, 15.0]
    # sigma_f (which sets the altitude at e_f) is flown over its whole grid, then the margin re-checked at it
    assert [s.name for s in d.search] == ["limit margin", "guidance.bank_end_deg", "limit margin at that sigma_f",
                                         "guidance.engage_acceleration_m_s2", "guidance.final_range_km"]
    assert [s.exhaustive for s in d.search] == [False, True, False, False, False]
    assert d.search[2].candidates == d.search[0].candidates
    # s_f* measured from the nominal flight's overshoot (28.5 km past: aim 28.5 km short), then 0
    final = d.search[4]
    assert final.calibrate({"err_range_m": -28_460.0}) == {"guidance.final_range_km": 28.5}
    assert final.calibrate({"err_range_m": 3_000.0}) == {"guidance.final_range_km": 0.0}
    assert final.candidates == ({"guidance.final_range_km": 0.0},)
    sigma_f = [c["guidance.bank_end_deg"] for c in d.search[1].candidates]
    assert sigma_f[0] == d.spec.bank_end_deg == 45.0 and sorted(sigma_f) == [20.0 + 5.0 * i for i in range(11)]
    assert interface_altitudes(scenario, terminal_interface(scenario)) == (25.0, 25.5, 26.0, 26.5, 24.5, 24.0)


def test_the_alpha_ramp_rewritten_in_speed_is_where_the_flight_meets_it():
    """HORUS-2B's alpha ramp is in normalised energy; rewritten in speed (altitude linear in energy)
    its ends are within 3 % of the speeds at which the drag-energy nominal flight reaches those
    energies (the approximation's altitude error moves a speed by g dh / V)."""
    from drake_entry.diagrams.closed_loop import fly

    scenario = load_scenario("horus2b")
    interface = terminal_interface(dc.replace(scenario, terminal=dc.replace(scenario.terminal, altitude_km=26.5)))
    speeds, values, how = alpha_rewritten(dc.replace(scenario, terminal=dc.replace(scenario.terminal, altitude_km=26.5)),
                                          interface, "velocity")
    assert values == [15.0, 40.0] and "rewritten in velocity" in how
    tr = fly(scenario).trajectory  # the drag-energy guidance aims at 26.5 km, Mach 2.5: E_f as above
    planet = scenario.make_planet().with_(j2=0.0)
    x0 = scenario.initial_state()
    E0 = float(planet.specific_energy(x0[0], x0[3]))
    Ef = float(planet.specific_energy(26.5e3, interface.speed_m_s))
    e = (E0 - np.array([float(planet.specific_energy(h, V)) for h, V in zip(tr.state[:, 0], tr.state[:, 3])])) / (E0 - Ef)
    flown = [float(np.interp(b, e, tr.state[:, 3])) for b in (0.98, 0.87)]  # breakpoints of 15 and 40 deg
    assert speeds == pytest.approx(flown, rel=0.03)


def test_a_constant_alpha_and_one_in_time():
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    scenario = load_scenario("cav_h_paper004")  # alpha: constant 20 deg, in time
    interface = terminal_interface(scenario)
    assert alpha_rewritten(scenario, interface, "velocity")[:2] == ([0.0], [20.0])
    ramp = dc.replace(scenario, alpha=dc.replace(scenario.alpha, breakpoints=[0.0, 100.0], values_deg=[20.0, 10.0]))
    with pytest.raises(CannotFly, match="alpha schedule is in time"):
        derivation_for(ramp, Fnpeg)
    lu = load_scenario("cav_h_fnpeg")  # its own method's profile in speed is the mission's alpha
    speeds, values, how = alpha_rewritten(lu, terminal_interface(lu), "normalized_energy")
    assert values == [14.0, 10.5, 11.0] and "own method's (!Fnpeg)" in how and speeds[-1] == pytest.approx(1.0, abs=1e-9)


def test_a_geodetic_box_is_an_interface_at_the_targets_latitude():
    """Paper 001's DRS box gives its altitude geodetically (10-13 km, eq. 64): a method aims at its
    centre as the state altitude whose geodetic altitude at the target is 11.5 km, with the
    box's 1.5-km tolerance; on the ellipsoid datum the geodetic altitude is stated as it is."""
    sphynx = load_scenario("sphynx_paper001")
    interface = terminal_interface(sphynx)
    planet, lat = sphynx.make_planet(), math.radians(sphynx.target.latitude_deg)
    assert float(planet.atmospheric_altitude(interface.altitude_km * 1e3, lat)) == pytest.approx(11.5e3, abs=1e-6)
    assert 3.5 < interface.altitude_km < 4.0  # the Azores site: the local radius 7.7 km under the reference sphere's
    assert interface.altitude_tolerance_km == 1.5 and interface.mach == 0.5 and interface.mach_given
    a = float(sphynx.make_atmosphere().speed_of_sound(11.5e3))
    assert interface.speed_m_s == pytest.approx(0.5 * a)
    assert interface_altitudes(sphynx, interface)[0] == pytest.approx(interface.altitude_km)
    ellipsoid = dc.replace(sphynx, altitude_datum="ellipsoid")
    assert terminal_interface(ellipsoid).altitude_km == 11.5
    assert terminal_interface(load_scenario("horus2b")).altitude_tolerance_km == \
        load_scenario("horus2b").terminal.altitude_tolerance_km


def test_a_state_altitude_on_an_oblate_earth_reads_the_atmosphere_at_its_geodetic_altitude(monkeypatch):
    """SPHYNX states its altitudes above the reference sphere (altitude_datum 'sphere') on an
    oblate Earth, whose plant reads the atmosphere at the geodetic altitude: the guidance's
    terminal Mach 0.72 at 2.5 km (state) is a speed at the speed of sound 10.17 km up (not the
    2.5 km one, 10 % faster), and the dynamic-pressure speed is the one of the air there. On a
    spherical planet, or with geodetic altitudes, the altitude is read as it is."""
    from drake_entry.guidance.derivation import q_limit_speed

    sphynx = load_scenario("sphynx_paper001")
    planet, lat, atmosphere = sphynx.make_planet(), math.radians(sphynx.target.latitude_deg), sphynx.make_atmosphere()
    air = float(planet.atmospheric_altitude(2.5e3, lat))
    assert sphynx.air_altitude(2.5e3) == pytest.approx(air, rel=1e-12) and 10.0e3 < air < 10.3e3
    h_f, V_f, _ = sphynx.guidance_terminal_state()
    assert h_f == 2.5e3 and V_f == pytest.approx(0.72 * float(atmosphere.speed_of_sound(air)), rel=1e-12)
    assert V_f < 0.95 * 0.72 * float(atmosphere.speed_of_sound(2.5e3))
    limited = dc.replace(sphynx.make_vehicle(), limits=dc.replace(sphynx.make_vehicle().limits,
                                                                  dynamic_pressure_max=20e3))
    monkeypatch.setattr(type(sphynx), "make_vehicle", lambda self: limited)
    assert q_limit_speed(sphynx, 2.5) == pytest.approx((2 * 20e3 / float(atmosphere.density(air))) ** 0.5, rel=1e-12)
    monkeypatch.undo()
    for name in ("horus2b", "shefex3_ampi"):  # a spherical planet; geodetic altitudes
        assert load_scenario(name).air_altitude(25e3) == 25e3


def test_a_box_without_a_speed_is_aimed_at_the_speed_where_the_missions_own_method_stops():
    """SHEFEX-3's box checks altitude and distance only (paper 003's speed window is a listed
    departure): the others aim at the 620 m/s where its AMPI guidance stops, and say so; a mission
    with no speed and no method of its own that stops at one is refused with why."""
    from drake_entry.guidance.fnpeg.spec import Fnpeg
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal

    shefex = load_scenario("shefex3_ampi")
    interface = terminal_interface(shefex)
    assert interface.altitude_km == 23.5 and interface.speed_m_s == 620.0 and interface.speed_from_own_method
    assert "own method stops" in interface.speed_words and not interface.mach_given
    choices = {c.field: c.how for c in derivation_for(shefex, LglTerminal).choices}
    assert "own method stops" in choices["guidance.terminal_altitude_km, terminal_velocity_m_s"]
    with pytest.raises(CannotFly, match="alpha schedule is in time"):  # Table 2's alpha law, in time
        derivation_for(shefex, Fnpeg)
    assert not terminal_interface(load_scenario("horus2b")).speed_from_own_method
    alone = dc.replace(shefex, guidance=None)
    with pytest.raises(CannotFly, match="its own method stops at no speed"):
        terminal_interface(alone)


def test_fnpeg_on_a_skipping_entry_engages_at_a_lower_acceleration_and_reaches_a_low_interface():
    """SPHYNX's shallow entry skips: wings level its first pull-out senses at most 1.09 m/s^2, so
    at Lu 2014's 1.52 FNPEG engages only past the site and ends thousands of km from it; at half
    of Lu's value (the derivation's next candidate) it engages in the first dip and ends inside the
    DRS box at E_f, which lies at 3.83 km, below the 5-km crash floor (now half of it)."""
    from drake_entry.diagrams.closed_loop import ALTITUDE_FLOOR_M, altitude_floor, fly
    from drake_entry.guidance.fnpeg.derive import ENGAGE_ACCELERATIONS_M_S2
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    assert altitude_floor(26.5e3) == ALTITUDE_FLOOR_M and altitude_floor(3830.0) == 1915.0 and altitude_floor(0.0) == 0.0
    sphynx = load_scenario("sphynx_paper001")
    d = derivation_for(sphynx, Fnpeg)
    assert [s.candidates for s in d.search if s.name == "guidance.engage_acceleration_m_s2"] == \
        [tuple({"guidance.engage_acceleration_m_s2": a} for a in ENGAGE_ACCELERATIONS_M_S2)]
    flights = {a: fly(apply_derivation(sphynx, d, {"guidance.bank_end_deg": 20.0,
                                                   "guidance.engage_acceleration_m_s2": a}))
               for a in ENGAGE_ACCELERATIONS_M_S2[:2]}
    late, engaged = flights[1.52], flights[0.76]
    assert late.guidance.fields["engage_time_s"] > 1000.0 and late.errors["distance_m"] > 1e6 and not late.success
    assert engaged.guidance.fields["engage_time_s"] < 400.0
    assert engaged.reached and engaged.success, engaged.message
    assert engaged.errors["distance_m"] < 10e3


def test_a_method_without_a_derivation_and_a_mission_without_an_interface_are_refused_in_one_line(monkeypatch):
    import importlib

    from drake_entry.guidance.fnpeg.spec import Fnpeg

    sphynx = load_scenario("sphynx_paper001")
    no_altitude = dc.replace(sphynx, terminal=dc.replace(sphynx.terminal, geodetic_altitude_km=None,
                                                         geodetic_altitude_tolerance_km=None))
    with pytest.raises(CannotFly, match="gives neither altitude_km nor geodetic_altitude_km"):
        derivation_for(no_altitude, Fnpeg)
    real = importlib.import_module

    def missing(name, *a, **k):
        if name == "drake_entry.guidance.fnpeg.derive":
            raise ModuleNotFoundError(name=name)
        return real(name, *a, **k)

    monkeypatch.setattr(importlib, "import_module", missing)
    with pytest.raises(CannotFly, match=r"!Fnpeg derives no settings from a mission \(guidance/fnpeg/derive.py"):
        derivation_for(load_scenario("horus2b"), Fnpeg)


def test_a_trial_is_kept_by_its_successes_then_its_box_ratio():
    ok = Trial("s", {"f": 1}, [Flight("nominal", True, 0.9), Flight("0", True, 0.8)], 0.0)
    better = Trial("s", {"f": 2}, [Flight("nominal", True, 0.3), Flight("0", True, 0.4)], 0.0)
    failing = Trial("s", {"f": 3}, [Flight("nominal", False, 0.1, "x"), Flight("0", True, 0.1)], 0.0)
    assert min([failing, ok, better], key=Trial.score) is better
    assert min([failing, ok], key=Trial.score) is ok
    assert better.good_enough() and not ok.good_enough() and GOOD_ENOUGH == 0.75
    assert not Trial("s", {}, [], 0.0, "pre-flight planning failed").good_enough()


def test_an_exhaustive_step_flies_every_candidate_and_keeps_the_best(monkeypatch):
    """A graded setting is not cut short by a first good-enough candidate: of the ratios 0.7, 0.2,
    0.5 (all successes) the plain step keeps the first, the exhaustive one flies all three and
    keeps 0.2."""
    import drake_entry.comparison.derive as derive
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    ratio = {45.0: 0.7, 50.0: 0.2, 40.0: 0.5}
    monkeypatch.setattr(derive, "_fly_candidate", lambda scenario, draws: (
        [Flight("nominal", True, ratio[scenario.guidance.bank_end_deg])], "", None))
    mission = load_scenario("horus2b")
    spec = Fnpeg(terminal_altitude_km=25.0, terminal_velocity_m_s=750.0, bank_end_deg=45.0)
    for exhaustive, flown, kept in ((False, [45.0], 45.0), (True, [45.0, 50.0, 40.0], 50.0)):
        step = SearchStep.over("guidance.bank_end_deg", (45.0, 50.0, 40.0), "test", exhaustive=exhaustive)
        chosen = derive_settings(mission, Derivation(spec, [], [step]))
        assert [t.values["guidance.bank_end_deg"] for t in chosen.trials] == flown
        assert chosen.chosen == {"guidance.bank_end_deg": kept}


@pytest.mark.parametrize("first", [False, True])
def test_a_calibrated_step_tries_the_value_measured_on_the_nominal_flight_first(monkeypatch, first):
    """A fake flight whose final range to go is -2 km minus the range offset: the calibrated step
    reads -2000 m on the nominal flight of the settings chosen before (the previous step's kept
    trial, no extra flight; a nominal flown for it when it is the first step), tries it first,
    lands (box ratio 0) and keeps it; the fixed fallback 0 is not flown."""
    import drake_entry.comparison.derive as derive
    from drake_entry.guidance.drag_energy.spec import DragEnergy

    flown = []

    def fake(scenario, draws):
        miss = -2000.0 - scenario.guidance.range_offset_m
        flown.append((scenario.guidance.range_offset_m, draws))
        return [Flight("nominal", True, abs(miss) / 5000.0)], "", {"err_range_m": miss}

    monkeypatch.setattr(derive, "_fly_candidate", fake)
    spec = DragEnergy(terminal_altitude_km=26.5, terminal_mach=2.5)
    steps = [SearchStep.calibrated("guidance.range_offset_m", lambda row: row["err_range_m"], (0.0,), "test")]
    if not first:
        steps.insert(0, SearchStep.over("guidance.corridor_margin", (0.05,), "test"))
    chosen = derive_settings(load_scenario("horus2b"), Derivation(spec, [], steps))
    assert chosen.chosen["guidance.range_offset_m"] == -2000.0
    assert chosen.trials[-1].values == {"guidance.range_offset_m": -2000.0} and chosen.trials[-1].mean_ratio == 0.0
    assert flown == ([(0.0, 0)] if first else [(0.0, 2)]) + [(-2000.0, 2)]


def test_the_search_flies_its_candidates_and_keeps_the_best():
    """The worked example (no range feedback) on HORUS-2B, |sigma| at entry 20, 66 or 45 deg to 50
    deg: no profile lands in the 2-km box (the hand-tuned 66 deg ends 48 km out on the nominal,
    20 deg overflies by 4800 km), so the search keeps the smallest box ratio, records every
    flight with why it failed, and gives the same answer twice."""
    from drake_entry.guidance.bank_profile.spec import BankProfile

    mission = load_scenario("horus2b")
    spec = BankProfile(terminal_altitude_km=26.5, terminal_mach=2.5, bank_start_deg=20.0, bank_end_deg=50.0)
    d = Derivation(spec, [], [SearchStep.over("guidance.bank_start_deg", (20.0, 66.0, 45.0), "test")])
    chosen = derive_settings(mission, d, draws=1)
    assert chosen.chosen == {"guidance.bank_start_deg": 66.0}
    assert [t.values["guidance.bank_start_deg"] for t in chosen.trials] == [20.0, 66.0, 45.0]
    low, kept, middle = chosen.trials
    assert all(t.successes == 0 and len(t.flights) == 2 for t in chosen.trials)
    assert "distance error +4" in low.flights[0].why and "outside the acceptance box" in kept.flights[0].why
    assert kept.mean_ratio < middle.mean_ratio < low.mean_ratio
    assert 2.0 * 10 < kept.flights[0].box_ratio < 2.0 * 100  # 20-200 km out of a 2-km box (+10: heat flux breached)
    assert chosen.scenario.guidance.bank_start_deg == 66.0 and chosen.scenario.vehicle == mission.vehicle
    record = chosen.record()
    assert record["chosen"] == chosen.chosen and [t["successes"] for t in record["trials"]] == [0, 0, 0]
    again = derive_settings(mission, d, draws=1)
    assert [(t.values, t.mean_ratio) for t in again.trials] == [(t.values, t.mean_ratio) for t in chosen.trials]


def test_compare_takes_a_comparison_or_a_mission_alone(tmp_path):
    assert "horus2b" in PACKAGED_COMPARISONS and load_comparison_or_mission("horus2b").methods  # the packaged one
    alone = load_comparison_or_mission("horus2b_flight")
    assert alone.name == "horus2b_flight" and not alone.methods
    assert [m.label for m in alone.entries()] == [folder_of(spec) for spec in REGISTRY]
    assert not alone.not_configured() and all(not m.not_flown and m.guidance is None for m in alone.entries())
    scenario_file = tmp_path / "mine.yaml"
    scenario_file.write_text("based_on: cav_h_fnpeg\nname: mine\n")
    assert load_comparison_or_mission(str(scenario_file)).mission == str(scenario_file)
    comparison_file = tmp_path / "c.yaml"
    comparison_file.write_text(f"name: c\nmission: {scenario_file.name}\n")
    c = load_comparison_or_mission(str(comparison_file))
    assert c.name == "c" and c.mission == str(scenario_file) and not c.methods
    with pytest.raises(ScenarioError, match="'nowhere' is neither a packaged comparison .* a packaged scenario"):
        load_comparison_or_mission("nowhere")
    vehicle = tmp_path / "glider.yaml"
    vehicle.write_text("name: glider\nmass_kg: 1000.0\n")
    with pytest.raises(ScenarioError, match="neither a comparison file .* it looks like a vehicle file"):
        load_comparison_or_mission(str(vehicle))
    assert isinstance(mission_comparison("capsule_lu2008"), Comparison)


def test_the_matrix_reads_comparison_directories(tmp_path):
    """The mission x method matrix from comparison directories: the one-sided 90 % lower bound
    (20 of 20: 0.1^(1/20) = 89.1 %; 0 of n: 0), each flown cell's figures, a not-flown method's
    reason, and a directory that holds no comparison refused in one line."""
    import json

    from drake_entry.comparison.matrix import matrix_markdown, success_lower_bound, write_matrix
    from drake_entry.errors import CampaignError

    assert success_lower_bound(20, 20) == pytest.approx(0.1 ** (1 / 20), rel=1e-9)
    assert success_lower_bound(0, 10) == 0.0 and success_lower_bound(5, 10) < 0.5 < success_lower_bound(9, 10)
    folder = tmp_path / "c"
    folder.mkdir()
    (folder / "comparison.json").write_text(json.dumps({
        "comparison": "mine", "mission": "x/mine.yaml", "runs": 20, "seed": 3, "sessions": [{"git_commit": "abc"}],
        "methods": {"fnpeg": {"method": "Fnpeg", "flown": True, "derivation": {"chosen": {}}},
                    "scvx": {"method": "Scvx", "flown": False, "reason": "cannot fly this mission: no DRS window; x"}}}))
    (folder / "comparison_summary.json").write_text(json.dumps({"methods": {"fnpeg": {
        "successful": 20, "samples": 20, "miss_km": {"median": 1.5, "p95": 2.25}, "wall_time_s": {"mean": 0.8}}}}))
    text = matrix_markdown([str(folder)])
    assert "| mine (20 runs, seed 3) | **20/20** (>= 89 %), miss 1.5 / 2.25 km, 0.8 s * | not flown: no DRS window |" in text
    (folder / "scenarios").mkdir()
    (folder / "scenarios" / "fnpeg.yaml").write_text("name: mine-fnpeg\n")
    manifest = json.loads((folder / "comparison.json").read_text())
    manifest["methods"]["fnpeg"].update(scenario="scenarios/fnpeg.yaml", derivation={"chosen": {
        "guidance.bank_end_deg": 40.0}, "trials": [{"step": "guidance.bank_end_deg", "values": {
            "guidance.bank_end_deg": 40.0}, "successes": 3, "flights": 3, "mean_box_ratio": 0.5, "wall_s": 1.0,
            "setup_failure": "", "why": []}]})
    (folder / "comparison.json").write_text(json.dumps(manifest))
    path = write_matrix([str(folder)], str(tmp_path / "m.md"))
    text = open(path).read()
    assert "commit abc" in text and "| [mine](derivations/mine.md) (20 runs, seed 3) |" in text
    page = (tmp_path / "derivations" / "mine.md").read_text()  # the search that chose the settings, the scenario flown
    assert "**fnpeg**: kept guidance.bank_end_deg = 40" in page and "| bank_end_deg 40 | 3 of 3 | 0.50 |" in page
    assert "[mine/fnpeg.yaml](mine/fnpeg.yaml) (derived)" in page
    assert (tmp_path / "derivations" / "mine" / "fnpeg.yaml").read_text() == "name: mine-fnpeg\n"
    with pytest.raises(CampaignError, match="holds no comparison report"):
        matrix_markdown([str(tmp_path)])
    manifest = json.loads((folder / "comparison.json").read_text())  # an expensive method flown with fewer runs
    manifest["methods"]["scvx"] = {"method": "Scvx", "flown": True}
    (folder / "comparison.json").write_text(json.dumps(manifest))
    summary = json.loads((folder / "comparison_summary.json").read_text())
    summary["methods"]["scvx"] = {"successful": 9, "samples": 10, "miss_km": {"median": 1.0, "p95": 2.0}}
    (folder / "comparison_summary.json").write_text(json.dumps(summary))
    assert "| mine (runs per cell, seed 3) | **20/20** (>= 89 %), miss 1.5 / 2.25 km, 0.8 s * | **9/10** (>= 66 %)" \
        in matrix_markdown([str(folder)])


def test_a_matrix_rewritten_from_some_missions_keeps_the_other_rows_marked_carried(tmp_path):
    """A matrix too long to fly at once is regenerated mission by mission: rewriting the file from
    one mission's directory replaces that row in place, keeps the others (marked carried, their
    commits read from their derivation pages into the header) and adds a new mission last."""
    import json

    from drake_entry.comparison.matrix import CARRIED, read_matrix_rows, write_matrix
    from drake_entry.errors import CampaignError

    def comparison(name, commit, successes):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "comparison.json").write_text(json.dumps({
            "comparison": name, "mission": f"x/{name}.yaml", "runs": 10, "seed": 3,
            "sessions": [{"git_commit": commit}], "methods": {"fnpeg": {"method": "Fnpeg", "flown": True}}}))
        (folder / "comparison_summary.json").write_text(json.dumps({"methods": {"fnpeg": {
            "successful": successes, "samples": 10, "miss_km": {"median": 1.0, "p95": 2.0}}}}))
        return str(folder)

    out = tmp_path / "out" / "matrix.md"
    first = [comparison("a", "aaa1111", 10), comparison("b", "bbb2222", 9)]
    write_matrix(first, str(out))
    rows = read_matrix_rows(str(out))
    assert list(rows) == ["a", "b"] and rows["b"]["commits"] == ["bbb2222"]
    assert rows["b"]["cells"] == {"fnpeg": "**9/10** (>= 66 %), miss 1 / 2 km"}
    (tmp_path / "a").rename(tmp_path / "a_old")
    again = [comparison("a", "ccc3333", 7), comparison("c", "ddd4444", 10)]
    text = open(write_matrix(again, str(out))).read()
    lines = [line for line in text.splitlines() if line.startswith("| [")]
    assert [line.split("]")[0] for line in lines] == ["| [a", "| [b", "| [c"]
    assert lines[0].startswith("| [a](derivations/a.md) (10 runs, seed 3) | **7/10**")
    assert lines[1] == f"| [b](derivations/b.md) {CARRIED} (10 runs, seed 3) | **9/10** (>= 66 %), miss 1 / 2 km |"
    assert "commit bbb2222, ccc3333, ddd4444." in text and "aaa1111" not in text and "1 row carried" in text
    assert list(read_matrix_rows(str(out))) == ["a", "b", "c"]  # a carried row is read back as such
    assert "carried" not in open(write_matrix(again + [first[1]], str(out))).read().split("Each cell")[0]
    out.write_text(open(out).read().replace(" | **9/10**", " | **9/10** | x"))
    with pytest.raises(CampaignError, match="the row of b has 2 cells against 1 methods"):
        read_matrix_rows(str(out))
    assert read_matrix_rows(str(tmp_path / "none.md")) == {}


def test_a_resumed_comparison_reuses_the_derived_scenario(tmp_path, monkeypatch):
    """Derivation is deterministic for one code, so a comparison run again into its directory at
    the commit of its derivation flies the scenario the first run derived (its file and record)
    without searching again; derived at another commit (or with no commit recorded), it derives
    again."""
    from pydrake.common.yaml import yaml_dump_typed

    import drake_entry.comparison.derive as derive_module
    from drake_entry.comparison.runner import _derived_scenario
    from drake_entry.comparison.spec import ComparedMethod
    from drake_entry.guidance.fnpeg.spec import Fnpeg

    comp = mission_comparison("horus2b")
    mission = load_scenario("horus2b")
    entry = ComparedMethod(label="fnpeg", method="Fnpeg")
    flown = dc.replace(mission, guidance=Fnpeg(terminal_altitude_km=26.0, terminal_velocity_m_s=750.0,
                                               bank_end_deg=30.0))
    path = tmp_path / "fnpeg.yaml"
    path.write_text(yaml_dump_typed(flown))
    import drake_entry.campaign.engine as engine_module

    monkeypatch.setattr(engine_module, "source_commit", lambda: "c0ffee")
    record = {"choices": [], "chosen": {"guidance.bank_end_deg": 30.0}, "trials": [], "commit": "c0ffee"}

    def refuse(*a, **k):
        raise AssertionError("searched again")

    monkeypatch.setattr(derive_module, "derive_settings", refuse)
    scenario, again = _derived_scenario(comp, entry, mission, str(path), {"derivation": record}, progress=False)
    assert again == record and scenario.guidance.bank_end_deg == 30.0 and scenario.name == "horus2b-fnpeg"
    with pytest.raises(AssertionError, match="searched again"):  # no record: it derives
        _derived_scenario(comp, entry, mission, str(path), None, progress=False)
    for other in ({**record, "commit": "decade"}, {k: v for k, v in record.items() if k != "commit"}):
        with pytest.raises(AssertionError, match="searched again"):  # derived by other code: it derives
            _derived_scenario(comp, entry, mission, str(path), {"derivation": other}, progress=False)


def test_swarm_bank_on_horus2b_flies_the_mission_alpha_and_weighs_the_box():
    """Paper 004's law on another mission: its load law first, then the mission's alpha ramp
    rewritten in speed, sigma_f searched with sigma_0 before flight, eq. 32's units at
    the box tolerances (2 km, 2 km), limits kept at 0.97 in the search, Lu 2014's path-limit
    feedback on the bank (HORUS-2B limits the heat rate, q and the load)."""
    from drake_entry.guidance.swarm_bank.derive import (
        BANK_END_BOUNDS_DEG,
        LIMIT_FRACTION,
        PATH_GAIN,
        PATH_LIMIT_FRACTION,
    )
    from drake_entry.guidance.swarm_bank.spec import SwarmBank

    scenario = load_scenario("horus2b")
    d = derivation_for(scenario, SwarmBank)
    speeds, alphas, _ = alpha_rewritten(scenario, terminal_interface(scenario), "velocity")
    g = d.spec
    assert g.alpha_law == "load" and g.alpha_deg == alphas == [15.0, 40.0]
    assert g.alpha_velocity_m_s == pytest.approx(speeds, abs=1e-3) and (g.alpha_min_deg, g.alpha_max_deg) == (15.0, 40.0)
    assert g.bank_end_bounds_deg == list(BANK_END_BOUNDS_DEG) and g.optimizer == "differential_evolution"
    assert (g.objective_range_unit_km, g.objective_altitude_unit_km) == (2.0, 2.0) and g.limit_fraction == LIMIT_FRACTION
    assert [s.name for s in d.search] == ["guidance.alpha_law", "guidance.qeg_gain", "guidance.terminal_altitude_km"]
    assert g.path_gain == PATH_GAIN == 40.0 and g.path_limit_fraction == PATH_LIMIT_FRACTION == 0.95
    assert d.search[1].candidates == ({"guidance.qeg_gain": 10.0}, {"guidance.qeg_gain": 0.0})
    assert d.search[0].candidates == ({"guidance.alpha_law": "load"}, {"guidance.alpha_law": "schedule"})
    g.validate(dc.replace(scenario, guidance=g))


def test_the_schedule_law_s_search_pays_for_each_limit_it_breaches():
    """limit_excess: the relative excess of each peak over its limit (times the fraction),
    summed; a limit the vehicle does not have costs nothing."""
    import math

    from drake_entry.guidance.swarm_bank.evaluator import limit_excess

    limits = load_scenario("horus2b").make_vehicle().limits  # 530 kW/m^2, 10 kPa, normal load 2.5 g
    assert math.isinf(limits.total_load_max) and limits.normal_load_max == 2.5
    peaks = np.array([[530e3, 583e3], [9e3, 11e3], [2.0, 3.0]])
    np.testing.assert_allclose(limit_excess(limits, peaks), [0.0, 0.1 + 0.1 + 0.2], rtol=1e-12)
    np.testing.assert_allclose(limit_excess(limits, peaks, 0.9)[0], 530 / 477 - 1.0, rtol=1e-12)
    # under the load law (eq. 31's alpha holds the load) only the heat rate and q are paid for
    np.testing.assert_allclose(limit_excess(limits, peaks, held=("load",)), [0.0, 0.1 + 0.1], rtol=1e-12)


def test_a_box_alpha_window_the_mission_s_alpha_misses_is_beyond_a_bank_only_method():
    """MaRV's impact box asks alpha 0 +- 2 deg; its alpha schedule is 11.9 deg: every method that
    flies the mission's alpha with the bank as its only control says so with those figures (the
    swarm's load law moves alpha 1 deg about a constant schedule, still outside), and a box without
    an alpha window constrains nothing."""
    from drake_entry.guidance.bank_profile.spec import BankProfile
    from drake_entry.guidance.drag_energy.spec import DragEnergy
    from drake_entry.guidance.fnpeg.spec import Fnpeg
    from drake_entry.guidance.swarm_bank.spec import SwarmBank

    marv = load_scenario("marv_guidance")
    for spec, flown in ((Fnpeg, r"\(11.9 deg\)"), (DragEnergy, r"\(11.9 deg\)"), (BankProfile, r"\(11.9 deg\)"),
                        (SwarmBank, r"\(10.9 to 12.9 deg\)")):
        with pytest.raises(CannotFly, match=r"asks alpha 0 \+- 2 deg at its interface, and this method flies the "
                                            r"mission's alpha schedule " + flown):
            derivation_for(marv, spec)
    marv.terminal.alpha_tolerance_deg = 15.0  # 11.9 deg is then inside the window
    assert derivation_for(marv, Fnpeg).spec.alpha_deg == [11.9]


def test_drag_energy_says_before_flying_when_its_plan_would_end_below_the_box():
    """Paper 000's corridor floor (eq. 70, the equilibrium glide with the lift vertical) at the
    capsule's interface is 30 m/s^2 and its drag there 9-17 m/s^2; a plan ends on the floor, whose
    drag on the interface's energy level lies 15.8-17.5 km up, inside the box's 19 +- 3 km, so the
    method flies it (and fails it: 0 of 5, 5-150 km off, its report shows). With a 1-km box the
    floor's point lies outside and the derivation says so with the figures. SPHYNX's DRS point
    (Mach 0.5 at 11.5 km geodetic) lies under the floor too, with the floor's point inside its
    box; the gliders' interfaces lie inside the corridor."""
    from drake_entry.guidance.drag_energy.spec import DragEnergy

    capsule = load_scenario("capsule_lu2008")
    assert type(derivation_for(capsule, DragEnergy).spec) is DragEnergy
    capsule.terminal.altitude_tolerance_km = 1.0
    with pytest.raises(CannotFly, match=r"drag below the glide floor at the interface: 11.8-14.4 m/s\^2 against "
                                        r"29.9-30 \(18.5-19.75 km, 305 m/s, alpha 20 deg; the floor.*: a plan ends "
                                        r"on the floor, whose drag on the interface's energy level lies at "
                                        r"16.3-16.8 km, outside the box's 19 \+- 1 km"):
        derivation_for(capsule, DragEnergy)
    for mission in ("horus2b_flight", "cav_h_paper004", "cav_h_fnpeg", "sphynx_paper001"):
        assert type(derivation_for(load_scenario(mission), DragEnergy).spec) is DragEnergy


def test_the_alpha_commanding_methods_fly_the_vehicle_s_alpha_actuator_where_it_states_one():
    """SHEFEX-3's vehicle states paper 003's alpha actuator (5 deg/s, 4 deg/s^2): SCvx, the swarm
    bank and FNPEG fly it, the LGL plans keep their slower 2 deg/s bound with its acceleration;
    on HORUS-2B (none stated) each keeps its own paper's. SCvx's derived plans may take 250
    iterations."""
    from drake_entry.comparison.mission_alpha import alpha_in_speed
    from drake_entry.guidance.fnpeg.spec import Fnpeg
    from drake_entry.guidance.lgl_terminal.spec import LglTerminal
    from drake_entry.guidance.scvx.derive import MAX_ITERATIONS
    from drake_entry.guidance.scvx.spec import Scvx
    from drake_entry.guidance.swarm_bank.spec import SwarmBank

    def actuators(mission):
        scenario = alpha_in_speed(load_scenario(mission))[0]  # as the comparison gives it to others
        s, w, f, g = (derivation_for(scenario, t).spec for t in (Scvx, SwarmBank, Fnpeg, LglTerminal))
        return ((s.alpha_rate_limit_deg_s, s.alpha_accel_limit_deg_s2), (w.alpha_rate_deg_s, w.alpha_accel_deg_s2),
                (f.alpha_rate_deg_s, f.alpha_accel_deg_s2), (g.alpha_rate_deg_s, g.alpha_accel_limit_deg_s2),
                s.flight_check().alpha_acceleration_deg_s2, s.max_iterations)

    assert actuators("shefex3_ampi") == ((5.0, 4.0), (5.0, 4.0), (5.0, 4.0), (2.0, 4.0), 4.0, MAX_ITERATIONS)
    assert actuators("horus2b") == ((1.0, 5.0), (4.0, 8.0), (5.0, 10.0), (2.0, 40.0), 5.0, MAX_ITERATIONS)
    choice = next(c for c in derivation_for(load_scenario("horus2b"), Scvx).choices if "alpha_rate" in c.field)
    assert "states no alpha actuator" in choice.how


@pytest.mark.slow
def test_scvx_s_plan_on_shefex3_flown_through_the_vehicle_s_alpha_actuator_is_verified():
    """The derived pre-flight plan (the search's altitude, 22.875 km) converges within the derived
    cap and its controls, flown by Drake through the 5-deg/s alpha actuator, end within the
    propagation tolerance of it (through the 1-deg/s actuator of paper 001 they ended 20.8 km off:
    the plan's alpha(V) moves 1.87 deg/s)."""
    from drake_entry.comparison.mission_alpha import alpha_in_speed
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.scvx.method import METHOD
    from drake_entry.guidance.scvx.planner import PROPAGATION_TOLERANCE_M
    from drake_entry.guidance.scvx.spec import Scvx

    scenario = alpha_in_speed(load_scenario("shefex3_ampi"))[0]
    d = derivation_for(scenario, Scvx)
    aim = next(c for c in d.search[0].candidates if c["guidance.terminal_altitude_km"] == 22.875)
    flown = apply_derivation(scenario, d, aim)
    plan = METHOD.make_planner(flown, verifier=fly_controls)
    assert plan.success, plan.message
    assert plan.iterations <= flown.guidance.max_iterations
    assert plan.propagated_error_m < PROPAGATION_TOLERANCE_M
    assert plan.metrics["max_alpha_rate_deg_s"] > 1.0
