import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd

from drake_entry.errors import ScenarioError
from drake_entry.models.atmosphere import ExponentialAtmosphere

# U.S. Standard Atmosphere 1976 reference densities (docs/models.md)
US76_TABLE = [(0.0, 1.2250), (11019.0, 0.36392), (20063.0, 0.088035), (32162.0, 0.013225),
              (47350.0, 1.4275e-3), (51413.0, 8.6161e-4), (71802.0, 6.4211e-5), (86000.0, 6.958e-6)]


@pytest.mark.parametrize("h, rho", US76_TABLE)
def test_us76_density_within_0p1_percent_of_the_standard_below_86km(us76, h, rho):
    assert us76.density(h) == pytest.approx(rho, rel=1e-3)


@pytest.mark.parametrize("h, rho", [(100e3, 5.604e-7), (120e3, 2.222e-8)])
def test_us76_density_within_1_percent_of_the_standard_86_to_150km(us76, h, rho):
    assert us76.density(h) == pytest.approx(rho, rel=1e-2)


def test_us76_sea_level_temperature_and_speed_of_sound(us76):
    rho, T, a = us76.properties(0.0)
    assert T == pytest.approx(288.15, abs=1e-9)
    assert a == pytest.approx(340.294, abs=1e-3)


def test_us76_matches_ussa1976_everywhere_to_1000km(us76):
    ussa1976 = pytest.importorskip("ussa1976")
    z = np.linspace(0.0, 1e6, 997)
    ds = ussa1976.compute(z=z, variables=["rho", "t"])
    err = us76.density(z) / ds["rho"].values - 1.0
    assert np.abs(err[z <= 86e3]).max() < 1e-3
    assert np.abs(err[(z > 86e3) & (z <= 150e3)]).max() < 1e-2
    assert np.abs(err).max() < 1e-2


@pytest.mark.parametrize("h", [5e3, 15e3, 40e3, 60e3, 80e3, 95e3, 130e3, 400e3])
def test_us76_density_derivatives_equal_finite_differences(us76, h):
    d = us76.density_derivatives(h)
    e = 0.5
    fd1 = (us76.density(h + e) - us76.density(h - e)) / (2 * e)
    fd2 = (us76.density(h + e) - 2 * us76.density(h) + us76.density(h - e)) / e**2
    assert d.d_h == pytest.approx(fd1, rel=1e-6)
    assert d.d_hh == pytest.approx(fd2, rel=1e-4)


def test_autodiff_density_gradient_is_the_analytic_derivative(us76):
    h = AutoDiffXd(42e3, np.array([1.0]))
    assert us76.density(h).derivatives()[0] == pytest.approx(us76.density_derivatives(42e3).d_h, rel=1e-12)


def test_vectorised_equals_scalar(us76):
    """The array path (vectorised by layer) gives every altitude what the scalar path gives,
    all six quantities, across every layer boundary and the 86 km table join."""
    from drake_entry.models.atmosphere import US76_LOWER_TOP, _us76_scalar

    h = np.concatenate([np.linspace(-5e3, 1000e3, 4001), [0.0, 11e3, 20e3, 32e3, 47e3, 51e3, 71e3],
                        [US76_LOWER_TOP, np.nextafter(US76_LOWER_TOP, 1e9)]])
    array = np.array(us76._evaluate(h))
    scalar = np.array([_us76_scalar(float(v)) for v in h]).T
    assert array == pytest.approx(scalar, rel=1e-13, abs=1e-300)
    lower_only = np.linspace(1e3, 80e3, 50)
    assert np.allclose(us76.density(lower_only), [us76.density(float(v)) for v in lower_only], rtol=1e-14)


def test_exponential_is_paper000_eq29():
    atm = ExponentialAtmosphere()
    assert atm.density(7200.0) == pytest.approx(1.2256 / np.e)
    d = atm.density_derivatives(10e3)
    assert d.d_h == pytest.approx(-d.value / 7200.0)


def test_altitude_outside_the_model_names_the_range(us76):
    with pytest.raises(ValueError, match=r"outside the us76 range \[-5000, 1e\+06\] m"):
        us76.density(1.2e6)


def test_bad_exponential_parameters_are_rejected():
    with pytest.raises(ValueError, match=r"scale_height = -1.0 m is out of range; allowed \[100, 1e6\]"):
        ExponentialAtmosphere(scale_height=-1.0)
    with pytest.raises(ValueError, match=r"scale_height = 1e\+300 m is out of range"):  # overflowed its square
        ExponentialAtmosphere(scale_height=1e300)


@pytest.mark.parametrize("h", [-4000.0, 0.0, 11000.0, 30500.0, 71000.0, 85999.0, 86001.0, 121500.0])
def test_air_data_fast_path_equals_properties_to_the_last_bit(us76, h):
    from drake_entry.models.atmosphere import DispersedAtmosphere

    for atm in (us76, ExponentialAtmosphere(), DispersedAtmosphere(us76, scale=1.07, amplitude=0.05,
                                                                     wavelength=9000.0, phase=0.3)):
        rho, _, a = atm.properties(h)
        assert atm.air_data(h) == (rho, a)
        rho_v, a_v = atm.air_data(np.array([h, h + 500.0]))  # other scalar types: properties
        assert rho_v[0] == rho and a_v[0] == a
    with pytest.raises(ValueError, match="outside"):
        us76.air_data(1.1e6)


# ---------------------------------------------------------------------------------------
# tabulated atmosphere (a user's GRAM/MSIS profile)
def _us76_table_csv(path, us76, heights):
    rho, T, _ = us76.properties(np.asarray(heights, float))
    rows = "\n".join(f"{h},{float(r)!r},{float(t)!r}" for h, r, t in zip(heights, rho, T))
    path.write_text(f"# US76 sampled every 2 km\naltitude_m,density_kg_m3,temperature_K\n{rows}\n")
    return path


def test_table_atmosphere_reproduces_its_table_and_interpolates_us76(tmp_path, us76):
    """Through its own rows exactly; between rows of a 2-km US76 sampling within 0.3 %
    (density) and 0.5 K (temperature): the splines are of ln rho and T."""
    from drake_entry.models.atmosphere import TableAtmosphere

    heights = np.arange(20e3, 80001.0, 2e3)
    atm = TableAtmosphere.from_csv(str(_us76_table_csv(tmp_path / "a.csv", us76, heights)))
    rho, T, _ = us76.properties(heights)
    assert atm.density(heights) == pytest.approx(rho, rel=1e-12)
    mid = heights[:-1] + 1e3
    r_mid, T_mid, _ = us76.properties(mid)
    assert np.abs(atm.density(mid) / r_mid - 1).max() < 3e-3
    assert np.abs(atm.temperature(mid) - T_mid).max() < 0.5
    assert atm.air_data(45e3)[0] == pytest.approx(atm.properties(45e3).rho, rel=1e-15)


@pytest.mark.parametrize("h", [25e3, 43.3e3, 61e3])
def test_table_atmosphere_derivatives_equal_finite_differences(tmp_path, us76, h):
    from drake_entry.models.atmosphere import TableAtmosphere

    atm = TableAtmosphere.from_csv(str(_us76_table_csv(tmp_path / "a.csv", us76, np.arange(20e3, 80001.0, 2e3))))
    d, t = atm.density_derivatives(h), atm.temperature_derivatives(h)
    e = 0.5
    assert d.d_h == pytest.approx((atm.density(h + e) - atm.density(h - e)) / (2 * e), rel=1e-6)
    assert d.d_hh == pytest.approx((atm.density(h + e) - 2 * atm.density(h) + atm.density(h - e)) / e**2, rel=1e-4)
    assert t.d_h == pytest.approx((atm.temperature(h + e) - atm.temperature(h - e)) / (2 * e), rel=1e-6, abs=1e-9)
    assert atm.density(AutoDiffXd(h, [1.0])).derivatives()[0] == pytest.approx(d.d_h, rel=1e-12)


@pytest.mark.parametrize("text, match", [
    ("altitude_m,density_kg_m3\n0,1.2\n", "expected altitude_m,density_kg_m3,temperature_K"),
    ("altitude_m,density_kg_m3,temperature_K\n0,1.2,288\n1000,1.1,281\n2000,1.0,275\n", "at least 4 rows"),
    ("altitude_m,density_kg_m3,temperature_K\n0,1.2,288\n1000,-1.1,281\n2000,1.0,275\n3000,0.9,268\n",
     r"density_kg_m3 = -1.1 in row 2 is out of range"),
    ("altitude_m,density_kg_m3,temperature_K\n0,1.2,288\n2000,1.1,281\n1000,1.0,275\n3000,0.9,268\n",
     "altitude_m must increase: row 3"),
    ("altitude_m,density_kg_m3,temperature_K\n0,1.2,288\n1000,x,281\n", "could not convert"),
])
def test_bad_atmosphere_tables_are_one_line_errors(tmp_path, text, match):
    from drake_entry.errors import ScenarioError
    from drake_entry.models.environment import AtmosphereSpec, atmosphere_from_spec

    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ScenarioError, match=match):
        atmosphere_from_spec(AtmosphereSpec(model="table", table_csv=str(path)))


def test_table_atmosphere_outside_its_altitudes_names_the_range(tmp_path, us76):
    from drake_entry.errors import ModelRangeError
    from drake_entry.models.atmosphere import TableAtmosphere

    atm = TableAtmosphere.from_csv(str(_us76_table_csv(tmp_path / "a.csv", us76, np.arange(20e3, 80001.0, 2e3))))
    with pytest.raises(ModelRangeError, match=r"outside the table range \[20000, 80000\]"):
        atm.density(90e3)
    with pytest.raises(ScenarioError, match="is not a file"):
        from drake_entry.models.environment import AtmosphereSpec, atmosphere_from_spec
        atmosphere_from_spec(AtmosphereSpec(model="table", table_csv=str(tmp_path / "missing.csv")))
