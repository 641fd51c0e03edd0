import numpy as np
import pytest

from drake_entry.models.constraints import HeatFlux, PathLimits, make_heat_flux, normal_load_factor


def test_chapman_equals_paper001_normalised_form():
    """docs/references.md: C1 = 5.28137e-5 is paper 001 eq. 9 with c* = 1.1097e8, n = 0.5, m = 3.15."""
    a, b = HeatFlux.chapman(0.8), HeatFlux.normalised(0.8)
    assert a(1e-4, 6000.0) == pytest.approx(b(1e-4, 6000.0), rel=1e-3)


def test_chapman_heat_flux_value_paper000_eq34():
    """Paper 000 eq. 34 with its constants (R_N 0.8 m, C_1 5.28137e-5, m 3.15) against
    Chapman's classical dimensional form, q = 11 030 W/cm^2 (R_N / 1 m)^-1/2 (rho / 1.225)^1/2
    (V / 7905 m/s)^3.15 (Chapman 1958, NACA TN 4276; the constant varies by about 1 % between
    sources): within 1 % (0.61 % at rho 2e-5 kg/m^3, 7 km/s), and its scaling laws exactly."""
    chapman = HeatFlux.chapman(0.8)
    q = chapman(2e-5, 7000.0)
    classical = 1.103e8 / np.sqrt(0.8) * np.sqrt(2e-5 / 1.225) * (7000.0 / 7905.0) ** 3.15
    assert q == pytest.approx(classical, rel=0.01)
    assert chapman(8e-5, 7000.0) == pytest.approx(2.0 * q, rel=1e-12)  # sqrt(rho)
    assert chapman(2e-5, 3500.0) == pytest.approx(q / 2.0 ** 3.15, rel=1e-12)  # V^3.15
    assert HeatFlux.chapman(3.2)(2e-5, 7000.0) == pytest.approx(q / 2.0, rel=1e-12)  # 1/sqrt(R_N)


def test_forms_by_name_and_bad_form():
    assert make_heat_flux("lumped", nose_radius=1.0, coefficient=1.2444e-3, velocity_exponent=3.0).velocity_exponent == 3.0
    with pytest.raises(ValueError, match="allowed: chapman, sutton_graves, normalised, lumped"):
        make_heat_flux("fay_riddell", nose_radius=1.0)


def test_normal_load_is_body_normal_force_paper000_eq35():
    assert normal_load_factor(3.0, 4.0, np.radians(90.0), 1.0) == pytest.approx(4.0)
    assert normal_load_factor(3.0, 4.0, 0.0, 1.0) == pytest.approx(3.0)


def test_margins_sign():
    m = PathLimits(heat_flux_max=100.0).margins(heat_flux=110.0, dynamic_pressure=0, normal_load=0, total_load=0)
    assert m["heat_flux"] == pytest.approx(-0.1)


def test_betts_shuttle_heating_in_the_books_own_units():
    """Betts (2010) Sec. 6.1's wing leading-edge heating, computed in its own units (rho in
    slug/ft^3, V in ft/s, q in BTU/ft^2/s, alpha in degrees) and converted with the exact
    definitions (1 ft = 0.3048 m, 1 slug = 14.593902937 kg, 1 BTU_IT = 1055.05585262 J),
    equals the SI model at three points."""
    hf = HeatFlux.betts_shuttle()
    for rho_slug_ft3, v_ft_s, a_deg in ((1e-6, 25_000.0, 40.0), (3.2e-6, 18_000.0, 17.5), (5e-7, 24_000.0, 0.0)):
        q_r = 17_700.0 * rho_slug_ft3 ** 0.5 * (1e-4 * v_ft_s) ** 3.07
        q_a = 1.0672181 - 0.19213774e-1 * a_deg + 0.21286289e-3 * a_deg ** 2 - 0.10117249e-5 * a_deg ** 3
        btu_ft2_s = q_a * q_r
        si = hf(rho_slug_ft3 * 14.593902937 / 0.3048 ** 3, v_ft_s * 0.3048, np.radians(a_deg))
        assert si == pytest.approx(btu_ft2_s * 1055.05585262 / 0.3048 ** 2, rel=1e-12)
        assert hf.factor(np.radians(a_deg)) == pytest.approx(q_a, rel=1e-12)


def test_each_named_form_is_its_published_formula():
    """make_heat_flux by name against each formula written out: Sutton-Graves k sqrt(rho/R_N) V^3,
    paper 001 eq. 9 c*/R_N^n (rho/rho0)^(1-n) (V/V_c)^m with a given V_c, the lumped k sqrt(rho)
    V^m (paper 004 eq. 13), Chapman with its own exponent, and an angle-of-attack factor q_a
    multiplying a form (degrees or radians)."""
    rho, V, R = 3e-5, 6500.0, 0.5
    assert make_heat_flux("sutton_graves", nose_radius=R)(rho, V) == pytest.approx(
        1.7415e-4 * np.sqrt(rho / R) * V ** 3, rel=1e-12)
    assert make_heat_flux("sutton_graves", nose_radius=R, coefficient=2e-4)(rho, V) == pytest.approx(
        2e-4 * np.sqrt(rho / R) * V ** 3, rel=1e-12)
    assert make_heat_flux("normalised", nose_radius=R, coefficient=1e8, velocity_exponent=3.0,
                          circular_speed=7800.0)(rho, V) == pytest.approx(
        1e8 / R ** 0.5 * (rho / 1.225) ** 0.5 * (V / 7800.0) ** 3.0, rel=1e-12)
    assert make_heat_flux("lumped", nose_radius=R, coefficient=9.4369e-5, velocity_exponent=3.15)(rho, V) == \
        pytest.approx(9.4369e-5 * np.sqrt(rho) * V ** 3.15, rel=1e-12)
    assert make_heat_flux("chapman", nose_radius=R, coefficient=5e-5, velocity_exponent=3.0)(rho, V) == \
        pytest.approx(5e-5 / np.sqrt(R) * np.sqrt(rho) * V ** 3.0, rel=1e-12)
    base = HeatFlux.chapman(R)
    deg = make_heat_flux("chapman", nose_radius=R, alpha_factor=(1.0, 0.01))
    rad = make_heat_flux("chapman", nose_radius=R, alpha_factor=(1.0, 0.5), alpha_unit="rad")
    assert deg(rho, V, np.radians(30.0)) == pytest.approx(1.3 * base(rho, V), rel=1e-12)
    assert rad(rho, V, 0.4) == pytest.approx(1.2 * base(rho, V), rel=1e-12) and base.factor(0.4) == 1.0
    with pytest.raises(ValueError, match="gives no alpha"):
        deg(rho, V)


@pytest.mark.parametrize("kwargs, message", [
    ({"form": "chapman", "circular_speed": 7800.0}, "applies to form 'normalised' only"),
    ({"form": "normalised", "circular_speed": 0.0}, r"must be in \(0, 1e5\)"),
    ({"form": "lumped", "coefficient": 1e-4}, "needs coefficient and velocity_exponent"),
    ({"form": "lumped", "velocity_exponent": 3.0}, "needs coefficient and velocity_exponent"),
    ({"form": "betts_shuttle", "coefficient": 1e-4}, "takes no coefficient"),
    ({"form": "betts_shuttle", "velocity_exponent": 3.0}, "takes no coefficient"),
    ({"form": "betts_shuttle", "alpha_factor": (1.0,)}, "has its own angle-of-attack factor"),
    ({"form": "chapman", "nose_radius": 0.0}, "nose_radius must be > 0"),
    ({"form": "sutton_graves", "nose_radius": -1.0}, "nose_radius must be > 0"),
    ({"form": "normalised", "nose_radius": 0.0}, "nose_radius must be > 0"),
])
def test_bad_heat_flux_settings_are_named(kwargs, message):
    kw = {"nose_radius": 1.0, **kwargs}
    with pytest.raises(ValueError, match=message):
        make_heat_flux(kw.pop("form"), **kw)


def test_heat_flux_and_limit_fields_are_checked_by_name():
    for kwargs, message in (({"coefficient": 0.0}, "coefficient must be > 0"),
                            ({"coefficient": 1.0, "alpha_unit": "grad"}, "alpha_unit = 'grad'"),
                            ({"coefficient": 1.0, "alpha_factor": (1.0, np.nan)}, "must be finite")):
        with pytest.raises(ValueError, match=message):
            HeatFlux(**kwargs)
    for name in ("heat_flux_max", "dynamic_pressure_max", "normal_load_max", "total_load_max"):
        with pytest.raises(ValueError, match=f"PathLimits.{name} must be > 0"):
            PathLimits(**{name: 0.0})


def test_each_margin_is_one_minus_its_own_value_over_its_own_limit():
    m = PathLimits(heat_flux_max=100.0, dynamic_pressure_max=50.0, normal_load_max=4.0, total_load_max=2.0).margins(
        heat_flux=110.0, dynamic_pressure=25.0, normal_load=1.0, total_load=2.0)
    assert m == {"heat_flux": pytest.approx(-0.1), "dynamic_pressure": 0.5, "normal_load": 0.75, "total_load": 0.0}


def test_load_factors_and_equilibrium_glide():
    """n = |(L, D)| / g0 (a 3-4-5 triangle), q = rho V^2 / 2, and the equilibrium-glide lift
    g - V^2/r: zero at circular speed."""
    from drake_entry.models.constraints import dynamic_pressure, equilibrium_glide_lift, total_load_factor

    assert total_load_factor(3.0, 4.0, 2.0) == pytest.approx(2.5)
    assert dynamic_pressure(0.02, 3000.0) == pytest.approx(90_000.0)
    r = 6.4e6
    assert equilibrium_glide_lift(np.sqrt(9.5 * r), r, 9.5) == pytest.approx(0.0, abs=1e-12)
    assert equilibrium_glide_lift(3000.0, r, 9.5) == pytest.approx(9.5 - 9e6 / r)


def test_normal_load_is_the_body_normal_projection_at_any_alpha():
    """Paper 000 eq. 35 against the geometry: the aerodynamic force (drag -D along the wind x
    axis, lift L along the wind z axis) projected on the body normal axis, the wind axes rotated
    by alpha; at 40 deg neither term vanishes, so a sign error shows."""
    L, D, a = 3.0, 4.0, np.radians(40.0)
    force_wind = np.array([-D, L])  # (along the velocity, normal to it in the symmetry plane, up)
    # the body axes: the nose alpha above the velocity, so the body normal (up) axis is the wind
    # normal axis tilted back by alpha: (-sin(alpha), cos(alpha)) in wind axes
    body_normal = np.array([-np.sin(a), np.cos(a)])
    assert normal_load_factor(L, D, a, 2.0) == pytest.approx(abs(force_wind @ body_normal) / 2.0, rel=1e-12)


def test_form_labels_constants_and_the_alpha_factor_tuple():
    """Each named form carries its name (messages and reports say which published constants are
    in use); paper 001 eq. 9's defaults are c* = 1.1097e8, n = 0.5, m = 3.15, rho0 = 1.225 kg/m^3,
    V_c = 7905 m/s; an angle-of-attack factor is stored as a tuple of floats (hashable, frozen)."""
    for form, kw in (("chapman", {}), ("sutton_graves", {}), ("normalised", {}), ("betts_shuttle", {}),
                     ("lumped", {"coefficient": 1e-4, "velocity_exponent": 3.0})):
        assert make_heat_flux(form, nose_radius=1.0, **kw).form == form
    rho, V = 2e-5, 7000.0
    assert HeatFlux.normalised(0.8)(rho, V) == pytest.approx(
        1.1097e8 / 0.8 ** 0.5 * (rho / 1.225) ** 0.5 * (V / 7905.0) ** 3.15, rel=1e-12)
    hf = HeatFlux(1.0, alpha_factor=[1, 2])
    assert hf.alpha_factor == (1.0, 2.0) and hash(hf)
    assert make_heat_flux("normalised", nose_radius=1.0, circular_speed=0.5).velocity_exponent == 3.15
    with pytest.raises(ValueError, match=r"must be in \(0, 1e5\)"):
        make_heat_flux("normalised", nose_radius=1.0, circular_speed=1e5)
    for kwargs, message in (({"form": "lumped", "coefficient": 1e-4}, "^heat_flux form 'lumped' needs"),
                            ({"form": "betts_shuttle", "coefficient": 1.0}, "^heat_flux form 'betts_shuttle' takes")):
        with pytest.raises(ValueError, match=message):
            make_heat_flux(kwargs.pop("form"), nose_radius=1.0, **kwargs)
