"""Horizontal winds (models.winds) and the air-relative aerodynamics (models.dynamics): the force
turns with the air-relative velocity and keeps its magnitude, a simulated flight's Mach and dynamic
pressure are the air-relative ones recomputed by hand from the logged state and wind, a head wind
raises q and a tail wind lowers it, the native plant equals the Python one, derivatives match
finite differences, the drawn wind has its specified statistics, and bad input is one line."""
import math

import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd
from pydrake.common import RandomGenerator
from pydrake.symbolic import Expression, Variable
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, LogVectorOutput

from drake_entry.errors import ScenarioError
from drake_entry.models import dynamics
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.dispersions import DispersionSpec, draw, validate
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle
from drake_entry.models.winds import WindProfile, WindSpec, WindyAtmosphere, draw_wind
from drake_entry.systems.native_plant import PlantProbe, add_plant

VEHICLE = load_vehicle("horus2b")
PLANET = Earth.spherical()
STILL = US76Atmosphere()
PROFILE = WindProfile([0.0, 12e3, 40e3, 70e3, 120e3], [5.0, 35.0, 10.0, 45.0, 20.0], [0.0, -8.0, 4.0, 15.0, 0.0])
WINDY = WindyAtmosphere(STILL, PROFILE)
X = [48e3, 0.3, 0.1, 4200.0, math.radians(-1.5), math.radians(35.0)]


def test_in_still_air_the_force_components_are_lift_cos_bank_lift_sin_bank_and_drag():
    got = dynamics.air_relative_force_components(X, 0.7, 30.0, 55.0, (0.0, 0.0))
    assert got == pytest.approx((30.0 * math.cos(0.7), 30.0 * math.sin(0.7), 55.0), rel=1e-14)


@pytest.mark.parametrize("wind", [(40.0, -25.0), (-120.0, 60.0), (0.0, 200.0)])
def test_the_aerodynamic_force_lies_along_and_across_the_air_relative_velocity(wind):
    """|force| = sqrt(L^2 + D^2); its component along v_a is -D; with zero bank it has no
    horizontal part normal to v_a."""
    L, D, bank = 30.0, 55.0, 0.4
    vertical, horizontal, drag_along = dynamics.air_relative_force_components(X, bank, L, D, wind)
    assert math.hypot(vertical, horizontal, drag_along) == pytest.approx(math.hypot(L, D), rel=1e-13)
    V, g, p = X[3], X[4], X[5]
    t = np.array([math.cos(g) * math.sin(p), math.cos(g) * math.cos(p), math.sin(g)])  # along v (east, north, up)
    n = np.array([-math.sin(g) * math.sin(p), -math.sin(g) * math.cos(p), math.cos(g)])
    h = np.array([math.cos(p), -math.sin(p), 0.0])
    force = -drag_along * t + vertical * n + horizontal * h
    va = V * t - np.array([wind[0], wind[1], 0.0])
    assert force @ va / np.linalg.norm(va) == pytest.approx(-D, rel=1e-12)
    v0, h0, d0 = dynamics.air_relative_force_components(X, 0.0, L, D, wind)
    f0 = -d0 * t + v0 * n + h0 * h
    side = np.cross(va, [0.0, 0.0, 1.0])  # horizontal, normal to v_a
    assert f0 @ side / np.linalg.norm(side) == pytest.approx(0.0, abs=1e-12)


def _flight(atmosphere, seconds=60.0):
    """60 s of the Python plant at bank 0.5 rad, alpha 30 deg: (times, states, conditions)."""
    builder = DiagramBuilder()
    plant, _, _ = add_plant(builder, VEHICLE, PLANET, atmosphere, initial_state=X, plant="python")
    for name, value in (("bank", 0.5), ("alpha", math.radians(30.0))):
        builder.Connect(builder.AddSystem(ConstantVectorSource([value])).get_output_port(), plant.GetInputPort(name))
    state = LogVectorOutput(plant.GetOutputPort("state"), builder, 5.0)
    cond = LogVectorOutput(plant.GetOutputPort("flight_conditions"), builder, 5.0)
    diagram = builder.Build()
    sim = Simulator(diagram)
    sim.AdvanceTo(seconds)
    ctx = sim.get_context()
    return (state.FindLog(ctx).sample_times(), state.FindLog(ctx).data().T, cond.FindLog(ctx).data().T)


def test_mach_and_dynamic_pressure_of_a_flight_are_the_air_relative_ones_recomputed_by_hand():
    _, states, conditions = _flight(WINDY)
    for x, c in zip(states, conditions):
        h, V, g, p = x[0], x[3], x[4], x[5]
        we, wn = np.interp(h, PROFILE.nodes, PROFILE.east), np.interp(h, PROFILE.nodes, PROFILE.north)
        va = math.sqrt((V * math.cos(g) * math.sin(p) - we) ** 2 + (V * math.cos(g) * math.cos(p) - wn) ** 2
                       + (V * math.sin(g)) ** 2)
        rho, T, a = STILL.properties(h)
        assert c[1] == pytest.approx(va / a, rel=1e-12)
        assert c[2] == pytest.approx(0.5 * rho * va * va, rel=1e-12)
        assert abs(va - V) > 1.0  # the wind is felt


@pytest.mark.parametrize("towards, q_change", [(-1.0, "higher"), (1.0, "lower")])
def test_a_head_wind_raises_the_dynamic_pressure_and_a_tail_wind_lowers_it(towards, q_change):
    psi = X[5]
    speed = 50.0 * towards  # the wind blows along (tail) or against (head) the heading
    air = WindyAtmosphere(STILL, WindProfile([0.0, 1e5], [speed * math.sin(psi)] * 2, [speed * math.cos(psi)] * 2))
    _, q_wind = PlantProbe(VEHICLE, PLANET, air, plant="python")(X, 0.5, math.radians(30))[1][1:3]
    _, q_still = PlantProbe(VEHICLE, PLANET, STILL, plant="python")(X, 0.5, math.radians(30))[1][1:3]
    ratio = ((X[3] - speed * math.cos(X[4])) ** 2 + (speed * math.sin(X[4])) ** 2) / X[3] ** 2
    assert q_wind / q_still == pytest.approx(ratio, rel=1e-12)
    assert (q_wind > q_still) == (q_change == "higher")


def test_the_native_plant_equals_the_python_plant_in_a_wind():
    native, python = (PlantProbe(VEHICLE, PLANET, WINDY, plant=p) for p in ("native", "python"))
    assert native.plant == "native"
    rng = np.random.default_rng(3)
    for _ in range(20):
        x = np.array(X) + rng.normal(0.0, [15e3, 0.1, 0.1, 1500.0, 0.02, 0.5])
        bank, alpha = rng.uniform(-1.2, 1.2), math.radians(rng.uniform(15, 40))
        (dn, cn), (dp, cp) = native(x, bank, alpha), python(x, bank, alpha)
        assert dn == pytest.approx(dp, rel=1e-12, abs=1e-15)
        assert cn == pytest.approx(cp, rel=1e-12)


def test_the_wind_equations_of_motion_match_finite_differences_in_autodiff():
    x0 = np.array(X)
    ad = [AutoDiffXd(v, np.eye(6)[i]) for i, v in enumerate(x0)]
    jac = np.array([d.derivatives() for d in dynamics.state_derivatives(ad, 0.5, 0.5, VEHICLE, PLANET, WINDY)])
    step = np.array([1.0, 1e-6, 1e-6, 1e-3, 1e-7, 1e-7])
    for i in range(6):
        up, dn = x0.copy(), x0.copy()
        up[i] += step[i]
        dn[i] -= step[i]
        fd = (dynamics.state_derivatives(list(up), 0.5, 0.5, VEHICLE, PLANET, WINDY)
              - dynamics.state_derivatives(list(dn), 0.5, 0.5, VEHICLE, PLANET, WINDY)) / (2 * step[i])
        assert jac[:, i] == pytest.approx(fd, rel=1e-5, abs=1e-9 * np.abs(jac).max())


def test_the_wind_profile_is_the_same_in_every_scalar_type():
    h = Variable("h")
    east, north = PROFILE(Expression(h))
    for z in (-100.0, 0.0, 5e3, 12e3, 39e3, 70e3, 119e3, 200e3):
        env = {h: z}
        assert (east.Evaluate(env), north.Evaluate(env)) == pytest.approx(PROFILE(z), rel=1e-14, abs=1e-12)
        ad = PROFILE(AutoDiffXd(z, [1.0]))
        assert ad[0].value() == pytest.approx(PROFILE(z)[0], rel=1e-14)
    slope = PROFILE(AutoDiffXd(20e3, [1.0]))[0].derivatives()[0]
    assert slope == pytest.approx((10.0 - 35.0) / 28e3, rel=1e-12)


WIND = WindSpec(altitude_km=[0.0, 12.0, 60.0, 100.0], east_mean_m_s=[5.0, 30.0, 40.0, 10.0],
                north_mean_m_s=[0.0, 0.0, -10.0, 0.0], sigma_m_s=[3.0, 8.0, 20.0, 25.0], large_scale_fraction=0.3,
                vertical_scale_km=4.0, step_km=0.5, top_km=110.0)


@pytest.fixture(scope="module")
def winds():
    return [draw_wind(WIND, RandomGenerator(seed)) for seed in range(10_000)]


def test_the_drawn_wind_has_the_specified_mean_and_sigma_profile(winds):
    h = winds[0].nodes
    east = np.array([w.east for w in winds])
    north = np.array([w.north for w in winds])
    sigma = np.interp(h / 1e3, WIND.altitude_km, WIND.sigma_m_s)
    for values, mean in ((east, WIND.east_mean_m_s), (north, WIND.north_mean_m_s)):
        assert values.std(axis=0) == pytest.approx(sigma, rel=0.03)
        expected = np.interp(h / 1e3, WIND.altitude_km, mean)
        assert np.all(np.abs(values.mean(axis=0) - expected) < 4 * sigma / math.sqrt(len(winds)))
    k = int(np.searchsorted(h, 50e3))
    assert abs(np.corrcoef(east[:, k], north[:, k])[0, 1]) < 0.03  # independent components
    j = int(np.searchsorted(h, 105e3))  # constant sigma above 100 km: corr = f + (1 - f) exp(-dh / L)
    expected = 0.3 + 0.7 * math.exp(-5.0 / 4.0)
    assert np.corrcoef(east[:, j - 10], east[:, j])[0, 1] == pytest.approx(expected, abs=0.02)


def test_a_sample_draws_its_wind_and_records_it():
    spec = DispersionSpec(winds=WIND)
    d = draw(spec, RandomGenerator(7))
    air = d.atmosphere(STILL)
    assert air.has_wind and not STILL.has_wind
    assert air.wind(50e3) == pytest.approx((d.columns()["disp_wind_east_50km"], d.columns()["disp_wind_north_50km"]))
    assert draw(spec, RandomGenerator(7)).columns() == d.columns()


@pytest.mark.parametrize("field, value, message", [
    ("altitude_km", [0.0, 50.0, 20.0, 100.0], "winds.altitude_km = [0.0, 50.0, 20.0, 100.0] must be finite and sorted"),
    ("sigma_m_s", [3.0, -1.0, 20.0, 25.0], "winds.sigma_m_s[1] = -1.0 is out of range; allowed: [0, 60] m/s"),
    ("east_mean_m_s", [5.0, 30.0, 400.0, 10.0], "winds.east_mean_m_s[2] = 400.0 is out of range"),
    ("north_mean_m_s", [0.0, 1.0], "winds.north_mean_m_s needs one value per altitude (4), got 2"),
    ("large_scale_fraction", 1.5, "winds.large_scale_fraction = 1.5 is out of range; allowed: [0, 1]"),
    ("vertical_scale_km", float("nan"), "winds.vertical_scale_km = nan is out of range"),
])
def test_bad_wind_input_is_one_line_naming_the_field(field, value, message):
    import dataclasses as dc

    spec = DispersionSpec(winds=dc.replace(WIND, **{field: value}))
    with pytest.raises(ScenarioError) as e:
        validate(spec)
    assert message in str(e.value) and "\n" not in str(e.value)
