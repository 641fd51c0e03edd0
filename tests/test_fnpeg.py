"""FNPEG (Lu 2014): the law's feedback terms against their derivations, the corrector on
functions with known roots, the native predictor against the models and its own step, the
spec's errors, and the closed loop through engagement and the first corrections."""
import math

import numpy as np
import pytest
from pydrake.symbolic import Variable

from drake_entry.errors import ScenarioError
from drake_entry.guidance.fnpeg import predictor as predictor_module
from drake_entry.guidance.fnpeg.corrector import SIGMA0_BOUNDS, CorrectorSettings, correct
from drake_entry.guidance.fnpeg.law import (
    FeedbackSettings,
    commanded_bank,
    qegc_sin_flight_path,
)
from drake_entry.guidance.fnpeg.onboard import FnpegSetup
from drake_entry.guidance.path_feedback import PathLimits, path_limit_sin_flight_path
from drake_entry.models import dynamics
from drake_entry.models.schedules import linear_bank
from drake_entry.models.vehicles import load_vehicle
from drake_entry.scenario import apply_overrides, load_scenario

R0, G0 = 6378137.0, 9.80665
#: a CAV-H state a few seconds after engagement (sqrt(L^2 + D^2) ~ 1.5 m/s^2), from the packaged scenario
ENGAGED = np.array([5.96448e4, -0.869685, 0.933247, 7461.26, -0.0296397, 0.995540])


@pytest.fixture(scope="module")
def setup():
    return FnpegSetup.from_scenario(load_scenario("cav_h_fnpeg"))


def test_linear_bank_runs_from_sigma0_to_sigmaf():
    assert linear_bank(3.0, 3.0, 7.0, 0.4, 1.0) == pytest.approx(0.4)
    assert linear_bank(7.0, 3.0, 7.0, 0.4, 1.0) == pytest.approx(1.0)
    assert linear_bank(5.0, 3.0, 7.0, 0.4, 1.0) == pytest.approx(0.7)


def test_without_feedback_the_command_is_the_profile_and_the_limit_clips_it():
    s = FeedbackSettings(R0, G0, damping_gain=0.0, bank_limit=math.radians(85.0))
    assert commanded_bank(0.7, 6000.0, -0.01, 5.0, 1.6, 5.2, 3e6, 3e4, s) == pytest.approx(0.7, abs=1e-12)
    assert commanded_bank(1.55, 6000.0, -0.01, 5.0, 1.6, 5.2, 3e6, 3e4, s) == pytest.approx(math.radians(85.0))


def test_phugoid_damping_is_zero_on_the_qegc_descent_and_lifts_a_faster_descent():
    s = FeedbackSettings(R0, G0, damping_gain=20.0, damping_off_speed=2000.0, ramp=1000.0)
    V, L, D = 6000.0, 5.0, 1.6
    gamma_qegc = math.asin(qegc_sin_flight_path(V, L / D, s))
    assert -0.01 < gamma_qegc < 0.0  # a shallow glide descent
    assert commanded_bank(0.8, V, gamma_qegc, L, D, 5.2, 3e6, 3e4, s) == pytest.approx(0.8, abs=1e-12)
    assert commanded_bank(0.8, V, gamma_qegc - 0.01, L, D, 5.2, 3e6, 3e4, s) < 0.8  # more vertical lift
    assert commanded_bank(0.8, V, gamma_qegc + 0.01, L, D, 5.2, 3e6, 3e4, s) > 0.8
    # the gain ramps to 0 at damping_off_speed: no correction there
    assert commanded_bank(0.8, 2000.0, gamma_qegc - 0.01, L, D, 5.2, 3e6, 3e4, s) == pytest.approx(0.8, abs=1e-12)


def test_qegc_angle_is_the_equilibrium_glide_derivative():
    """sin(gamma_QEGC) = -2 / (beta v^2 cos(sigma) L/D): differentiate the equilibrium glide
    L cos(sigma) = g - V^2/r in an exponential atmosphere (rho' / rho = -beta / R0, dV/dt = -D)
    numerically and compare."""
    s = FeedbackSettings(R0, G0, beta=900.0)
    V, ld = 5000.0, 3.0
    # equilibrium glide altitude h(V): rho(h) V^2 k cos(sigma) = g0 - V^2/R0 with rho = exp(-beta h / R0)
    k = 1e-3

    def h_eq(v):
        return -R0 / s.beta * math.log((G0 - v * v / R0) / (v * v * k * math.cos(s.damping_bank)))

    dv = 0.01
    dh_dv = (h_eq(V + dv) - h_eq(V - dv)) / (2 * dv)
    L = G0 - V * V / R0  # vertical lift per cos(sigma) on the glide, with D = L / ld ...
    D = L / math.cos(s.damping_bank) / ld
    sin_gamma = dh_dv * (-D) / V  # hdot = dh/dV * dV/dt
    assert qegc_sin_flight_path(V, ld, s) == pytest.approx(sin_gamma, rel=2e-3)


@pytest.mark.parametrize("which", ["load", "q", "heat"])
def test_path_limit_bound_keeps_the_predicted_quantity_at_its_limit(which):
    """At sin(gamma) = U, the first-order prediction of the quantity ``horizon`` seconds ahead
    (rho'/rho = -beta/R0, dV/dt = -D) equals its limit."""
    V, D, d, beta = 6500.0, 2.0, 16.0, 900.0
    value, exponent_rho, exponent_v = {"load": (12.0, 1.0, 2.0), "q": (4e4, 1.0, 2.0),
                                       "heat": (4e6, 0.5, 3.15)}[which]
    limit = 0.9 * value
    kwargs = {"load_max": limit} if which == "load" else {"q_max": limit} if which == "q" else {"heat_max": limit}
    s = PathLimits(R0, G0, beta=beta, horizon=d, **kwargs)
    loads = {"load": value, "q": 1.0, "heat": 1.0}
    u = path_limit_sin_flight_path(V, D, loads["load"], value if which == "heat" else 1.0,
                                   value if which == "q" else 1.0, s)
    rate = exponent_rho * (-beta * V * u / R0) - exponent_v * D / V
    assert value * (1.0 + rate * d) == pytest.approx(limit, rel=1e-12)


def test_law_is_the_same_for_float_and_symbolic_scalars():
    s = FeedbackSettings(R0, G0, path=PathLimits(R0, G0, gain=40.0, load_max=1.8 * G0, heat_max=4.3e6, q_max=6e4),
                         bank_limit=math.radians(85.0))
    names = ("sigma", "V", "gamma", "L", "D", "a", "heat", "q")
    xs = [Variable(n) for n in names]
    with np.errstate(all="ignore"):  # numpy's object loops report stray FP flags as warnings
        expr = commanded_bank(*xs, s)
    rng = np.random.default_rng(40)
    for _ in range(20):
        vals = [rng.uniform(0.2, 1.3), rng.uniform(2500, 7400), rng.uniform(-0.05, 0.02), rng.uniform(1, 20),
                rng.uniform(0.3, 6), rng.uniform(1, 25), rng.uniform(1e6, 6e6), rng.uniform(5e3, 9e4)]
        assert expr.Evaluate(dict(zip(xs, vals))) == pytest.approx(commanded_bank(*vals, s), rel=1e-12, abs=1e-12)


def test_corrector_finds_a_root_by_the_damped_secant():
    target = math.radians(63.0)
    z = lambda s0: 4e6 * (math.cos(target) - math.cos(s0))  # noqa: E731  (z grows with the bank: less range flown)
    c = correct(z, math.radians(20.0), CorrectorSettings(tolerance=50.0))
    assert c.converged and abs(c.z) <= 50.0 and c.sigma0 == pytest.approx(target, abs=2e-5)
    assert c.predictions <= 10
    again = correct(z, c.sigma0, CorrectorSettings(tolerance=50.0), slope=c.slope)  # the next cycle
    assert again.converged and again.predictions == 1


def test_corrector_without_a_root_stops_on_the_bound_not_a_traceback():
    """Energy short: the range falls short whatever the bank (z > 0 everywhere) -> sigma_0 = 0,
    not converged, with the reason."""
    z = lambda s0: 2e5 + 4e6 * (1.0 - math.cos(s0))  # noqa: E731
    c = correct(z, math.radians(40.0), CorrectorSettings(tolerance=100.0))
    assert not c.converged and c.sigma0 == pytest.approx(SIGMA0_BOUNDS[0]) and c.stop
    # too long whatever the bank: sigma_0 stays at 90 deg, never beyond
    c = correct(lambda s0: -1e5 + 1e3 * s0, math.radians(80.0), CorrectorSettings())
    assert not c.converged and c.sigma0 == pytest.approx(SIGMA0_BOUNDS[1])


@pytest.mark.parametrize("stages", ["as chosen", "one system", "two stages"])
def test_predictor_derivatives_are_the_plants_with_the_laws_bank(setup, stages, monkeypatch):
    """The native predictor's dx/dt at a state equals drake_entry.models.dynamics with the lift and
    drag scaled as the flight has shown and the bank commanded_bank gives there, in float: in
    the form the predictor chose for CAV-H (two stages: its expressions repeat the Mach tables)
    and in both forms forced."""
    if stages == "as chosen":
        p = setup.predictor
        assert p.staged  # CAV-H's one-system expressions are 3.6 times the stages'
    else:
        monkeypatch.setattr(predictor_module, "STAGED_SIZE_RATIO", math.inf if stages == "one system" else 0.0)
        p = FnpegSetup.from_scenario(load_scenario("cav_h_fnpeg")).predictor
        assert p.staged == (stages == "two stages")
    sigma0, sign = math.radians(55.0), -1.0
    k_lift, k_drag = 1.04, 0.97  # what the flight has shown: the predictions fly the models times these
    # e0 below: the profile has moved
    got = p.derivatives([*ENGAGED, 0.0], [sigma0, setup.energy(ENGAGED) + 1e5, sign, k_lift, k_drag])
    x = ENGAGED
    alpha = setup.alpha_command(x[3])
    rho, a = dynamics.air_data(x, setup.planet, setup.atmosphere)
    _, L, D = dynamics.aero_accelerations(x, alpha, rho, a, setup.vehicle)
    L, D = k_lift * L, k_drag * D
    base = linear_bank(setup.energy(x), setup.energy(x) + 1e5, setup.e_f, sigma0, setup.sigma_f)
    bank = sign * commanded_bank(base, x[3], x[4], L, D, math.hypot(L, D), setup.vehicle.heat_flux(rho, x[3], alpha),
                                 0.5 * rho * x[3] ** 2, setup.feedback)
    want = dynamics.equations_of_motion(list(x), bank, L, D, setup.planet)
    r = setup.planet.radius(x[0])
    np.testing.assert_allclose(got[:6], want, rtol=1e-10)
    assert got[6] == pytest.approx(x[3] * math.cos(x[4]) * setup.planet.reference_radius / r, rel=1e-12)


def test_prediction_stops_at_the_terminal_energy_and_converges_with_the_step(setup):
    sigma0 = math.radians(70.0)
    coarse = setup.predict(ENGAGED, sigma0)
    assert coarse.reached and setup.energy(coarse.state) == pytest.approx(setup.e_f, rel=1e-9)
    fine_predictor = FnpegSetup.from_scenario(_scenario({"guidance.predictor_step_s": 1.0})).predictor
    fine = fine_predictor.predict(ENGAGED, sigma0)
    # measured: 4-s steps within about 60 m of 0.5-s steps over a 3700-s, 22 000-km prediction
    assert abs(coarse.range_m - fine.range_m) < 200.0, (coarse.range_m, fine.range_m)
    assert 5e6 < fine.range_m < 2e7 and 1000.0 < fine.time_s < 4000.0


def _scenario(overrides, name="cav_h_fnpeg"):
    sc = load_scenario(name)
    apply_overrides(sc, overrides)
    return sc


@pytest.mark.parametrize("overrides, field", [
    ({"guidance.alpha_deg": [10.0, 12.0], "guidance.alpha_velocity_m_s": [1000.0]}, "guidance.alpha_deg"),
    ({"guidance.alpha_velocity_m_s": [7000.0, 2000.0]}, "guidance.alpha_velocity_m_s"),
    ({"guidance.replan_period_s": 0.5}, "guidance.replan_period_s"),
    ({"guidance.bank_end_deg": 95.0}, "guidance.bank_end_deg"),
    ({"guidance.predictor_step_s": 0.0}, "guidance.predictor_step_s"),
    ({"vehicle_limits": {"mass_kg": 1.0}}, "vehicle_limits"),
    ({"vehicle_limits": {"total_load_max_g": -1.0}}, "vehicle_limits.total_load_max_g"),
])
def test_bad_settings_name_the_field(overrides, field):
    with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
        _scenario(overrides).validate()


def test_vehicle_limits_replace_the_files():
    v = _scenario({}).make_vehicle()
    assert v.bank_rate_limit == pytest.approx(math.radians(10.0)) and v.limits.total_load_max == pytest.approx(2.5)
    assert load_scenario("cav_h").make_vehicle().limits.total_load_max == pytest.approx(2.0)


def test_closed_loop_engages_on_the_acceleration_and_corrects_every_second():
    """The first 420 s of the packaged flight: ballistic until sqrt(L^2 + D^2) reaches 1.52 m/s^2
    (about 315 s), then one correction a second, each converged."""
    from drake_entry.diagrams.closed_loop import fly

    sc = _scenario({})
    sc.simulation.max_time_s = 420.0
    r = fly(sc)
    f = r.guidance.fields
    assert r.guidance.active and 250.0 < f["engage_time_s"] < 380.0
    assert r.guidance.plans == pytest.approx(420.0 - f["engage_time_s"], abs=2)
    assert f["corrections_unconverged"] == 0 and abs(f["last_predicted_range_error_m"]) <= 100.0
    L, D = r.trajectory.column("lift"), r.trajectory.column("drag")
    engaged = r.trajectory.time >= f["engage_time_s"]
    assert np.all(np.hypot(L, D)[~engaged][:-1] < 1.52 + 1e-9)


# -- Lu (2008)'s capsule setting (capsule_lu2008) ----------------------------------------------

@pytest.fixture(scope="module")
def capsule():
    return FnpegSetup.from_scenario(load_scenario("capsule_lu2008"))


#: a capsule state shortly after engagement (about 215 s into the packaged flight)
CAPSULE_ENGAGED = np.array([7.94583e4, -2.044727, 0.292517, 7453.09, -0.0234551, 1.107283])


def test_capsule_predicts_in_one_system(capsule):
    """The capsule's expressions repeat little (1.7 times the stages' expanded size): a second
    native stage would cost more than it saves, so its predictor stays one system."""
    assert not capsule.predictor.staged


def test_capsule_dispersions_are_lu2008s():
    """Lu (2008): 3-sigma Gaussian entry longitude 0.59 deg, latitude 0.66, speed 0.41 m/s,
    flight path 0.023 deg, heading 0.39 deg; uniform C_L +-3 %, C_D +-6 %, mass +-5 %, density +-30 %."""
    d = load_scenario("capsule_lu2008").dispersions
    for field, three_sigma in (("longitude_deg", 0.59), ("latitude_deg", 0.66), ("velocity_m_s", 0.41),
                               ("flight_path_deg", 0.023), ("heading_deg", 0.39)):
        g = getattr(d.entry, field)
        assert (g.mean, 3.0 * g.stddev) == (0.0, pytest.approx(three_sigma, rel=1e-12)), field
    for field, half in (("lift_scale", 0.03), ("drag_scale", 0.06), ("mass_scale", 0.05), ("density_scale", 0.30)):
        u = getattr(d, field)
        assert (u.min, u.max) == (pytest.approx(1.0 - half), pytest.approx(1.0 + half)), field
    assert d.entry.altitude_m == 0.0


def test_apollo_cm_is_the_apollo10_compilation():
    v = load_vehicle("apollo_cm")
    assert (v.mass, v.reference_area) == (5498.22, 12.017) and v.representative
    cl, cd = v.aero.coefficients(math.radians(20.0), 25.0)
    assert (cl, cd) == (0.40815, 1.2569) and v.aero.coefficients(0.0, 0.5) == (cl, cd)  # trim: no alpha, no Mach
    assert cl / cd == pytest.approx(0.3247, abs=1e-4)


@pytest.mark.slow  # two more compiled predictors (about 10 s of a core on a new machine): CI's slow set
def test_constant_profile_predicts_the_linear_profile_with_sigma_f_equal_to_sigma_0(capsule):
    """guidance.bank_profile: constant flies |sigma| = sigma_0 to e_f: the same prediction as the
    linear profile whose sigma_f is sigma_0, and a different one from the packaged sigma_f."""
    sigma0 = math.radians(55.0)
    constant = FnpegSetup.from_scenario(_scenario({"guidance.bank_profile": "constant"}, "capsule_lu2008")).predict(CAPSULE_ENGAGED, sigma0)
    flat = FnpegSetup.from_scenario(_scenario({"guidance.bank_end_deg": 55.0}, "capsule_lu2008")).predict(CAPSULE_ENGAGED, sigma0)
    linear = capsule.predict(CAPSULE_ENGAGED, sigma0)
    assert constant.reached and flat.reached and linear.reached
    assert constant.range_m == pytest.approx(flat.range_m, rel=1e-12)
    np.testing.assert_allclose(constant.state, flat.state, rtol=1e-12)
    assert abs(linear.range_m - constant.range_m) > 10e3  # sigma_f 70 deg shortens the range


def test_bad_profile_names_the_field_and_the_allowed_values():
    with pytest.raises(ScenarioError, match=r"guidance\.bank_profile = 'quadratic'; allowed: 'linear' or 'constant'"):
        _scenario({"guidance.bank_profile": "quadratic"}, "capsule_lu2008").validate()


@pytest.mark.parametrize("profile, within_km", [("linear", 1.0), ("constant", 2.5)])
def test_capsule_nominal_flights_reach_the_target(profile, within_km):
    """The packaged capsule flight, nominal (no dispersion): the linear profile ends within 1 km
    (measured 0.46 km), the constant one within Lu (2008)'s 2.5 km (measured 1.60 km), each a
    verified success (box and every path limit)."""
    from drake_entry.diagrams.closed_loop import fly

    r = fly(_scenario({"guidance.bank_profile": profile}, "capsule_lu2008"))
    assert r.success, r.message
    assert r.errors["distance_m"] < within_km * 1e3


# -- the compiled predictor against Drake's native one ----------------------------------------

def _predictors(name, **kw):
    """(compiled, native) predictors of a packaged scenario's FNPEG, with ``kw`` changed."""
    s = FnpegSetup.from_scenario(load_scenario(name))
    g = load_scenario(name).guidance
    args = dict(sigma_f=s.sigma_f, e_f=s.e_f, alpha=s.alpha, step_s=g.predictor_step_s,
                constant=g.bank_profile == "constant", **kw)
    return tuple(predictor_module.Predictor(s.vehicle, s.planet, s.atmosphere, s.feedback, engine=engine, **args)
                 for engine in predictor_module.ENGINES)


@pytest.mark.parametrize("name, state", [("cav_h_fnpeg", ENGAGED), ("capsule_lu2008", CAPSULE_ENGAGED)])
def test_compiled_prediction_is_the_native_one(name, state):
    """The compiled predictor (one call: kernels generated from the same model expressions,
    models.kernels) against Drake's Simulator integrating the SymbolicVectorSystems: the
    derivatives agree to 1e-12 (relative) and the predicted flights, with the lift and drag
    scaled and both bank signs, end at the same stop, within 1e-6 m of range (measured: 2e-8 m
    over 5000-20 000 km) and 1e-6 s."""
    compiled, native = _predictors(name)
    assert compiled.engine == "compiled" and native.engine == "drake"
    params = [math.radians(55.0), compiled.energy(state) + 1e5, -1.0, 1.04, 0.97]
    np.testing.assert_allclose(compiled.derivatives([*state, 0.0], params),
                               native.derivatives([*state, 0.0], params), rtol=1e-12, atol=0.0)
    for deg, sign in ((15.0, 1.0), (40.0, -1.0), (60.0, 1.0), (85.0, -1.0)):
        a = compiled.predict(state, math.radians(deg), sign, (1.03, 0.98))
        b = native.predict(state, math.radians(deg), sign, (1.03, 0.98))
        assert (a.reached, a.reason) == (b.reached, b.reason) and a.reached, (deg, a.reason, b.reason)
        assert a.range_m == pytest.approx(b.range_m, abs=1e-6) and a.time_s == pytest.approx(b.time_s, abs=1e-6)
        np.testing.assert_allclose(a.state, b.state, rtol=1e-12, atol=1e-9)
    assert compiled.predictions == native.predictions == 4 and compiled.evaluations > 0


@pytest.mark.parametrize("kw, sigma0, reason", [
    ({"floor_m": 55e3}, 80.0, "below 55 km"),
    ({"ceiling_m": 62e3}, 0.0, "above 62 km"),
    ({"max_time_s": 300.0}, 60.0, "not reached in 300 s"),
])
def test_compiled_prediction_stops_as_the_native_one(kw, sigma0, reason):
    """The other stops, checked every ten steps on both engines: below the floor (the range to
    that point), above the ceiling and out of time (no range)."""
    compiled, native = _predictors("cav_h_fnpeg", **kw)
    a, b = (p.predict(ENGAGED, math.radians(sigma0)) for p in (compiled, native))
    assert not a.reached and reason in a.reason and a.reason == b.reason
    assert a.time_s == pytest.approx(b.time_s, abs=1e-9) and np.allclose(a.state, b.state, rtol=1e-12, atol=1e-9)
    if "floor_m" in kw:
        assert a.range_m == pytest.approx(b.range_m, abs=1e-6) and a.range_m > 0
    else:
        assert math.isnan(a.range_m) and math.isnan(b.range_m)


def test_compiled_prediction_names_a_non_finite_state():
    """A NaN state (here the entry speed) is a stop with its reason, never a traceback."""
    compiled, _ = _predictors("capsule_lu2008")
    p = compiled.predict([*CAPSULE_ENGAGED[:3], math.nan, *CAPSULE_ENGAGED[4:]], 0.5)
    assert not p.reached and math.isnan(p.range_m) and "NaN or infinite" in p.reason


def test_predictor_engine_is_checked():
    s = FnpegSetup.from_scenario(load_scenario("capsule_lu2008"))
    with pytest.raises(ScenarioError, match="engine = 'numba'; allowed: compiled, drake"):
        predictor_module.Predictor(s.vehicle, s.planet, s.atmosphere, s.feedback, sigma_f=s.sigma_f, e_f=s.e_f,
                                   alpha=s.alpha, engine="numba")
