import numpy as np
import pytest
from pydrake.common import RandomGenerator

from drake_entry.errors import ScenarioError
from drake_entry.models.aerodynamics import ScaledAero
from drake_entry.models.atmosphere import DispersedAtmosphere
from drake_entry.models.dispersions import DispersionSpec, draw
from drake_entry.scenario import load_scenario


def test_dispersed_density_derivatives_equal_finite_differences(us76):
    atm = DispersedAtmosphere(us76, scale=1.07, amplitude=0.05, wavelength=6000.0, phase=0.3)
    h, e = 41234.0, 0.5
    d, _ = atm.derivatives(h)
    assert d.value == pytest.approx(us76.density(h) * 1.07 * (1 + 0.05 * np.sin(2 * np.pi * h / 6000 + 0.3)))
    assert d.d_h == pytest.approx((atm.density(h + e) - atm.density(h - e)) / (2 * e), rel=1e-6)
    assert d.d_hh == pytest.approx((atm.density(h + e) - 2 * atm.density(h) + atm.density(h - e)) / e**2, rel=1e-3)
    assert atm.temperature(h) == us76.temperature(h)


def test_scaled_aero_scales_coefficients_and_drag_partials(horus):
    s = ScaledAero(horus.aero, lift_scale=0.9, drag_scale=1.1)
    cl, cd = s.coefficients(0.6, 8.0)
    cl0, cd0 = horus.aero.coefficients(0.6, 8.0)
    assert (cl, cd) == pytest.approx((0.9 * cl0, 1.1 * cd0))
    d, cl_v = s.drag_derivatives(0.6, 8.0)
    d0, _ = horus.aero.drag_derivatives(0.6, 8.0)
    assert d.d_alpha == pytest.approx(1.1 * d0.d_alpha) and cl_v == pytest.approx(cl)


def test_draws_depend_only_on_the_generator_seed():
    spec = load_scenario("horus2b").dispersions
    a, b, c = draw(spec, RandomGenerator(9)), draw(spec, RandomGenerator(9)), draw(spec, RandomGenerator(10))
    assert a.columns() == b.columns() and a.columns() != c.columns()
    assert abs(a.columns()["disp_dh_m"]) <= 250.0 and abs(a.columns()["disp_dV_m_s"]) <= 15.0


def test_yaml_dispersions_with_drake_distributions(tmp_path):
    from importlib import resources

    text = resources.files("drake_entry").joinpath("scenarios/horus2b.yaml").read_text()
    text = text.replace("dispersions:", "dispersions:\n  density_scale: !Gaussian {mean: 1.0, stddev: 0.05}\n"
                                        "  mass_scale: 1.02\n"
                                        "  nav_bias: !UniformVector {min: [-50, 0, 0, -1, 0, 0], max: [50, 0, 0, 1, 0, 0]}")
    p = tmp_path / "s.yaml"
    p.write_text(text)
    s = load_scenario(str(p))
    d = draw(s.dispersions, RandomGenerator(1))
    assert d.mass_scale == 1.02 and d.density_scale != 1.0 and abs(d.nav_bias[0]) <= 50.0
    p.write_text(text.replace("max: [50, 0, 0, 1, 0, 0]", "max: [50, 0, 0, 1, 0]").replace(
        "min: [-50, 0, 0, -1, 0, 0]", "min: [-50, 0, 0, -1, 0]"))
    with pytest.raises(ScenarioError, match="nav_bias needs 6 entries"):
        load_scenario(str(p))


@pytest.mark.parametrize("scale, miss_km, inside", [(0.9, 1.0, True), (1.1, 1.0, False)])
def test_density_bias_is_absorbed_by_sensed_drag_feedback(scale, miss_km, inside):
    """Guidance and tracking act on the accelerometer's drag, so a +-10 % density bias the
    nominal models do not know still reaches E_f near the target (measured: 0.32 km at -10 %,
    0.21 km at +10 %; 1.8 and 9.2 km when the sensed drag scaled the model's b_D too; feeding
    back the model's drag instead missed by 207 km at -10 %). At +10 % the flight ends 2.05 km
    above the box's centre, outside its +-2 km: the guidance aims 1.5 km up, and the denser air
    holds the same drag about H ln 1.1 = 0.7 km higher."""
    from drake_entry.diagrams.closed_loop import fly

    s = load_scenario("horus2b")
    res = fly(s, draw=draw(DispersionSpec(density_scale=scale), RandomGenerator(0)))
    assert "energy" in res.trajectory.reason and res.guidance.active, res.message
    assert res.errors["distance_m"] < miss_km * 1e3
    assert res.success is inside and res.box["distance"]["inside"]
    assert res.box["altitude"]["inside"] is inside
    tr = res.trajectory
    assert tr.column("heat_flux").max() <= 530e3 and tr.column("normal_load").max() <= 2.5


@pytest.mark.parametrize("field, edge, outside", [
    ("density_scale", 1e-3, 0.0), ("density_scale", 50.0, None),
    ("density_wave_amplitude", -0.999, -1.0), ("density_wave_amplitude", 0.999, 1.0),
    ("lift_scale", 1e-3, 0.0), ("drag_scale", 1e-3, 0.0), ("mass_scale", 1e-3, 0.0), ("mass_scale", 50.0, None),
])
def test_a_dispersion_the_scenario_accepts_at_its_bound_the_models_accept(field, edge, outside):
    """One validation per input: a value at the edge of what the scenario check accepts is drawn,
    built into the sample's closed loop (dispersed atmosphere, aerodynamics, mass) and gives finite
    equations of motion at the entry state; the value just outside is refused by the scenario
    check, naming the field, before any sample."""
    import dataclasses as dc

    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, build_closed_loop
    from drake_entry.guidance.bank_profile.spec import BankProfile

    scenario = load_scenario("horus2b")
    scenario.guidance = BankProfile(terminal_altitude_km=26.5, bank_start_deg=60.0, bank_end_deg=50.0)
    scenario.simulation = dc.replace(scenario.simulation, plant="python")
    setattr(scenario.dispersions, field, edge)
    scenario.validate()
    d = draw(scenario.dispersions, RandomGenerator(3))
    built = build_closed_loop(ClosedLoopSetup.from_scenario(scenario), draw=d)
    context = built.diagram.CreateDefaultContext()
    derivatives = built.diagram.EvalTimeDerivatives(context).CopyToVector()
    assert derivatives.size >= 6 and np.all(np.isfinite(derivatives))
    if outside is not None:
        setattr(scenario.dispersions, field, outside)
        with pytest.raises(ScenarioError, match=f"dispersions.{field}"):
            scenario.validate()


def _regime_aero(**kw):
    from drake_entry.models.aerodynamics import RegimeAero
    from drake_entry.models.vehicles import load_vehicle

    return RegimeAero(load_vehicle("horus2b").aero, **kw)


def test_regime_aero_flies_each_regime_s_error_and_blends_them_continuously():
    """At a regime's middle the coefficients are the base's times (1 + its error); across a
    boundary they change linearly over blend_mach (half way at the boundary) and nowhere jump."""
    errors_l, errors_d = (0.10, 0.20, -0.05, 0.04), (-0.10, 0.15, 0.05, -0.03)
    aero = _regime_aero(lift_errors=errors_l, drag_errors=errors_d, boundaries=(0.8, 1.2, 5.0), blend_mach=0.2)
    base = aero.base
    for mach, k in ((0.5, 0), (1.0, 1), (3.0, 2), (10.0, 3)):
        cl, cd = aero.coefficients(0.3, mach)
        cl0, cd0 = base.coefficients(0.3, mach)
        assert cl == pytest.approx(cl0 * (1 + errors_l[k]), rel=1e-14)
        assert cd == pytest.approx(cd0 * (1 + errors_d[k]), rel=1e-14)
    assert aero.factors(5.0) == pytest.approx((1 + (errors_l[2] + errors_l[3]) / 2, 1 + (errors_d[2] + errors_d[3]) / 2))
    mach = np.linspace(0.3, 8.0, 20001)
    kl, kd = aero.factors(mach)
    steepest = 0.35 / 0.2  # the largest error change over the blend width
    assert np.max(np.abs(np.diff(kl))) <= steepest * (mach[1] - mach[0]) * (1 + 1e-9)
    assert np.max(np.abs(np.diff(kd))) <= steepest * (mach[1] - mach[0]) * (1 + 1e-9)


def test_regime_aero_trim_error_shifts_the_angle_of_attack_and_is_the_same_in_every_scalar():
    """A trim error dalpha gives the base's coefficients at alpha + dalpha; the symbolic form (what
    the native plant evaluates) equals the float one."""
    from pydrake.symbolic import Expression, Variable

    aero = _regime_aero(lift_errors=(0.0,) * 4, drag_errors=(0.0,) * 4, trim_alpha=np.radians(0.7))
    assert aero.coefficients(0.4, 7.0) == pytest.approx(aero.base.coefficients(0.4 + np.radians(0.7), 7.0),
                                                        rel=1e-14)
    shaped = _regime_aero(lift_errors=(0.1, 0.2, 0.05, -0.04), drag_errors=(-0.1, 0.1, 0.02, 0.03),
                          trim_alpha=np.radians(-0.4))
    a, m = Variable("alpha"), Variable("mach")
    with np.errstate(invalid="ignore"):  # numpy's object loop reports a stale FP flag under pytest only
        cl_s, cd_s = shaped.coefficients(Expression(a), Expression(m))  # as the native plant passes them
    for alpha, mach in ((0.35, 0.79), (0.2, 1.15), (0.5, 4.95), (0.6, 12.0)):
        env = {a: alpha, m: mach}
        cl, cd = shaped.coefficients(alpha, mach)
        assert cl_s.Evaluate(env) == pytest.approx(cl, rel=1e-12) and cd_s.Evaluate(env) == pytest.approx(cd, rel=1e-12)


def test_regime_errors_are_drawn_with_their_sigmas_and_correlation():
    """Over 10 000 draws the per-regime C_L and C_D errors have the stated 1-sigma (2 % of it) and
    correlation (0.02), the trim error its 1-sigma; the draws before them are those of a scenario
    without regime errors (a scenario that does not use them draws as before)."""
    from drake_entry.models.dispersions import AeroRegimeDispersionSpec

    plain = load_scenario("horus2b").dispersions
    spec = load_scenario("horus2b").dispersions
    spec.aero_regimes = AeroRegimeDispersionSpec(lift_sigma=[0.05, 0.10, 0.04, 0.03],
                                                 drag_sigma=[0.04, 0.12, 0.05, 0.02],
                                                 correlation=[0.0, 0.6, -0.5, 0.9], trim_alpha_sigma_deg=0.5)
    draws = [draw(spec, RandomGenerator(seed)) for seed in range(10_000)]
    first = draw(plain, RandomGenerator(0))
    assert np.array_equal(draws[0].entry_delta, first.entry_delta) and draws[0].nav_seed == first.nav_seed
    lift = np.array([d.aero_lift_errors for d in draws])
    drag = np.array([d.aero_drag_errors for d in draws])
    assert lift.std(axis=0) == pytest.approx([0.05, 0.10, 0.04, 0.03], rel=0.02)
    assert drag.std(axis=0) == pytest.approx([0.04, 0.12, 0.05, 0.02], rel=0.02)
    rho = [np.corrcoef(lift[:, k], drag[:, k])[0, 1] for k in range(4)]
    assert rho == pytest.approx([0.0, 0.6, -0.5, 0.9], abs=0.02)
    assert np.degrees([d.trim_alpha for d in draws]).std() == pytest.approx(0.5, rel=0.02)
    assert {"disp_dCL_transonic", "disp_dCD_hypersonic", "disp_trim_alpha_deg"} <= set(draws[0].columns())


def test_entry_delivery_covariance_is_drawn_with_its_covariance():
    """A correlated 6 x 6 delivery covariance (table units) is reproduced by 10 000 draws to 3 % of
    each standard deviation and 0.02 in correlation, in SI radians and metres."""
    sd = np.array([300.0, 0.05, 0.04, 12.0, 0.02, 0.03])
    corr = np.eye(6)
    corr[0, 3] = corr[3, 0] = -0.8  # altitude against speed
    corr[4, 0] = corr[0, 4] = 0.5
    cov = corr * np.outer(sd, sd)
    spec = load_scenario("horus2b").dispersions
    spec.entry = type(spec.entry)()  # no uniform box: the covariance alone
    spec.entry_covariance = cov.tolist()
    deltas = np.array([draw(spec, RandomGenerator(seed)).entry_delta for seed in range(10_000)])
    table = deltas / np.array([1.0, np.pi / 180, np.pi / 180, 1.0, np.pi / 180, np.pi / 180])
    assert table.std(axis=0) == pytest.approx(sd, rel=0.03)
    c = np.corrcoef(table.T)
    assert c[0, 3] == pytest.approx(-0.8, abs=0.02) and c[0, 4] == pytest.approx(0.5, abs=0.02)
    assert abs(c[1, 2]) < 0.03


@pytest.mark.parametrize("field, value, match", [
    ("aero_regimes.lift_sigma", "[0.05, -0.01, 0.0, 0.0]", r"lift_sigma\[1\] \(transonic\) = -0.01 is out of range"),
    ("aero_regimes.drag_sigma", "[0.05, 0.3, 0.0, 0.0]", r"drag_sigma\[1\] \(transonic\) = 0.3 is out of range"),
    ("aero_regimes.correlation", "[0.0, 1.2, 0.0, 0.0]", r"correlation\[1\] \(transonic\) = 1.2 .* allowed: \[-1, 1\]"),
    ("aero_regimes.mach_boundaries", "[0.8, 5.0, 1.2]", "mach_boundaries = .* increasing"),
    ("aero_regimes.lift_sigma", "[0.05, 0.05]", "lift_sigma needs 4 values"),
    ("aero_regimes.blend_mach", "0.9", "blend_mach = 0.9 is out of range"),
    ("entry_covariance", "[[1, 2, 0, 0, 0, 0], [2, 1, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0], "
                         "[0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1]]", "entry_covariance is not positive semi-definite"),
    ("entry_covariance", "[[1, 0.5, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0], "
                         "[0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1]]", "entry_covariance is not symmetric"),
    ("entry_covariance", "[[1, 0], [0, 1]]", "entry_covariance needs 6 rows of 6 values"),
])
def test_bad_aero_regime_and_covariance_inputs_are_one_line_naming_the_field(field, value, match):
    from drake_entry.scenario import apply_overrides

    scenario = load_scenario("horus2b")
    if field.startswith("aero_regimes."):
        apply_overrides(scenario, {"dispersions.aero_regimes": "{}"})
    prefix = "dispersions.aero_regimes." if field.startswith("aero_regimes.") else "dispersions."
    with pytest.raises(ScenarioError, match=prefix + match):
        apply_overrides(scenario, {f"dispersions.{field}": value})


def test_a_sample_with_regime_errors_flies_them_on_the_native_plant():
    """A drawn sample's plant carries its regime errors and trim error, natively: the closed loop
    builds on the native plant (their symbolic form) and its aerodynamics are the draw's."""
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, build_closed_loop
    from drake_entry.guidance.bank_profile.spec import BankProfile
    from drake_entry.models.dispersions import AeroRegimeDispersionSpec

    scenario = load_scenario("horus2b")
    scenario.guidance = BankProfile(terminal_altitude_km=26.5, bank_start_deg=60.0, bank_end_deg=50.0)
    scenario.dispersions.aero_regimes = AeroRegimeDispersionSpec(lift_sigma=[0.05] * 4, drag_sigma=[0.05] * 4,
                                                                 trim_alpha_sigma_deg=1.0)
    scenario.validate()
    d = draw(scenario.dispersions, RandomGenerator(11))
    built = build_closed_loop(ClosedLoopSetup.from_scenario(scenario), draw=d)
    assert built.plant == "native"
    aero = d.aerodynamics(scenario.make_vehicle().aero)
    assert aero.trim_alpha == d.trim_alpha != 0.0 and aero.lift_errors == d.aero_lift_errors


def test_the_report_lists_regime_errors_and_the_delivery_covariance():
    """The campaign report's dispersion table names each regime's 1-sigma and correlation, the
    trim error, each delivered 1-sigma and the correlated pairs."""
    from drake_entry.campaign.report import _dispersions
    from drake_entry.models.dispersions import AeroRegimeDispersionSpec

    scenario = load_scenario("horus2b")
    scenario.dispersions.aero_regimes = AeroRegimeDispersionSpec(lift_sigma=[0.0, 0.1, 0.05, 0.03],
                                                                 drag_sigma=[0.0, 0.12, 0.05, 0.02],
                                                                 correlation=[0.0, 0.5, 0.0, -0.3],
                                                                 trim_alpha_sigma_deg=0.5)
    cov = np.diag([1e4, 1e-4, 1e-4, 100.0, 1e-4, 1e-4])
    cov[0, 3] = cov[3, 0] = -800.0
    scenario.dispersions.entry_covariance = cov.tolist()
    text = _dispersions(scenario)
    assert "| C_L and C_D relative errors, transonic (Mach 0.8 to 1.2) | 0 | Gaussian, correlation 0.5 | " \
           "1σ 0.1 and 0.12 | - |" in text
    assert "subsonic" not in text  # not dispersed
    assert "| trim angle-of-attack error | 0 | Gaussian | 1σ 0.5 | deg |" in text
    assert "| entry speed (delivery covariance) | 0 | Gaussian, correlated | 1σ 10 | m/s |" in text
    assert "altitude-speed -0.80" in text


def test_force_dispersions_name_what_changes_the_lift_or_drag():
    """Only the entry and navigation dispersed (HORUS-2B): none. A density, aerodynamic or mass
    scale whose distribution leaves 1 (a constant 1.02 too), a density wave, regimes with a sigma,
    perturbations or winds are named; a constant scale of 1 is not."""
    import dataclasses as dc

    from pydrake.common import schema

    from drake_entry.models.dispersions import AeroRegimeDispersionSpec, force_dispersions

    assert force_dispersions(load_scenario("horus2b").dispersions) == []
    spec = DispersionSpec(density_scale=schema.Gaussian(mean=1.0, stddev=0.05), lift_scale=1.0,
                          drag_scale=schema.Deterministic(value=1.0), mass_scale=1.02)
    assert force_dispersions(spec) == ["density_scale", "mass_scale"]
    spec = dc.replace(DispersionSpec(), density_wave_amplitude=schema.Uniform(min=-0.01, max=0.01),
                      aero_regimes=AeroRegimeDispersionSpec())
    assert force_dispersions(spec) == ["density_wave_amplitude"]  # regimes without a sigma disperse nothing
    spec.aero_regimes.drag_sigma = [0.0, 0.0, 0.05, 0.05]
    assert force_dispersions(spec) == ["density_wave_amplitude", "aero_regimes"]
    assert force_dispersions(load_scenario("capsule_lu2008").dispersions) == [
        "density_scale", "lift_scale", "drag_scale", "mass_scale"]
