"""Paper 004's per-step guidance law: eq. 17 bank, eq. 47 (corrected) against the derivative
of eq. 46, eq. 48's sign, and the constraint-derived alpha of eqs. 21 and 31 (CAV-H)."""
import math

import numpy as np
import pytest

from drake_entry.errors import ScenarioError
from drake_entry.guidance.swarm_bank.guidance_law import (
    alpha_for_heat_rate,
    alpha_for_load_factor,
    equilibrium_glide_radius,
    linear_bank,
    qeg_bank,
    qeg_sin_flight_path,
)
from drake_entry.models.vehicles import load_vehicle

BETA = 920.0  # paper 004, below eq. 46
D2R = math.radians


def test_eq17_bank_is_linear_in_energy_between_its_ends():
    e = np.array([0.2, 0.35, 0.5])
    got = linear_bank(e, 0.2, 0.5, D2R(58.9), D2R(60.0))
    assert np.degrees(got) == pytest.approx([58.9, 59.45, 60.0])


@pytest.mark.parametrize("V, r, D", [(0.75, 1.0094, 0.05), (0.95, 1.011, 0.02), (0.4, 1.006, 0.3)])
def test_eq47_corrected_follows_the_equilibrium_glide_radius_of_eq46(V, r, D):
    """Flying sin(gamma_QEGC), the dynamics' dr/dV = V sin g / (-D - sin g / r^2) equals
    d r_eq / dV of eq. 46 (central difference); the printed eq. 47 does not."""
    s = qeg_sin_flight_path(r, V, D, BETA)
    drdV_dynamics = V * s / (-D - s / r**2)
    h = 1e-6
    drdV_eq46 = (equilibrium_glide_radius(V + h, 5.0, BETA) - equilibrium_glide_radius(V - h, 5.0, BETA)) / (2 * h)
    assert drdV_dynamics == pytest.approx(drdV_eq46, rel=1e-7)
    printed = -D / (BETA * V**3 * (1 - V**2) + 1 / r**2)
    assert not 0.9 < printed / s < 1.1  # the typo a pre-implementation prototype found (x0.56 to x1.25)


def test_eq48_lowers_vertical_lift_when_climbing_above_the_glide():
    base = D2R(60.0)
    same = qeg_bank(base, L=0.5, D=0.2, sin_gamma=-0.001, sin_gamma_qeg=-0.001, k2=10.0)
    climbing = qeg_bank(base, L=0.5, D=0.2, sin_gamma=0.001, sin_gamma_qeg=-0.001, k2=10.0)
    sinking = qeg_bank(base, L=0.5, D=0.2, sin_gamma=-0.003, sin_gamma_qeg=-0.001, k2=10.0)
    assert same == pytest.approx(base) and climbing > base > sinking
    # L cos(sigma_cmd) = L cos(sigma_base) - k2 (dr/de - dr_QEGC/de), dr/de = sin gamma / D
    assert 0.5 * math.cos(climbing) == pytest.approx(0.5 * math.cos(base) - 10.0 * 0.002 / 0.2)
    assert qeg_bank(base, L=0.5, D=0.2, sin_gamma=0.5, sin_gamma_qeg=0.0, k2=10.0) == pytest.approx(math.pi)


@pytest.fixture(scope="module")
def cav_h():
    return load_vehicle("cav_h")


def test_eq31_alpha_puts_the_total_load_on_its_limit(cav_h):
    q = np.array([20e3, 40e3, 60e3])
    mach = np.array([15.0, 10.0, 6.0])
    alpha = alpha_for_load_factor(q, mach, cav_h.aero, cav_h.area_over_mass, 9.80665, 2.0, D2R(10), D2R(20))
    cl, cd = cav_h.aero.coefficients(alpha, mach)
    load = q * cav_h.area_over_mass * np.hypot(cl, cd) / 9.80665
    inside = (alpha > D2R(10) + 1e-9) & (alpha < D2R(20) - 1e-9)
    assert inside.any() and load[inside] == pytest.approx(2.0, rel=1e-10)
    thin = alpha_for_load_factor(100.0, 20.0, cav_h.aero, cav_h.area_over_mass, 9.80665, 2.0, D2R(10), D2R(20))
    dense = alpha_for_load_factor(1e6, 5.0, cav_h.aero, cav_h.area_over_mass, 9.80665, 2.0, D2R(10), D2R(20))
    assert thin == pytest.approx(D2R(20)) and dense == pytest.approx(D2R(10))  # saturated at the bounds


def test_eq21_alpha_is_a_fixed_point_on_the_heat_limit_and_raises_drag_above_it(cav_h):
    a0, mach = D2R(12.0), 18.0
    assert alpha_for_heat_rate(a0, 1.0, mach, cav_h.aero, D2R(10), D2R(20)) == pytest.approx(a0, abs=1e-12)
    a1 = alpha_for_heat_rate(a0, 1.1, mach, cav_h.aero, D2R(10), D2R(20))
    assert a1 > a0
    assert cav_h.aero.coefficients(a1, mach)[1] == pytest.approx(1.21 * cav_h.aero.coefficients(a0, mach)[1])
    with pytest.raises(ScenarioError, match="lower < upper"):
        alpha_for_heat_rate(a0, 1.0, mach, cav_h.aero, D2R(20), D2R(10))


def _case1_problem():
    """Paper 004 Case 1 on the packaged substitute mission (cav_h_paper004.yaml)."""
    from drake_entry.guidance.swarm_bank.search import problem_from_scenario
    from drake_entry.scenario import load_scenario

    return problem_from_scenario(load_scenario("cav_h_paper004"))


def test_population_members_fly_independently():
    from drake_entry.guidance.swarm_bank.evaluator import evaluate

    p = _case1_problem()
    both = evaluate(p, np.radians([57.0, 61.0]))
    alone = evaluate(p, np.radians([61.0]))
    assert both.trajectories == 2 and both.reached.all()
    assert both.J[1] == pytest.approx(alone.J[0], rel=1e-12)
    assert both.final_state[1] == pytest.approx(alone.final_state[0], rel=1e-12)


def test_case1_optimum_is_where_the_substitute_target_puts_it():
    """Case 1 on the substitute mission (target placed for the paper's sigma_0 = 58.89 deg;
    the root of the signed range error lies between 58.7 and 58.9 deg here); the peak heat rate
    is the pre-implementation prototype's 2.90 MW/m^2 (it does not depend on the target), the load stays
    within its 2 g limit, and the TAEM speed is met within a few m/s (the energy fixes it)."""
    from drake_entry.guidance.swarm_bank.evaluator import evaluate

    ev = evaluate(_case1_problem(), np.radians([58.7, 58.9]))
    assert ev.range_error_m[0] > 0 > ev.range_error_m[1]
    assert (np.abs(ev.range_error_m) < 40e3).all() and (np.abs(ev.crossrange_m) < 10e3).all()
    # paper 004 Sec. "Case 1": its alpha profile keeps the peak heat rate "much lesser than the
    # specified" 6 MW/m^2; 2.90 MW/m^2 is a regression pin of our model (the prototype's figure)
    assert (ev.peak_heat_flux_W_m2 < 0.6 * 6e6).all()
    assert ev.peak_heat_flux_W_m2 == pytest.approx(2.90e6, rel=0.02)
    assert (ev.peak_total_load_g <= 2.0 * 1.01).all()
    assert (np.abs(ev.velocity_error_m_s) < 5.0).all()


def test_path_feedback_lifts_only_where_a_limit_would_be_passed_ahead():
    """Lu 2014's path-limit feedback in paper 004's bank law (guidance.path_feedback): off or far
    from every limit the law is eqs. 17 and 46-48 exactly; descending towards the heat-rate
    limit it flies more vertical lift, by L cos(sigma) lowered by k V (sin(gamma) - U) sqrt(g0/R0)
    with U the flight-path sine that meets the limit ``horizon`` seconds ahead."""
    import dataclasses as dc

    from drake_entry.guidance.path_feedback import PathLimits, path_limit_sin_flight_path
    from drake_entry.guidance.swarm_bank.guidance_law import LawSettings, bank_magnitude

    R0, g0 = 6378137.0, 9.80665
    law = LawSettings(sigma_f=D2R(60.0), e0=4.0e7, ef=5.5e7, bank_limit=D2R(85.0), alpha_min=D2R(10.0),
                      alpha_max=D2R(20.0), load_max=2.5, heat_max=5e5, case="load", mach_shift=20.0, k2=0.0,
                      beta=BETA, R0=R0, g0=g0, mu=3.986004418e14)
    path = PathLimits(R0, g0, beta=BETA, gain=40.0, horizon=16.0, heat_max=5e5)
    fed = dc.replace(law, path=path)
    V, r, L, D, q = 5000.0, R0 + 50e3, 6.0, 2.0, 2e4  # (eq. 48's gain 0: the base is eq. 17 alone)
    args = (D2R(50.0), V, -0.02, r, L, D, D2R(60.0))
    base = bank_magnitude(law, *args)
    assert bank_magnitude(fed, *args, heat=1e5, q=q) == base  # far below the limit: untouched
    near = bank_magnitude(fed, *args, heat=4.6e5, q=q)
    assert near < base
    u = path_limit_sin_flight_path(V, D, math.hypot(L, D), 4.6e5, q, path)
    assert u > math.sin(-0.02)
    expected = math.cos(base) - 40.0 * V * (math.sin(-0.02) - u) * math.sqrt(g0 / R0) / L
    assert math.cos(near) == pytest.approx(expected, rel=1e-12)
    assert bank_magnitude(dc.replace(law, path=dc.replace(path, gain=0.0)), *args, heat=4.6e5, q=q) == base
