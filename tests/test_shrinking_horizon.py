"""Shrinking-horizon re-solution (drake_entry.planning.nlp.shrinking_horizon): the principle of
optimality on the brachistochrone (from a point of the cycloid the rest of the cycloid is
optimal: its time is exactly the remaining time), the errors, and a MaRV re-solve from a
perturbed mid-flight state meeting paper 002's eq. 16 terminal conditions, verified."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from drake_entry.errors import ScenarioError
from drake_entry.planning import nlp
from drake_entry.planning.nlp import catalogue
from drake_entry.planning.nlp.shrinking_horizon import remaining_problem, resolve_from, shifted_guess


def _cycloid(xf=2.0, yf=1.0):
    """The exact brachistochrone through (xf, yf): x = R (phi - sin phi), y = R (1 - cos phi),
    phi = w t, w = sqrt(g / R); (R, w, T)."""
    g = catalogue.G_BRACHISTOCHRONE
    p = brentq(lambda p: (p - math.sin(p)) / (1 - math.cos(p)) - xf / yf, 1e-6, 2 * math.pi - 1e-6)
    R = yf / (1 - math.cos(p))
    w = math.sqrt(g / R)
    return R, w, p / w


@pytest.fixture(scope="module")
def brachistochrone_solution():
    problem, _ = catalogue.brachistochrone()
    return nlp.solve(problem, nodes=20)


@pytest.mark.parametrize("fraction", [0.2, 0.5, 0.8])
def test_from_a_point_of_the_optimum_the_rest_of_it_is_optimal(brachistochrone_solution, fraction):
    """The exact cycloid's state at t0 (not the numerical solution's): the re-solution takes
    T - t0 to 1e-9 and stays on the cycloid to 1e-6 (1e-12 and 5e-8 measured)."""
    R, w, T = _cycloid()
    g = catalogue.G_BRACHISTOCHRONE
    t0 = fraction * T
    phi = w * t0
    x = [R * (phi - math.sin(phi)), R * (1 - math.cos(phi)), math.sqrt(2 * g * R * (1 - math.cos(phi)))]
    r = resolve_from(brachistochrone_solution, x, t0)
    assert r.converged and r.final_time == pytest.approx(T - t0, rel=1e-9)
    phi = w * (t0 + r.time)
    exact = np.column_stack([R * (phi - np.sin(phi)), R * (1 - np.cos(phi))])
    assert np.abs(r.states[:, :2] - exact).max() < 1e-6


def test_a_segmented_solution_is_resolved_in_its_segments():
    """An LGL solution in 3 segments is re-solved in 3 segments on the same nodes (unless told
    otherwise), and from the cycloid's state at half time takes the rest of its time to 1e-6."""
    problem, _ = catalogue.brachistochrone()
    previous = nlp.solve(problem, nodes=22, segments=3, solver="ipopt")
    R, w, T = _cycloid()
    g = catalogue.G_BRACHISTOCHRONE
    phi = w * 0.5 * T
    x = [R * (phi - math.sin(phi)), R * (1 - math.cos(phi)), math.sqrt(2 * g * R * (1 - math.cos(phi)))]
    r = resolve_from(previous, x, 0.5 * T, solver="ipopt")
    assert previous.converged and r.converged and (r.segments, r.nodes) == (3, 22)
    assert r.final_time == pytest.approx(0.5 * T, rel=1e-6)
    assert resolve_from(previous, x, 0.5 * T, solver="ipopt", segments=1).segments == 1


def test_the_warm_start_starts_at_the_measured_state_and_ends_where_the_previous_did(brachistochrone_solution):
    prev = brachistochrone_solution
    x = prev.state_function()(np.array([0.3]))[0] + np.array([0.01, -0.02, 0.05])
    t, X, U = shifted_guess(prev, x, 0.3)
    assert t[0] == 0.0 and t[-1] == pytest.approx(prev.final_time - 0.3)
    assert X[0] == pytest.approx(x) and X[-1] == pytest.approx(prev.states[-1])
    assert U.shape == (t.size, 1)


def test_bad_states_and_times_are_named(brachistochrone_solution):
    problem = brachistochrone_solution.problem
    with pytest.raises(ScenarioError, match=r"x_now: expected 3 finite values \(x, y, v\)"):
        remaining_problem(problem, [0.0, 0.0], 0.1)
    with pytest.raises(ScenarioError, match=r"x_now: expected 3 finite values"):
        remaining_problem(problem, [0.0, np.nan, 0.0], 0.1)
    with pytest.raises(ScenarioError, match=r"elapsed_s = -1.0: allowed finite values >= 0 s"):
        remaining_problem(problem, [0.0, 0.0, 0.0], -1.0)
    with pytest.raises(ScenarioError, match="past the previous solution's final time"):
        shifted_guess(brachistochrone_solution, [0.0, 0.0, 0.0], 5.0)
    fixed = catalogue.brachistochrone()[0]
    import dataclasses as dc

    with pytest.raises(ScenarioError, match="leaves no horizon: the final time is at most 0.5 s"):
        remaining_problem(dc.replace(fixed, final_time=0.5), [0.0, 0.0, 0.0], 0.5)
    assert remaining_problem(dc.replace(fixed, final_time=(0.2, 2.0)), [0.0, 0.0, 0.0], 0.5).final_time == (
        pytest.approx(1e-3), 1.5)


@pytest.mark.slow
def test_marv_resolved_from_a_perturbed_mid_flight_state_meets_eq16():
    """Paper 002's MaRV (eqs. 16-19) solved on 60 LGL nodes, then re-solved on 40 nodes from its
    state at 500 s moved 200 m up and 10 m/s faster: converged and verified (between the nodes
    and by the Drake-flown controls), ending on eq. 16's terminal conditions (ground, 25.15 deg
    downrange, 1219 m/s, -89 deg, alpha 0) from exactly the measured state; 7 s measured."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning.ocp_yaml import load_problem

    problem, _ = load_problem("marv")
    base = nlp.solve(problem, transcription="lgl", solver="snopt", nodes=60, tolerance=1e-6)
    assert base.converged, base.message
    x = base.state_function()(np.array([500.0]))[0] + np.array([200.0, 0, 0, 10.0, 0, 0, 0, 0])
    r = resolve_from(base, x, 500.0, nodes=40, solver="snopt", tolerance=1e-6, verifier=fly_controls)
    assert r.success, r.message
    assert r.states[0] == pytest.approx(x, abs=1e-9)
    h, lon, lat, V, gamma, psi, alpha, sigma = r.states[-1]
    assert abs(h) < 1e-3 and lon == pytest.approx(math.radians(25.15), abs=1e-9) and V == pytest.approx(1219.0)
    assert gamma == pytest.approx(math.radians(-89.0)) and alpha == pytest.approx(0.0, abs=1e-9)
    assert 250.0 < r.final_time < 350.0  # the previous solution had 308 s left
