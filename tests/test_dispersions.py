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


@pytest.mark.parametrize("scale, miss_km", [(0.9, 3.0), (1.1, 12.0)])
def test_density_bias_is_absorbed_by_sensed_drag_feedback(scale, miss_km):
    """Guidance and tracking act on the accelerometer's drag, so a +-10 % density bias the
    nominal models do not know still reaches E_f near the target (measured: 1.8 km at -10 %,
    9.2 km at +10 %; feeding back the model's drag instead missed by 207 km at -10 %)."""
    from drake_entry.diagrams.closed_loop import fly

    s = load_scenario("horus2b")
    res = fly(s, draw=draw(DispersionSpec(density_scale=scale), RandomGenerator(0)))
    assert "energy" in res.trajectory.reason and res.guidance.active, res.message
    assert res.errors["distance_m"] < miss_km * 1e3
    # success means inside the mission's box (2 km, paper 000 Table 1): +10 % misses it
    assert res.success == (res.errors["distance_m"] <= 2e3) and res.box["distance"]["inside"] == res.success
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
