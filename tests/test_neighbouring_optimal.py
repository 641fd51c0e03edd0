"""planning.neighbouring_optimal: the Hamiltonian's second derivatives against their closed form,
and the law against the algebraic Riccati gain where the second variation is an LQR."""
import math

import numpy as np
import pytest
from scipy.linalg import solve_continuous_are

from drake_entry.errors import ScenarioError
from drake_entry.planning.neighbouring_optimal import hamiltonian_hessian, neighbouring_optimal, without_odd_even_mode
from drake_entry.planning.tracking import TrackingWeights


class _Pendulum:
    """p' = v, v' = -w2 sin(p) - c v + b u; L = q1 p^2 + q2 v^2 + r u^2 (states 'p', 'v'; control 'f')."""

    state_names, control_names, n_states, n_controls = ("p", "v"), ("f",), 2, 1
    w2, c, b, q1, q2, r = 4.0, 0.3, 2.0, 1.5, 0.2, 0.7

    def dynamics(self, x, u):
        return np.array([x[1], -self.w2 * np.sin(x[0]) - self.c * x[1] + self.b * u[0]])

    def lagrangian(self, x, u):
        return self.q1 * x[0] ** 2 + self.q2 * x[1] ** 2 + self.r * u[0] ** 2


def test_hamiltonian_hessian_is_the_closed_form_with_the_costates_curvature_term():
    """H = L + l1 v + l2 (-w2 sin p - c v + b u): H_pp = 2 q1 + l2 w2 sin p, H_vv = 2 q2,
    H_uu = 2 r, every cross term 0."""
    pend = _Pendulum()
    lam, x, u = np.array([0.4, -1.3]), np.array([0.6, 0.2]), np.array([0.1])
    W = hamiltonian_hessian(pend, lam, x, u, np.ones(3))
    expected = np.diag([2 * pend.q1 + lam[1] * pend.w2 * math.sin(x[0]), 2 * pend.q2, 2 * pend.r])
    assert W == pytest.approx(expected, abs=1e-6)


def test_law_far_from_the_end_is_the_algebraic_riccati_gain_of_the_second_variation():
    """About the rest state (p = v = u = 0, so sin p's curvature vanishes for any costate) the second
    variation is the LQR with Q = 2 diag(q1, q2), R = 2 r of the linearised plant: over 40x its time
    constant the gain at t = 0 is R^-1 B' P (P the algebraic Riccati solution), whatever the
    (numerical) scales; no terminal penalty: no gain at the end."""
    pend = _Pendulum()
    w = TrackingWeights(state_scale={"p": 0.5, "v": 2.0}, control_scale={"f": 3.0})
    t = np.linspace(0.0, 40.0, 5)
    law = neighbouring_optimal(pend, t, np.zeros((5, 2)), np.zeros((5, 1)), t, np.tile([0.3, -0.8], (5, 1)), w,
                               samples=60)
    A = np.array([[0.0, 1.0], [-pend.w2, -pend.c]])
    B = np.array([[0.0], [pend.b]])
    Q, R = 2 * np.diag([pend.q1, pend.q2]), np.array([[2 * pend.r]])
    P = solve_continuous_are(A, B, Q, R)
    assert law.gain(0.0) == pytest.approx(np.linalg.solve(R, B.T @ P), rel=1e-3)
    assert law.gain(40.0) == pytest.approx(np.zeros((1, 2)), abs=1e-9)


def test_a_concave_control_curvature_is_refused_naming_the_time():
    """H_uu <= 0 (r < 0): the Legendre-Clebsch condition fails; the error says where."""
    pend = _Pendulum()
    pend.r = -0.1
    w = TrackingWeights(state_scale={"p": 1.0, "v": 1.0}, control_scale={"f": 1.0})
    t = np.linspace(0.0, 10.0, 3)
    with pytest.raises(ScenarioError, match=r"H_uu is not positive definite at t = 0\.0 s"):
        neighbouring_optimal(pend, t, np.zeros((3, 2)), np.zeros((3, 1)), t, np.zeros((3, 2)), w, samples=5)


def test_the_odd_even_filter_removes_alternation_and_keeps_linear_values():
    """(1/4, 1/2, 1/4) between neighbours: an alternating column becomes 0 inside, a linear one
    stays as it is, the end values are kept."""
    k = np.arange(9.0)
    v = np.column_stack([3.0 * (-1.0) ** k, 2.0 - 0.5 * k])
    out = without_odd_even_mode(v)
    assert out[1:-1, 0] == pytest.approx(np.zeros(7), abs=1e-15)
    assert out[:, 1] == pytest.approx(v[:, 1], abs=1e-15)
    assert out[[0, -1], 0] == pytest.approx(v[[0, -1], 0])
