"""Great-circle geometry (drake_entry.models.geodesy) and trajectory metrics (drake_entry.models.trajectory)."""
import math

import numpy as np
import pytest
from pydrake.autodiffutils import AutoDiffXd

from drake_entry.models.constraints import PathLimits
from drake_entry.models.dynamics import FLIGHT_CONDITION_NAMES
from drake_entry.models.geodesy import (
    bearing,
    central_angle,
    central_angle_smooth,
    crossrange_from_great_circle,
    downtrack_crosstrack,
    range_and_crossrange,
)
from drake_entry.models.trajectory import Trajectory, metrics

R = 6378137.0
D = math.radians


def test_bearings_of_the_cardinal_directions_from_the_equator():
    assert bearing(0.0, 0.0, 0.0, D(10)) == pytest.approx(0.0)
    assert bearing(0.0, 0.0, D(10), 0.0) == pytest.approx(math.pi / 2)
    assert bearing(0.0, 0.0, 0.0, D(-10)) == pytest.approx(math.pi)
    assert bearing(0.0, 0.0, D(-10), 0.0) == pytest.approx(-math.pi / 2)


def test_quarter_meridian_and_the_smooth_form_agree():
    assert central_angle(0.0, 0.0, 0.0, math.pi / 2) == pytest.approx(math.pi / 2)
    rng = np.random.default_rng(3)
    p = rng.uniform(-1.5, 1.5, (50, 4))
    exact = central_angle(*p.T)
    smooth = [central_angle_smooth(*map(float, row)) for row in p]
    assert np.allclose(exact, smooth, atol=1e-12)
    a = central_angle_smooth(AutoDiffXd(0.3, [1.0]), 0.2, 0.5, 0.1)  # differentiable (optimisers)
    h = 1e-6
    fd = (central_angle(0.3 + h, 0.2, 0.5, 0.1) - central_angle(0.3 - h, 0.2, 0.5, 0.1)) / (2 * h)
    assert a.derivatives()[0] == pytest.approx(fd, rel=1e-6)


def test_range_and_crossrange_split_the_distance_along_and_across_the_heading():
    # flying north from (0, 0): a target north-east is ahead (+) and to the right (+)
    rng, cross, dist = range_and_crossrange(0.0, 0.0, 0.0, D(1), D(1), R)
    assert rng > 0 and cross > 0 and math.hypot(rng, cross) == pytest.approx(dist)
    assert dist == pytest.approx(R * central_angle(0.0, 0.0, D(1), D(1)))
    # flying east past a target behind and to the left
    rng, cross, _ = range_and_crossrange(D(2), 0.0, math.pi / 2, D(1), D(0.5), R)
    assert rng < 0 and cross < 0


def test_downtrack_crosstrack_of_the_end_points_paper002_eqs_24_30():
    d, c = downtrack_crosstrack(np.array([0.0, D(10)]), np.array([0.0, D(5)]), 0.0, 0.0, D(10), D(5), R)
    assert d[0] == pytest.approx(0.0) and c == pytest.approx([0.0, 0.0], abs=1e-6)
    assert d[1] == pytest.approx(R * central_angle(0.0, 0.0, D(10), D(5)))


def test_crossrange_from_the_initial_great_circle_is_signed_right_positive():
    assert crossrange_from_great_circle(0.0, D(20), 0.0, 0.0, 0.0, R) == pytest.approx(0.0, abs=1e-6)
    assert crossrange_from_great_circle(D(1), D(5), 0.0, 0.0, 0.0, R) == pytest.approx(R * D(1) * math.cos(D(5)),
                                                                                       rel=2e-3)
    assert crossrange_from_great_circle(D(-1), D(5), 0.0, 0.0, 0.0, R) < 0


def _trajectory(t, heat, q, nz, n):
    cond = np.zeros((t.size, len(FLIGHT_CONDITION_NAMES)))
    for name, v in (("heat_flux", heat), ("dynamic_pressure", q), ("normal_load", nz), ("total_load", n)):
        cond[:, FLIGHT_CONDITION_NAMES.index(name)] = v
    return Trajectory(time=t, state=np.zeros((t.size, 6)), conditions=cond, bank=np.zeros(t.size),
                      alpha=np.zeros(t.size), reason="test", wall_time=0.0)


def test_metrics_peaks_heat_load_and_margins_of_the_finite_limits():
    t = np.linspace(0.0, 100.0, 101)
    tr = _trajectory(t, heat=1e3 * t, q=5e3 * np.sin(np.pi * t / 100), nz=np.full(t.size, 2.0), n=np.full(t.size, 2.5))
    m = metrics(tr, PathLimits(heat_flux_max=2e5, dynamic_pressure_max=1e4, normal_load_max=2.5))
    assert m["heat_load_J_m2"] == pytest.approx(1e3 * 100.0**2 / 2)  # trapezoid exact for a linear q(t)
    assert m["peak_heat_flux_W_m2"] == 1e5 and m["peak_dynamic_pressure_Pa"] == pytest.approx(5e3)
    assert m["margin_heat_flux"] == pytest.approx(0.5) and m["margin_normal_load"] == pytest.approx(0.2)
    assert m["peak_total_load_g"] == 2.5 and "margin_total_load" not in m  # no total-load limit given
    assert "margin_heat_flux" not in metrics(tr)


def test_destination_lies_on_the_great_circle_at_the_distance():
    from drake_entry.models.geodesy import destination

    lon, lat = destination(D(-72.3), D(39.2), D(38.6), 11250e3, R)
    assert R * central_angle(D(-72.3), D(39.2), lon, lat) == pytest.approx(11250e3, rel=1e-9)
    assert crossrange_from_great_circle(lon, lat, D(-72.3), D(39.2), D(38.6), R) == pytest.approx(0.0, abs=1e-3)
    assert destination(0.0, 0.0, 0.0, R * D(10), R) == pytest.approx((0.0, D(10)))


def test_array_bearings_equal_the_scalar_bearing():
    from drake_entry.models.geodesy import bearings

    rng = np.random.default_rng(4)
    p = rng.uniform(-1.4, 1.4, (4, 30))
    assert bearings(*p) == pytest.approx([bearing(*map(float, c)) for c in p.T], abs=1e-14)


def test_reversal_sign_turns_back_at_the_corridor_edges():
    from drake_entry.models.bank_reversal import reversal_sign, wrap_angle

    assert [reversal_sign(e, 0.1, s) for e, s in ((0.2, 1.0), (-0.2, -1.0), (0.05, -1.0), (0.2, -1.0))] == \
        [-1.0, 1.0, -1.0, -1.0]
    assert list(reversal_sign(np.array([0.2, -0.2, 0.0]), 0.1, np.array([1.0, -1.0, 1.0]))) == [-1.0, 1.0, 1.0]
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
