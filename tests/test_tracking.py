"""planning.tracking: the linearisation against finite differences of the problem's
dynamics, the TVLQR gain against the algebraic Riccati solution of a time-invariant plant,
the law's interpolation and the weights' errors."""
import math

import numpy as np
import pytest
from scipy.linalg import solve_continuous_are

from drake_entry.errors import ScenarioError
from drake_entry.planning.tracking import CommandFeedback, TrackingLaw, TrackingWeights, linearise, tvlqr


class _Oscillator:
    """A damped oscillator x1' = x2, x2' = -w^2 x1 - c x2 + b u (state 'p', 'v'; control 'f')."""

    state_names, control_names, n_states, n_controls = ("p", "v"), ("f",), 2, 1
    A = np.array([[0.0, 1.0], [-4.0, -0.3]])
    B = np.array([[0.0], [2.0]])

    def dynamics(self, x, u):
        return self.A @ x + self.B @ u


def test_tvlqr_gain_far_from_the_end_is_the_algebraic_riccati_gain_in_si_units():
    """Over a horizon 40x the plant's time constant the finite-horizon gain at t0 is the
    infinite-horizon one, K = R^-1 B' P; the scales (p 0.5, v 2, f 3) are undone in K."""
    plant = _Oscillator()
    w = TrackingWeights(state_scale={"p": 0.5, "v": 2.0}, control_scale={"f": 3.0}, state_weight=0.7)
    t = np.linspace(0.0, 40.0, 5)
    law = tvlqr(plant, t, np.zeros((5, 2)), np.zeros((5, 1)), w, samples=50)
    sx, su = np.array([0.5, 2.0]), np.array([3.0])
    A_s, B_s = plant.A * sx[None, :] / sx[:, None], plant.B * su[None, :] / sx[:, None]
    P = solve_continuous_are(A_s, B_s, 0.7 * np.eye(2), np.eye(1))
    K_si = (B_s.T @ P) * su[:, None] / sx[None, :]
    assert law.gain(0.0) == pytest.approx(K_si, rel=1e-3)
    assert law.gain(40.0) == pytest.approx(np.zeros((1, 2)), abs=1e-9)  # Q_f = 0: no gain at the end
    # the law: u_ref - K (x - x_ref), held after the last sample
    assert law.command(0.0, [1.0, 0.0]) == pytest.approx(-K_si[:, 0], rel=1e-3)
    assert law.command(99.0, [1.0, 0.0]) == pytest.approx([0.0], abs=1e-9)


def test_linearisation_of_the_shefex3_dynamics_matches_finite_differences():
    from drake_entry.planning.ocp_yaml import load_problem

    problem, _ = load_problem("shefex3")
    x = np.array([60e3, math.radians(-30.0), math.radians(66.0), 4000.0, math.radians(-1.0), math.radians(-20.0),
                  math.radians(25.0), 100.0])
    u = np.array([math.radians(2.0)])
    A, B = linearise(problem, [100.0], x[None, :], u[None, :])
    f = lambda x_, u_: np.asarray(problem.dynamics(x_, u_), float)  # noqa: E731
    for j in range(8):
        e = np.zeros(8)
        e[j] = 1e-6 * max(1.0, abs(x[j]))
        fd = (f(x + e, u) - f(x - e, u)) / (2 * e[j])
        assert A[0][:, j] == pytest.approx(fd, rel=1e-5, abs=1e-10), problem.state_names[j]
    e = 1e-6
    fd = (f(x, u + e) - f(x, u - e)) / (2 * e)
    assert B[0][:, 0] == pytest.approx(fd, rel=1e-6, abs=1e-12)


def test_tracking_law_interpolates_linearly_between_samples():
    law = TrackingLaw(np.array([0.0, 10.0]), np.array([[0.0, 0.0], [10.0, 20.0]]), np.array([[1.0], [3.0]]),
                      np.array([0.0, 10.0]), np.array([[[1.0, 0.0]], [[3.0, 0.0]]]))
    x_ref, u_ref = law.reference(2.5)
    assert x_ref == pytest.approx([2.5, 5.0]) and u_ref == pytest.approx([1.5])
    assert law.command(5.0, [6.0, 10.0]) == pytest.approx([2.0 - 2.0 * 1.0])


def test_weights_and_reference_errors_name_the_field():
    plant = _Oscillator()
    t, X, U = np.linspace(0, 1, 3), np.zeros((3, 2)), np.zeros((3, 1))
    with pytest.raises(ScenarioError, match="TrackingWeights.state_scale: unknown name 'q'; allowed p, v"):
        tvlqr(plant, t, X, U, TrackingWeights({"q": 1.0}, {"f": 1.0}))
    with pytest.raises(ScenarioError, match="control_scale needs every control; missing 'f'"):
        tvlqr(plant, t, X, U, TrackingWeights({"p": 1.0}, {}))
    with pytest.raises(ScenarioError, match=r"TrackingWeights.terminal_scale\['p'\] = -1.0: must be > 0"):
        tvlqr(plant, t, X, U, TrackingWeights({"p": 1.0}, {"f": 1.0}, terminal_scale={"p": -1.0}))
    with pytest.raises(ScenarioError, match="time_s must be increasing"):
        tvlqr(plant, t[::-1], X, U, TrackingWeights({"p": 1.0}, {"f": 1.0}))
    with pytest.raises(ScenarioError, match=r"states \(3, 3\) and controls"):
        tvlqr(plant, t, np.zeros((3, 3)), U, TrackingWeights({"p": 1.0}, {"f": 1.0}))


def test_entry_defaults_are_the_ampi_guidance_defaults():
    from drake_entry.guidance.ampi.spec import Ampi

    assert Ampi().weights() == TrackingWeights.entry()


def test_command_feedback_puts_the_estimate_and_the_offsets_into_the_law_state():
    """An 8-state law (six entry states, alpha, sigma; controls u_alpha, u_sigma) with a known
    gain: the offsets (sigma, alpha) are the commanded states' deviations, the estimate gives
    the first six, and the rates are -K (x - x_ref) of each offset's rate control."""
    K = np.arange(16.0).reshape(2, 8) / 10.0
    x_ref = np.array([30e3, 0.1, 0.0, 5000.0, -0.1, 1.5, 0.2, 0.7])
    law = TrackingLaw(np.array([0.0, 100.0]), np.vstack([x_ref, x_ref]), np.zeros((2, 2)),
                      np.array([0.0, 100.0]), np.stack([K, K]))
    fb = CommandFeedback(law, ((7, 1), (6, 0)))  # offsets (sigma, alpha)
    assert fb.rates(50.0, x_ref[:6], [0.0, 0.0]) == pytest.approx([0.0, 0.0], abs=1e-12)
    estimate = x_ref[:6] + np.array([100.0, 0.0, 0.0, -5.0, 0.0, 0.0])
    dx = np.array([100.0, 0.0, 0.0, -5.0, 0.0, 0.0, -0.03, 0.02])
    expected = -K @ dx
    assert fb.rates(50.0, estimate, [0.02, -0.03]) == pytest.approx([expected[1], expected[0]], rel=1e-12)
