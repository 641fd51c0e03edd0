import numpy as np
import pytest

from drake_entry.models.planet import Earth


def test_gravity_is_minus_the_gradient_of_the_j2_potential():
    p = Earth.oblate()
    r, lat = 6.5e6, 0.6
    e = 1.0
    dphi_dr = (p.potential(r + e, lat) - p.potential(r - e, lat)) / (2 * e)
    dphi_dlat = (p.potential(r, lat + 1e-7) - p.potential(r, lat - 1e-7)) / 2e-7
    g_r, g_n = p.gravity(r, lat)
    assert g_r == pytest.approx(dphi_dr, rel=1e-8)  # inward magnitude = dPhi/dr
    assert g_n == pytest.approx(-dphi_dlat / r, rel=1e-6)  # north component = -(1/r) dPhi/dlat


def test_spherical_non_j2_gravity_is_central():
    p = Earth.spherical()
    g_r, g_n = p.gravity(7e6, 0.5)
    assert g_r == pytest.approx(p.mu / 7e6**2)
    assert g_n == 0.0
    assert p.omega > 0 and Earth.spherical(rotating=False).omega == 0.0


def test_j2_increases_equatorial_gravity_paper000_eq28():
    p = Earth.spherical(j2=True)
    g_r, _ = p.gravity(p.equatorial_radius, 0.0)
    assert g_r == pytest.approx(p.mu / p.equatorial_radius**2 * (1 + 1.5 * p.j2))


def test_geodetic_altitude_of_a_point_on_the_ellipsoid_is_zero():
    p = Earth.oblate()
    a, f = p.equatorial_radius, p.flattening
    b = a * (1 - f)
    phi = np.radians(50.0)  # geodetic latitude
    e2 = f * (2 - f)
    n = a / np.sqrt(1 - e2 * np.sin(phi) ** 2)
    x, z = n * np.cos(phi), n * (1 - e2) * np.sin(phi)
    h, lat = p.geodetic(np.hypot(x, z), np.arctan2(z, x))
    assert abs(h) < 1e-3 and lat == pytest.approx(phi, abs=1e-10)
    assert b < np.hypot(x, z) < a


def test_bad_planet_parameters():
    with pytest.raises(ValueError, match="flattening must be in"):
        Earth(flattening=1.5)


def test_from_geodetic_inverts_geodetic_at_paper001_site():
    """The Azores site (paper 001: 36.974 deg N geodetic) lies 0.185 deg (20.5 km) further
    south in geocentric latitude; a point at 0 m geodetic is 7.7 km below the WGS-84 equatorial
    sphere's surface there (docs/methods/scvx.md)."""
    p = Earth.oblate()
    h, lat = p.from_geodetic(0.0, np.radians(36.974))
    assert np.degrees(lat) == pytest.approx(36.7895, abs=1e-3)
    assert p.reference_radius * np.radians(36.974 - np.degrees(lat)) == pytest.approx(20.5e3, abs=0.3e3)
    assert h == pytest.approx(-p.equatorial_radius * p.flattening * np.sin(lat) ** 2, rel=0.01)
    for alt, glat in ((120e3, 0.3), (10e3, -1.1), (0.0, 0.0)):
        h, lat = p.from_geodetic(alt, glat)
        back_alt, back_lat = p.geodetic(p.radius(h), lat)
        assert back_alt == pytest.approx(alt, abs=1e-3) and back_lat == pytest.approx(glat, abs=1e-12)
