import numpy as np
import pytest
from pydrake.autodiffutils import ExtractGradient, InitializeAutoDiff
from pydrake.symbolic import Expression, Variable
from scipy.integrate import solve_ivp

from drake_entry.models.aerodynamics import CallableAero
from drake_entry.models.atmosphere import ExponentialAtmosphere
from drake_entry.models.dynamics import energy_rate, flight_conditions, specific_energy, state_derivatives
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle


def test_autodiff_jacobian_equals_finite_differences(horus, us76, entry_state):
    p = Earth.oblate()
    z = np.append(entry_state, [0.6, np.radians(40.0)])
    J = ExtractGradient(_f_ad(z, horus, p, us76))
    for i in range(8):
        e = 1e-6 * max(1.0, abs(z[i]))
        zp, zm = z.copy(), z.copy()
        zp[i] += e
        zm[i] -= e
        fd = (_f(zp, horus, p, us76) - _f(zm, horus, p, us76)) / (2 * e)
        assert np.allclose(J[:, i], fd, rtol=1e-5, atol=1e-12), i


def _f(z, v, p, a):
    return state_derivatives(z[:6], z[6], z[7], v, p, a)


def _f_ad(z, v, p, a):
    zad = InitializeAutoDiff(z).ravel()
    return state_derivatives(zad[:6], zad[6], zad[7], v, p, a)


def _liftonly_vehicle():
    return Vehicle("glider", 1000.0, 1.0, 0.5, CallableAero(cl=lambda a, M: 0.5 + 0.0 * M, cd=lambda a, M: 0.0 * M))


@pytest.mark.parametrize("planet", [Earth.spherical(rotating=False), Earth(omega=0.0)])
def test_energy_is_conserved_without_drag_on_a_non_rotating_planet(planet):
    v = _liftonly_vehicle()
    atm = ExponentialAtmosphere()
    x0 = np.array([60e3, 0.1, 0.5, 6500.0, np.radians(-1.0), 0.7])
    sol = solve_ivp(lambda t, x: state_derivatives(x, 0.4, 0.2, v, planet, atm), (0, 600), x0,
                    method="DOP853", rtol=1e-11, atol=1e-9)
    E = [specific_energy(x, planet) for x in sol.y.T]
    assert np.ptp(E) / abs(E[0]) < 1e-9


def test_jacobi_integral_is_conserved_on_a_rotating_planet_without_drag():
    p = Earth.oblate()
    v = _liftonly_vehicle()
    atm = ExponentialAtmosphere()
    x0 = np.array([60e3, 0.1, 0.5, 6500.0, np.radians(-1.0), 0.7])
    sol = solve_ivp(lambda t, x: state_derivatives(x, -0.3, 0.2, v, p, atm), (0, 600), x0,
                    method="DOP853", rtol=1e-11, atol=1e-9)

    def jacobi(x):
        r = p.radius(x[0])
        return specific_energy(x, p) - 0.5 * (p.omega * r * np.cos(x[2])) ** 2

    J = [jacobi(x) for x in sol.y.T]
    assert np.ptp(J) / abs(J[0]) < 1e-9


def test_energy_rate_is_minus_drag_times_speed_paper000_eq39(horus, us76, entry_state):
    p = Earth.spherical(rotating=False)
    xdot = state_derivatives(entry_state, 0.5, 0.7, horus, p, us76)
    fc = flight_conditions(entry_state, 0.5, 0.7, horus, p, us76)
    assert energy_rate(entry_state, xdot, p) == pytest.approx(-fc.drag * entry_state[3], rel=1e-12)


def test_paper000_eq102_terms_by_hand(horus, us76, entry_state):
    p = Earth.spherical()
    h, lon, lat, V, g, psi = entry_state
    fc = flight_conditions(entry_state, 0.0, 0.7, horus, p, us76)
    xdot = state_derivatives(entry_state, 0.0, 0.7, horus, p, us76)
    r = p.radius(h)
    gr = p.mu / r**2
    w = p.omega
    vdot = -fc.drag - gr * np.sin(g) + w**2 * r * np.cos(lat) * (np.sin(g) * np.cos(lat) - np.cos(g) * np.sin(lat) * np.cos(psi))
    assert xdot[3] == pytest.approx(vdot, rel=1e-12)
    assert xdot[0] == pytest.approx(V * np.sin(g))


def test_symbolic_dynamics_evaluate_to_the_float_dynamics():
    from drake_entry.models.vehicles import load_vehicle

    x = [Variable(n) for n in ("h", "lon", "lat", "V", "gamma", "psi")]
    sigma, alpha = Variable("sigma"), Variable("alpha")
    vehicle, planet = load_vehicle("cav_h"), Earth.oblate()
    atm = ExponentialAtmosphere(temperature_K=250.0)
    with np.errstate(invalid="ignore"):  # numpy's FP check after ufuncs on Expressions is spurious
        f = state_derivatives(x, sigma, alpha, vehicle, planet, atm)
    assert all(isinstance(e, Expression) for e in f)
    point = [50e3, 0.1, 0.3, 5000.0, -0.01, 1.0]
    env = {**dict(zip(x, point)), sigma: 0.4, alpha: 0.2}
    expected = state_derivatives(np.array(point), 0.4, 0.2, vehicle, planet, atm)
    assert np.allclose([e.Evaluate(env) for e in f], expected, rtol=1e-12)


def test_energy_domain_form_is_time_form_divided_by_energy_rate(horus, us76, entry_state):
    from drake_entry.models.dynamics import energy_domain_derivatives

    p = Earth.oblate()
    dx_dE = energy_domain_derivatives(entry_state, 0.3, 0.7, horus, p, us76)
    xdot = state_derivatives(entry_state, 0.3, 0.7, horus, p, us76)
    edot = energy_rate(entry_state, xdot, p)
    assert np.allclose(dx_dE[:6] * edot, xdot, rtol=1e-12)
    assert dx_dE[6] == pytest.approx(1.0 / edot)
    assert edot < 0  # drag dissipates energy


def _cartesian(x, planet):
    """Position and velocity [m, m/s] in the planet-fixed (rotating) frame of a state
    [h, lon, lat, V, gamma, psi], and the local up, north, east unit vectors: geometry only."""
    h, lon, lat, V, gamma, psi = x
    up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
    east = np.array([-np.sin(lon), np.cos(lon), 0.0])
    v = V * (np.sin(gamma) * up + np.cos(gamma) * (np.cos(psi) * north + np.sin(psi) * east))
    return planet.radius(h) * up, v, up, north, east


@pytest.mark.parametrize("planet", [Earth.spherical(rotating=True), Earth.oblate()], ids=["spherical", "oblate_j2"])
def test_equations_of_motion_are_newtons_law_in_the_rotating_frame(planet):
    """The spherical-coordinate equations against Newton's second law written independently in
    Cartesian coordinates of the rotating frame: d/dt of the position is the velocity, and d/dt of
    the velocity is lift + drag + gravity - 2 w x v - w x (w x r), the time derivatives taken
    through the coordinate map (central differences) with the equations' x_dot. Lift L cos(sigma)
    lies in the vertical plane of the velocity (raising gamma), L sin(sigma) horizontal (raising
    psi), drag against the velocity, gravity -g_r up + g_n north; random states up to
    |gamma| = 60 deg and |lat| = 75 deg."""
    from drake_entry.models.dynamics import equations_of_motion_lift_components

    rng = np.random.default_rng(7)
    w = np.array([0.0, 0.0, planet.omega])
    for _ in range(40):
        x = np.array([rng.uniform(20e3, 120e3), rng.uniform(-np.pi, np.pi), np.radians(rng.uniform(-75, 75)),
                      rng.uniform(500.0, 7800.0), np.radians(rng.uniform(-60, 60)), rng.uniform(-np.pi, np.pi)])
        Lv, Lh, D = rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(0, 30)
        xdot = equations_of_motion_lift_components(x, Lv, Lh, D, planet)
        r, v, up, north, east = _cartesian(x, planet)
        gamma, psi = x[4], x[5]
        lift_v = np.cos(gamma) * up - np.sin(gamma) * (np.cos(psi) * north + np.sin(psi) * east)
        lift_h = -np.sin(psi) * north + np.cos(psi) * east
        g_r, g_n = planet.gravity(np.linalg.norm(r), x[2])
        accel = Lv * lift_v + Lh * lift_h - D * v / np.linalg.norm(v) - g_r * up + g_n * north \
            - 2.0 * np.cross(w, v) - np.cross(w, np.cross(w, r))
        scale = np.array([1.0, 1e-6, 1e-6, 1e-3, 1e-6, 1e-6])  # a step of about 6 m or 1 mm/s on each
        dr, dv = np.zeros(3), np.zeros(3)
        for i in range(6):
            e = np.zeros(6)
            e[i] = scale[i]
            rp, vp = _cartesian(x + e, planet)[:2]
            rm, vm = _cartesian(x - e, planet)[:2]
            dr += (rp - rm) / (2 * scale[i]) * xdot[i]
            dv += (vp - vm) / (2 * scale[i]) * xdot[i]
        assert np.allclose(dr, v, rtol=0, atol=1e-6 * np.linalg.norm(v)), (x, dr - v)
        assert np.allclose(dv, accel, rtol=0, atol=1e-6 * (np.linalg.norm(accel) + 1.0)), (x, dv - accel)


def test_energy_rate_is_the_derivative_of_the_energy_along_the_motion():
    """On the oblate rotating Earth (J2: the potential depends on latitude) the chain-rule
    energy rate equals the central difference of specific_energy along x_dot, at several
    latitudes and with every state derivative non-zero."""
    p = Earth.oblate()
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = np.array([rng.uniform(20e3, 100e3), 0.3, np.radians(rng.uniform(-70, 70)), 6000.0, -0.1, 0.4])
        xdot = rng.uniform(-1.0, 1.0, 6) * np.array([200.0, 1e-3, 1e-3, 20.0, 1e-3, 1e-3])
        e = 1e-3
        fd = (specific_energy(x + e * xdot, p) - specific_energy(x - e * xdot, p)) / (2 * e)
        assert energy_rate(x, xdot, p) == pytest.approx(fd, rel=1e-7)


def test_a_non_finite_derivative_stops_with_the_state_named():
    from drake_entry.errors import NonFiniteStateError
    from drake_entry.models.dynamics import equations_of_motion_lift_components

    with pytest.raises(NonFiniteStateError, match=r"non-finite state derivative at h = 50000 m, V = nan m/s"):
        equations_of_motion_lift_components(np.array([5e4, 0.0, 0.0, np.nan, 0.0, 0.0]), 1.0, 0.0, 1.0, Earth.oblate())


def test_flight_conditions_mach_and_an_alpha_dependent_heat_flux(us76):
    """Mach is V over the atmosphere's speed of sound at the state's altitude, and a heat-flux
    form with an angle-of-attack factor (Betts' shuttle) is evaluated at the flown alpha."""
    import dataclasses as dc

    from drake_entry.models.constraints import HeatFlux
    from drake_entry.models.vehicles import load_vehicle

    p = Earth.spherical()
    v = dc.replace(load_vehicle("horus2b"), heat_flux=HeatFlux.betts_shuttle())
    x = np.array([60e3, 0.0, 0.3, 5000.0, -0.02, 0.5])
    alpha = np.radians(35.0)
    c = flight_conditions(x, 0.3, alpha, v, p, us76)
    h = p.atmospheric_altitude(x[0], x[2])
    rho, a = us76.density(h), us76.speed_of_sound(h)
    assert c.mach == pytest.approx(5000.0 / a, rel=1e-12) and c.rho == pytest.approx(rho, rel=1e-12)
    assert c.heat_flux == pytest.approx(HeatFlux.betts_shuttle()(rho, 5000.0, alpha), rel=1e-12)
