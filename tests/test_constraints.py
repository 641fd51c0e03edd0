import numpy as np
import pytest

from drake_entry.models.constraints import HeatFlux, PathLimits, make_heat_flux, normal_load_factor


def test_chapman_equals_paper001_normalised_form():
    """docs/references.md: C1 = 5.28137e-5 is paper 001 eq. 9 with c* = 1.1097e8, n = 0.5, m = 3.15."""
    a, b = HeatFlux.chapman(0.8), HeatFlux.normalised(0.8)
    assert a(1e-4, 6000.0) == pytest.approx(b(1e-4, 6000.0), rel=1e-3)


def test_chapman_heat_flux_value_paper000_eq34():
    q = HeatFlux.chapman(0.8)(2e-5, 7000.0)
    assert q == pytest.approx(5.28137e-5 / np.sqrt(0.8) * np.sqrt(2e-5) * 7000.0**3.15)


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
