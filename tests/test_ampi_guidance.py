"""Paper 003's guidance on the packaged SHEFEX-3 database: the database itself (729 verified,
consistent cases at 60 LD nodes, its provenance), the reference maker's eq. 6 offsets, AMPI
against NTT references, the tracker system's errors and recorded failures, the spec's field
errors, and closed-loop flights through the Drake Simulator."""
import dataclasses as dc
import math

import numpy as np
import pytest

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.reference import DatabaseReference


@pytest.fixture(scope="module")
def planner():
    return DatabaseReference.load("shefex3")


def test_packaged_database_is_the_full_eq_5_grid_verified_consistent_and_reaches_the_target(planner):
    db, problem = planner.database, planner.problem
    assert planner.success, planner.message
    assert db.grid.size == 729 and db.verified.all() and db.inconsistent() == {}
    assert db.n_ld == 60 and db.storage_bytes / 1e6 == pytest.approx(3.155, abs=0.01)
    assert db.provenance["study"]["problem"] == "shefex3"
    # every case ends on the hard terminal point, in the speed and geodetic altitude windows
    nx = len(db.state_names)
    end = db.values[:, -1, :nx]
    names = db.state_names
    assert np.abs(end[:, names.index("lon")] - problem.final["lon"]).max() < 1e-6
    assert np.abs(end[:, names.index("lat")] - problem.final["lat"]).max() < 1e-6
    V = end[:, names.index("V")]
    assert V.min() >= 570.0 - 1e-3 and V.max() <= 620.0 + 1e-3
    h_geo = [problem.planet.atmospheric_altitude(x[0], x[2]) for x in end]
    assert min(h_geo) >= 21e3 - 1.0 and max(h_geo) <= 26e3 + 1.0


@pytest.mark.xfail(strict=True, reason="known limitation (docs/methods/ampi.md): the first-order-held bank "
                   "rate dips the bank up to 3 deg past 60 deg between DirectCollocation knots (case 591: "
                   "-63.0 deg at 77.9 s) and the between-node verification does not check state bounds; "
                   "the tracker clips the command at 60 deg. Remove this mark when the database is rebuilt")
def test_packaged_database_bank_holds_the_table_2_limit_between_knots(planner):
    """Paper 003 Table 2: |sigma| <= 60 deg along every stored trajectory (the LD nodes)."""
    db = planner.database
    assert np.degrees(np.abs(db.values[:, :, db.state_names.index("sigma")])).max() <= 60.0 + 1e-6


def test_offsets_are_eq_6_with_a_geodetic_altitude(planner):
    p = planner.problem
    x0 = np.array([p.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")])
    assert planner.offsets(x0) == pytest.approx(np.zeros(6), abs=1e-9)
    x = x0.copy()
    x[2] += math.radians(0.3)  # same state altitude at another latitude: a geodetic offset
    x[3] += 20.0
    d = planner.offsets(x)
    dh = p.planet.atmospheric_altitude(x[0], x[2]) - p.planet.atmospheric_altitude(x0[0], x0[2])
    assert abs(dh) > 10.0 and d == pytest.approx([dh, 0.0, math.radians(0.3), 20.0, 0.0, 0.0], abs=1e-9)


def test_ampi_at_the_nominal_is_the_stored_entry_and_ntt_takes_the_nearest_case(planner):
    db = planner.database
    centre = db.grid.index(db.grid.centre)
    x0 = np.array([planner.problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")])
    syn, _ = planner.synthesis(x0)
    assert np.array_equal(syn.states, db.entry(centre, planner.hd_points).states)
    x = x0.copy()
    x[3] += 50.0  # nearer V + 70 than V 0
    ntt = dc.replace(planner, mode="ntt")
    s_ntt, off = ntt.synthesis(x)
    s_ampi, _ = planner.synthesis(x)
    assert s_ntt.cases == [db.grid.index((1, 1, 1, 2, 1, 1))] and off[3] == pytest.approx(50.0)
    # AMPI's t_f lies between the two stored cases', 50/70 of the way
    t0, t1 = db.final_time[centre], db.final_time[s_ntt.cases[0]]
    assert s_ampi.final_time == pytest.approx(t0 + 50.0 / 70.0 * (t1 - t0), rel=1e-12)


def test_reference_comes_with_a_tvlqr_law(planner):
    x0 = np.array([planner.problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")])
    ref = planner.reference(x0)
    law = ref.law
    assert law.gains.shape == (planner.gain_samples, 1, 8) and np.isfinite(law.gains).all()
    assert law.time[-1] == pytest.approx(ref.synthesis.final_time)
    # the law flown on the problem's own dynamics from an entry 20 m/s fast ends nearer the
    # reference's end point than the reference's rate flown open loop
    from scipy.integrate import solve_ivp

    from drake_entry.models.geodesy import central_angle

    p = planner.problem
    x0 = law.states[0].copy()
    x0[3] += 20.0
    ends = {}
    for name, u in (("feedback", lambda t, x: law.command(t, x)), ("open", lambda t, x: law.reference(t)[1])):
        sol = solve_ivp(lambda t, x: np.asarray(p.dynamics(x, np.clip(u(t, x), -np.radians(5), np.radians(5))), float),
                        (0.0, law.time[-1]), x0, rtol=1e-7, atol=1e-6)
        xf = sol.y[:, -1]
        ends[name] = central_angle(xf[1], xf[2], law.states[-1, 1], law.states[-1, 2]) * p.planet.reference_radius
    assert ends["feedback"] < 1e3 and ends["open"] > 10e3, ends  # measured 207 m, 30.6 km


def test_tracker_records_a_reference_it_cannot_make_and_holds_its_bank(planner):
    from pydrake.systems.analysis import Simulator

    from drake_entry.systems.reference_tracking import ReferenceTracker

    db = dc.replace(planner.database, verified=planner.database.verified.copy())
    centre = db.grid.index(db.grid.centre)
    db.verified[centre] = False
    broken = dc.replace(planner, database=db)
    tracker = ReferenceTracker(broken, bank_limit=math.radians(60), rate_limit=math.radians(5), initial_bank=0.3)
    ctx = tracker.CreateDefaultContext()
    x0 = [planner.problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")]
    tracker.GetInputPort("estimated_state").FixValue(ctx, x0)
    sim = Simulator(tracker, ctx)
    sim.AdvanceTo(5.0)
    mem = tracker.memory(sim.get_context())
    assert mem.reference is None and f"database cases [{centre}" in mem.message and "not verified" in mem.message
    assert tracker.GetOutputPort("bank_command").Eval(sim.get_context())[0] == 0.3
    with pytest.raises(ScenarioError, match="ReferenceTracker.lead = -1.0 s: allowed 0 to 10"):
        ReferenceTracker(planner, bank_limit=1.0, rate_limit=0.1, lead=-1.0)
    with pytest.raises(ScenarioError, match="ReferenceTracker.rate_limit = 0: must be > 0"):
        ReferenceTracker(planner, bank_limit=1.0, rate_limit=0)


@pytest.mark.parametrize("index", ["time", "energy"])
def test_tracker_reads_its_reference_at_the_clock_or_at_the_estimates_energy(planner, index):
    """Read in energy, a flight at the reference's state of 200 s gets that state whatever its
    clock (the energy falls by 6 kJ/kg per second there, so 0.5 s is 3 kJ/kg); read in time, the
    state at its clock."""
    from pydrake.systems.analysis import Simulator

    from drake_entry.systems.reference_tracking import ReferenceTracker

    tracker = ReferenceTracker(planner, bank_limit=math.radians(60), rate_limit=math.radians(5), index=index)
    ctx = tracker.CreateDefaultContext()
    x0 = [planner.problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")]
    port = tracker.GetInputPort("estimated_state")
    port.FixValue(ctx, x0)
    Simulator(tracker, ctx).Initialize()
    law = tracker.memory(ctx).reference.law
    energy = tracker.memory(ctx).energy
    if index == "time":
        assert energy is None
    else:  # the reference's energy at its samples, falling
        assert energy.shape == law.time.shape and np.all(np.diff(energy) <= 0.0) and energy[0] > energy[-1] + 1e6
    port.FixValue(ctx, law.state(200.0)[:6])
    read = tracker.GetOutputPort("reference_state").Eval(ctx)
    expected = law.state(200.0 if index == "energy" else 0.0)[:7]
    scale = np.array([100.0, 1e-5, 1e-5, 1.0, 1e-4, 1e-4, 1e-3])  # 0.5 s of the reference, about
    assert np.all(np.abs(read - expected) < scale), (read - expected) / scale
    with pytest.raises(ScenarioError, match="ReferenceTracker.index = 'range'; allowed: time, energy"):
        ReferenceTracker(planner, bank_limit=1.0, rate_limit=0.1, index="range")


def test_sensed_reference_is_the_state_of_the_reference_energy_with_the_reference_drag():
    """In an exponential atmosphere (scale height 7 km): the state keeps the reference's energy
    V^2/2 + g h; its drag k_D rho V^2 is the reference's, to 1e-6 at orbital speed and to second
    order in ln k_D at 400 m/s (where the altitude moves less than H ln k_D: the speed it trades
    changes the drag too); each bank gives k_L cos(sigma) rho V^2 = cos(sigma_ref) rho_ref
    V_ref^2, its sign kept; nominal ratios change nothing."""
    from drake_entry.systems.reference_tracking import sensed_reference

    H, g = 7000.0, 9.7

    def density(h):
        return 1.2 * math.exp(-h / H)

    for V_ref, tolerance in ((7000.0, 1e-6), (400.0, 2e-3)):
        h, V, (s1, s2) = sensed_reference(40e3, V_ref, (0.9, -0.4), (1.06, 1.04), density, g)
        assert 0.5 * V * V + g * h == pytest.approx(0.5 * V_ref ** 2 + g * 40e3, rel=1e-12)
        drag = density(40e3) * V_ref ** 2
        assert 1.04 * density(h) * V * V == pytest.approx(drag, rel=tolerance)
        assert 0.0 < h - 40e3 <= H * math.log(1.04) + 1e-9
        for s, ref in ((s1, 0.9), (s2, -0.4)):
            assert 1.06 * math.cos(s) == pytest.approx(1.04 * math.cos(ref), rel=1e-12)
            assert math.copysign(1.0, s) == math.copysign(1.0, ref)
    assert h - 40e3 < 0.6 * H * math.log(1.04)  # at 400 m/s
    assert sensed_reference(40e3, 400.0, (0.9,), (1.0, 1.0), density, g) == (
        pytest.approx(40e3), pytest.approx(400.0), [pytest.approx(0.9)])
    # more drag than lift asks more vertical lift than a bank can give: wings level
    assert sensed_reference(40e3, 400.0, (0.1,), (0.8, 1.3), density, g)[2] == [0.0]


def test_tracker_at_nominal_ratios_commands_what_it_commands_without_them(planner):
    """One update at the reference's state where it banks most (read in energy): the port "model_scales" at
    (1, 1) leaves the command unchanged; more sensed lift than drag (1.1, 1.0) turns the bank
    further from wings level, keeping the reference's vertical lift (1.1 cos(sigma) = cos(sigma_ref))."""
    from pydrake.systems.analysis import Simulator

    from drake_entry.models.atmosphere import make_atmosphere
    from drake_entry.systems.reference_tracking import ReferenceTracker

    density = make_atmosphere("us76").density
    x0 = [planner.problem.initial[n] for n in ("h", "lon", "lat", "V", "gamma", "psi")]
    banks = {}
    for scales in (None, (1.0, 1.0), (1.1, 1.0)):
        tracker = ReferenceTracker(planner, bank_limit=math.radians(85), rate_limit=math.radians(500),
                                   index="energy", density=None if scales is None else density)
        ctx = tracker.CreateDefaultContext()
        port = tracker.GetInputPort("estimated_state")
        port.FixValue(ctx, x0)
        if scales is not None:
            tracker.GetInputPort("model_scales").FixValue(ctx, scales)
        Simulator(tracker, ctx).Initialize()
        law = tracker.memory(ctx).reference.law
        t = float(law.time[np.argmax(np.abs(law.states[:, 6]))])  # where the reference banks most
        port.FixValue(ctx, law.state(t)[:6])
        bank = tracker.GetOutputPort("bank_command")
        for k in range(ctx.num_discrete_state_groups()):  # the command at the reference's bank then
            if ctx.get_discrete_state(k).size() == 1:
                ctx.SetDiscreteState(k, [law.state(t + tracker.lead)[6]])
        ctx.SetDiscreteState(tracker.EvalUniquePeriodicDiscreteUpdate(ctx))
        banks[scales] = float(bank.Eval(ctx)[0])
    assert abs(banks[None]) > math.radians(5.0), banks
    assert banks[(1.0, 1.0)] == pytest.approx(banks[None], abs=1e-9)
    # at the reference's state the feedback is nil: the command is the feed-forward, scaled
    assert 1.1 * math.cos(banks[(1.1, 1.0)]) == pytest.approx(math.cos(banks[None]), abs=1e-9), banks
    assert abs(banks[(1.1, 1.0)]) > abs(banks[None]) + math.radians(2.0), banks
    assert not ReferenceTracker(planner, bank_limit=1.0, rate_limit=0.1).HasInputPort("model_scales")


def test_tracker_path_limit_feedback_only_lifts_where_a_limit_is_ahead(planner):
    """limited_bank: descending at -8 deg with q at 0.97 of a 30-kPa limit held at 0.95, Lu 2014's
    feedback raises cos(sigma) by exactly k V (U - sin gamma) sqrt(g0/R0) / L (U the flight-path
    sine that holds q 16 s ahead), the sign kept; level flight far below the limit, or no lift,
    leaves the command alone. Only a tracker with an active feedback reads the flight conditions."""
    from drake_entry.guidance.path_feedback import PathLimits, path_limit_sin_flight_path
    from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
    from drake_entry.models.planet import Earth
    from drake_entry.systems.reference_tracking import ReferenceTracker, limited_bank

    path = PathLimits(6378137.0, 9.80665, gain=40.0, q_max=0.95 * 30e3)
    fc = np.zeros(len(FLIGHT_CONDITION_NAMES))
    idx = {n: i for i, n in enumerate(FLIGHT_CONDITION_NAMES)}
    V, gamma, L, D, q = 1500.0, math.radians(-8.0), 8.0, 5.0, 0.97 * 30e3
    fc[idx["lift"]], fc[idx["drag"]], fc[idx["dynamic_pressure"]] = L, D, q
    x = [25e3, 0.0, 0.0, V, gamma, 0.0]
    U = path_limit_sin_flight_path(V, D, math.hypot(L, D), 0.0, q, path)
    assert U > math.sin(gamma)  # the limit is ahead
    sigma = math.radians(-120.0)
    lifted = limited_bank(sigma, x, fc, path, math.radians(170.0))
    expected = math.cos(sigma) + 40.0 * V * (U - math.sin(gamma)) * math.sqrt(9.80665 / 6378137.0) / L
    assert lifted < 0.0 and math.cos(lifted) == pytest.approx(min(expected, 1.0), rel=1e-12)
    assert abs(lifted) < abs(sigma)
    level = [25e3, 0.0, 0.0, V, 0.0, 0.0]
    fc[idx["dynamic_pressure"]] = 0.3 * 30e3
    assert limited_bank(sigma, level, fc, path, math.radians(170.0)) == sigma
    fc[idx["lift"]] = 0.0
    assert limited_bank(sigma, x, fc, path, math.radians(170.0)) == sigma
    assert ReferenceTracker(planner, bank_limit=1.0, rate_limit=0.1, path=path).HasInputPort("flight_conditions")
    off = PathLimits.of_vehicle(planner.problem.vehicle.limits, Earth(), gain=0.0, horizon=16.0, fraction=0.95)
    assert not ReferenceTracker(planner, bank_limit=1.0, rate_limit=0.1, path=off).HasInputPort("flight_conditions")


@pytest.mark.parametrize("field, value, message", [
    ("reference", "best", "guidance.reference = 'best'; allowed: ampi, ntt"),
    ("path_gain", -1.0, r"guidance.path_gain = -1.0 is out of range; allowed \[0, 1000\]"),
    ("path_limit_fraction", 1.2, r"guidance.path_limit_fraction = 1.2 is out of range"),
    ("database", "nowhere.npz", "guidance.database 'nowhere.npz' is neither a packaged database"),
    ("tracking_scales", [1.0] * 6, "guidance.tracking_scales needs 7 values, got 6"),
    ("bank_lead_s", 20.0, r"guidance.bank_lead_s = 20.0 is out of range; allowed \[0, 10\]"),
    ("hd_points", 1, r"guidance.hd_points = 1 is out of range"),
    ("tracking_index", "range", "guidance.tracking_index = 'range'; allowed: time, energy"),
    ("terminal_velocity_m_s", 9000.0, r"guidance.terminal_velocity_m_s = 9000.0 is out of range"),
])
def test_spec_errors_name_the_field(field, value, message):
    from drake_entry.scenario import load_scenario

    s = load_scenario("shefex3_ampi")
    bad = dc.replace(s, guidance=dc.replace(s.guidance, **{field: value}))
    with pytest.raises(ScenarioError, match=message):
        bad.guidance.validate(bad)


def _fly(mode, dV=0.0, dgamma_deg=0.0):
    from drake_entry.diagrams import closed_loop as cl
    from drake_entry.scenario import load_scenario

    s = load_scenario("shefex3_ampi")
    s = dc.replace(s, guidance=dc.replace(s.guidance, reference=mode))
    x0 = s.initial_state()
    x0[3] += dV
    x0[4] += math.radians(dgamma_deg)
    return cl.fly(s, initial_state=x0)


def test_nominal_flight_reaches_the_target_within_the_limits():
    """The nominal entry through the Drake closed loop (navigation, actuator, tracker):
    1.28 km from the target (the LD-60 reference alone drifts 5.7 km open loop), in the
    altitude and speed windows, under Table 2's path limits."""
    r = _fly("ampi")
    assert r.success, r.message
    assert r.errors["distance_m"] < 2.0e3
    assert abs(r.errors["velocity_m_s"]) < 1.0
    tr = r.trajectory
    assert r.guidance.fields["reference_mode"] == "ampi" and r.guidance.fields["reference_extrapolated"] == 0
    assert r.guidance.fields["synthesis_ms"] < 50.0  # loose: one cold call in a test process
    peaks = {"dynamic_pressure": 50e3, "heat_flux": 6.5e6, "normal_load": 10.0}
    for name, limit in peaks.items():
        assert np.max(tr.column(name)) <= limit, name


def test_ampi_beats_ntt_between_the_grid_levels():
    """An entry 30 m/s fast and 0.2 deg steep (between the levels): NTT tracks the
    nominal-speed case's reference and ends far from the target; AMPI's interpolated
    reference lands within a few km."""
    a, n = _fly("ampi", 30.0, 0.2), _fly("ntt", 30.0, 0.2)
    assert a.success, a.message
    assert a.errors["distance_m"] < 3.0e3
    assert n.errors["distance_m"] > 3.0 * a.errors["distance_m"]


@pytest.mark.slow
def test_reduced_campaign_ampi_against_ntt_table_3_form(tmp_path):
    """The first 40 samples of the 1000-run campaign (seed 0) of each mode, same controller:
    AMPI lands every one within 25 km under the path limits; NTT, flying the nearest entry's
    reference, ends farther on average and passes the q limit (the full campaigns:
    docs/methods/ampi.md)."""
    import pandas as pd
    from pydrake.common.yaml import yaml_dump_typed

    from drake_entry.campaign.montecarlo import run_campaign
    from drake_entry.scenario import Scenario, load_scenario

    s = load_scenario("shefex3_ampi")
    dist = {}
    for mode in ("ampi", "ntt"):
        path = tmp_path / f"{mode}.yaml"
        path.write_text(yaml_dump_typed(dc.replace(s, guidance=dc.replace(s.guidance, reference=mode)), schema=Scenario))
        out = run_campaign(str(path), runs=40, seed=0, workers=2, out_dir=str(tmp_path / mode), progress=False)
        rows = pd.read_parquet(tmp_path / mode / "samples.parquet")
        assert len(rows) == 40 and rows["reached_terminal"].all(), out
        if mode == "ampi":  # NTT exceeds q on 230 of the full 1000 (up to 5.2 %), 8 of these 40
            for c in ("margin_heat_flux", "margin_dynamic_pressure", "margin_normal_load"):
                assert rows[c].min() >= 0.0, c
        dist[mode] = rows["err_distance_m"].to_numpy()
    assert (dist["ampi"] <= 25e3).all() and dist["ampi"].mean() < 3e3
    assert dist["ntt"].mean() > 2.0 * dist["ampi"].mean()


@pytest.mark.slow
def test_accuracy_study_and_reconstruction_error(tmp_path):
    """Eq. 13 on 6 entries: every entry's own OCP verified, AMPI's references nearer to it
    than NTT's on average; the nominal's LD-60 reconstruction against its own flown bank
    within the figures docs/methods/ampi.md gives (156 m, 5.7 km at the end)."""
    from drake_entry.guidance.ampi.accuracy_study import AccuracyStudy, accuracy_study, reconstruction_error, summarise

    rows = accuracy_study(str(tmp_path / "acc"), AccuracyStudy(cases=6), workers=2, progress=False)
    s = summarise(rows)
    assert s["verified"] == 6, s["failed"]
    for n in ("h", "V", "lon", "lat"):
        assert s["ampi"][n]["mean"] < s["ntt"][n]["mean"], n
    assert s["ampi"]["synthesis_s"]["max"] < 0.05
    planner = DatabaseReference.load("shefex3")
    db = planner.database
    e = reconstruction_error(db, db.grid.index(db.grid.centre), planner.problem)
    assert 50.0 < e["h"] < 300.0 and 1e3 < e["position_m"] < 10e3
