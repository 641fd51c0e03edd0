"""Density and temperature perturbations along the flight (models.atmosphere_perturbations) and
the sample's perturbed atmosphere (models.atmosphere.PerturbedAtmosphere): the process has the
1-sigma profile and the correlation against separation it is specified with, the atmosphere
applies it in every scalar type, and bad input is one line naming the field."""
import math

import numpy as np
import pytest
from pydrake.common import RandomGenerator

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import PerturbedAtmosphere, US76Atmosphere
from drake_entry.models.atmosphere_perturbations import AtmospherePerturbationSpec, draw_profiles

SPEC = AtmospherePerturbationSpec(altitude_km=[0.0, 40.0, 80.0, 120.0], density_sigma=[0.01, 0.03, 0.08, 0.15],
                                  temperature_sigma=[0.005, 0.01, 0.03, 0.05], large_scale_fraction=0.4,
                                  vertical_scale_km=6.0, density_temperature_correlation=-0.6, step_km=0.5,
                                  top_km=130.0)


@pytest.fixture(scope="module")
def profiles():
    """10 000 independent samples' profiles (each from its own generator, as a campaign draws)."""
    draws = [draw_profiles(SPEC, RandomGenerator(seed)) for seed in range(10_000)]
    h = draws[0][0]
    return h, np.array([d[1] for d in draws]), np.array([d[2] for d in draws])


def test_the_perturbations_have_the_specified_sigma_profile(profiles):
    """At every node the sample standard deviation is the specified 1-sigma (linear between the
    given altitudes) to 3 %, and the mean is zero to 4 standard errors."""
    h, d_rho, d_T = profiles
    for q, sigma in ((d_rho, SPEC.density_sigma), (d_T, SPEC.temperature_sigma)):
        expected = np.interp(h / 1e3, SPEC.altitude_km, sigma)
        assert q.std(axis=0) == pytest.approx(expected, rel=0.03)
        assert np.all(np.abs(q.mean(axis=0)) < 4 * expected / math.sqrt(q.shape[0]))


@pytest.mark.parametrize("separation_km", [0.5, 3.0, 6.0, 15.0, 40.0])
def test_the_correlation_against_separation_is_the_large_scale_share_plus_the_markov_decay(profiles, separation_km):
    """corr(d(h), d(h + dh)) = f + (1 - f) exp(-dh / L) where sigma is constant (above 120 km it is),
    to 0.02 over 10 000 samples."""
    h, d_rho, _ = profiles
    i = int(np.searchsorted(h, 120e3))
    j = int(np.searchsorted(h, 120e3 + separation_km * 1e3)) if 120 + separation_km <= 130 else None
    if j is None:  # beyond the top: compare lower down, where sigma varies linearly, with the same law
        i, j = int(np.searchsorted(h, 60e3)), int(np.searchsorted(h, (60 + separation_km) * 1e3))
    expected = SPEC.large_scale_fraction + (1 - SPEC.large_scale_fraction) * math.exp(-separation_km /
                                                                                       SPEC.vertical_scale_km)
    assert np.corrcoef(d_rho[:, i], d_rho[:, j])[0, 1] == pytest.approx(expected, abs=0.02)


def test_density_and_temperature_perturbations_carry_their_correlation(profiles):
    h, d_rho, d_T = profiles
    k = int(np.searchsorted(h, 70e3))
    assert np.corrcoef(d_rho[:, k], d_T[:, k])[0, 1] == pytest.approx(SPEC.density_temperature_correlation, abs=0.02)


def test_a_profile_depends_on_the_sample_s_generator_alone():
    a = draw_profiles(SPEC, RandomGenerator(5))
    b = draw_profiles(SPEC, RandomGenerator(5))
    c = draw_profiles(SPEC, RandomGenerator(6))
    assert np.array_equal(a[1], b[1]) and not np.array_equal(a[1], c[1])


def test_the_perturbed_atmosphere_applies_the_profile_in_every_scalar_type():
    """rho (1 + d_rho) and T (1 + d_T), so a = a_base sqrt(1 + d_T); linear between nodes, held
    beyond them; the symbolic form (the native plant's) equals the float one; the altitude
    derivatives agree with central differences."""
    from pydrake.symbolic import Expression, Variable

    base = US76Atmosphere()
    nodes, d_rho, d_T = [20e3, 40e3, 60e3, 80e3], [0.05, -0.04, 0.10, 0.02], [0.01, -0.02, 0.03, 0.0]
    air = PerturbedAtmosphere(base, nodes, d_rho, d_T)
    for h, fr, ft in ((30e3, 0.005, -0.005), (10e3, 0.05, 0.01), (90e3, 0.02, 0.0), (60e3, 0.10, 0.03)):
        rho, a = air.air_data(h)
        rho0, a0 = base.air_data(h)
        assert rho == pytest.approx(rho0 * (1 + fr), rel=1e-12) and a == pytest.approx(a0 * math.sqrt(1 + ft), rel=1e-12)
    x = Variable("h")
    with np.errstate(invalid="ignore"):
        rho_s, T_s = air.symbolic_profile(Expression(x))
    for h in (15e3, 33e3, 59e3, 61e3, 85e3):
        rho, a = air.air_data(h)
        T = a * a / (air.gamma * air.gas_constant)
        assert rho_s.Evaluate({x: h}) == pytest.approx(rho, rel=1e-12)
        assert T_s.Evaluate({x: h}) == pytest.approx(T, rel=1e-12)
    d, t = air.derivatives(45e3)
    step = 1.0
    assert d.d_h == pytest.approx((air.density(45e3 + step) - air.density(45e3 - step)) / (2 * step), rel=1e-6)
    assert t.d_h == pytest.approx((air.temperature(45e3 + step) - air.temperature(45e3 - step)) / (2 * step), rel=1e-6)


@pytest.mark.parametrize("field, value, match", [
    ("density_sigma", "[0.01, -0.02]", r"density_sigma\[1\] = -0.02 is out of range"),
    ("temperature_sigma", "[0.01, 0.3]", r"temperature_sigma\[1\] = 0.3 is out of range"),
    ("altitude_km", "[40, 20]", "altitude_km = .* increasing"),
    ("density_temperature_correlation", "1.5", r"density_temperature_correlation = 1.5 is out of range"),
    ("large_scale_fraction", "-0.1", "large_scale_fraction = -0.1 is out of range"),
    ("density_sigma", "[0.01]", "density_sigma needs one value per altitude"),
])
def test_bad_perturbation_input_is_one_line_naming_the_field(field, value, match):
    from drake_entry.scenario import apply_overrides, load_scenario

    scenario = load_scenario("horus2b")
    apply_overrides(scenario, {"dispersions.atmosphere_perturbations": "{altitude_km: [0, 100], density_sigma: "
                                                                       "[0.01, 0.05], temperature_sigma: [0, 0]}"})
    with pytest.raises(ScenarioError, match=f"dispersions.atmosphere_perturbations.{match}"):
        apply_overrides(scenario, {f"dispersions.atmosphere_perturbations.{field}": value})


def test_a_sample_with_perturbations_flies_them_on_the_native_plant_and_records_them():
    """A drawn sample's plant flies its profile natively; its row records the perturbation at 30,
    50 and 70 km; a scenario without perturbations draws what it drew before."""
    import dataclasses as dc

    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, build_closed_loop
    from drake_entry.guidance.bank_profile.spec import BankProfile
    from drake_entry.models.dispersions import draw
    from drake_entry.scenario import load_scenario

    scenario = load_scenario("horus2b")
    plain = draw(scenario.dispersions, RandomGenerator(4))
    scenario.guidance = BankProfile(terminal_altitude_km=26.5, bank_start_deg=60.0, bank_end_deg=50.0)
    scenario.dispersions.atmosphere_perturbations = dc.replace(SPEC)
    scenario.validate()
    d = draw(scenario.dispersions, RandomGenerator(4))
    assert np.array_equal(d.entry_delta, plain.entry_delta) and d.nav_seed == plain.nav_seed
    built = build_closed_loop(ClosedLoopSetup.from_scenario(scenario), draw=d)
    assert built.plant == "native"
    columns = d.columns()
    assert {"disp_drho_30km", "disp_dT_50km", "disp_drho_70km"} <= set(columns)
    assert columns["disp_drho_50km"] == pytest.approx(np.interp(50e3, d.perturbation_altitude_m, d.density_perturbation))


def test_the_report_lists_the_perturbation_profiles():
    import dataclasses as dc

    from drake_entry.campaign.report import _dispersions
    from drake_entry.scenario import load_scenario

    scenario = load_scenario("horus2b")
    scenario.dispersions.atmosphere_perturbations = dc.replace(SPEC)
    text = _dispersions(scenario)
    assert ("| density perturbation along the flight | 0 | per-flight part 40 % of the variance, the rest correlated "
            "over 6 km of altitude | 1σ 0.01 at 0 km, 0.03 at 40 km, 0.08 at 80 km, 0.15 at 120 km | fraction |") in text
    assert "correlation with density -0.6" in text
