import numpy as np
import pytest
from numpy.polynomial import legendre

from drake_entry.planning.pseudospectral import LGL, lgl_nodes


@pytest.mark.parametrize("n", [3, 10, 41, 161])
def test_lgl_nodes_are_roots_of_paper000_eq8(n):
    tau = lgl_nodes(n)
    N = n - 1
    dP = legendre.legval(tau[1:-1], legendre.legder(np.eye(N + 1)[N]))
    assert np.abs(dP).max() < 1e-9 * max(1, N**2)
    assert tau[0] == -1 and tau[-1] == 1 and np.all(np.diff(tau) > 0)


@pytest.mark.parametrize("n", [5, 12, 40])
def test_lgl_quadrature_is_exact_to_degree_2N_minus_1(n):
    op = LGL(n)
    N = n - 1
    for deg in range(0, 2 * N):
        exact = (1.0 - (-1.0) ** (deg + 1)) / (deg + 1)
        assert op.integrate(op.x**deg) == pytest.approx(exact, abs=1e-12)
    # and not beyond: P_N^2 (degree 2N) integrates to 2/N instead of 2/(2N+1)
    P_N = legendre.legval(op.x, np.eye(N + 1)[N])
    assert op.integrate(P_N**2) == pytest.approx(2.0 / N, rel=1e-10)
    # mapped interval (eq. 16): the integral of x^2 over [2, 7]
    mapped = LGL(n, 2.0, 7.0)
    assert mapped.integrate(mapped.x**2) == pytest.approx((7.0**3 - 2.0**3) / 3.0, rel=1e-13)


@pytest.mark.parametrize("n", [6, 20, 40])
def test_derivative_matrices_are_exact_for_degree_N(n):
    op = LGL(n, -3.0e7, -6.0e7)  # decreasing energy interval, paper-000 scale
    N = n - 1
    rng = np.random.default_rng(n)
    c = rng.standard_normal(N + 1)
    t = op.to_tau(op.x)
    p = legendre.Legendre(c)
    dt = 2.0 / (op.b - op.a)
    assert np.allclose(op.D1 @ p(t), p.deriv(1)(t) * dt, rtol=1e-9, atol=1e-9 * np.abs(p.deriv(1)(t) * dt).max())
    assert np.allclose(op.D2 @ p(t), p.deriv(2)(t) * dt**2, rtol=1e-7,
                       atol=1e-7 * np.abs(p.deriv(2)(t) * dt**2).max())


def test_weights_are_paper000_eq17_corrected():
    op = LGL(9)
    N = 8
    P = legendre.legval(op.tau, np.eye(N + 1)[N])
    assert np.allclose(op.weights_tau, 2.0 / (N * (N + 1) * P**2))
    assert op.weights_tau[0] == pytest.approx(2.0 / (N * (N + 1)))


def test_interpolation_reproduces_runge_function_paper000_fig1b():
    op = LGL(25)
    f = lambda x: 1.0 / (1.0 + 25.0 * x**2)
    xs = np.linspace(-1, 1, 1001)
    err = np.abs(op.interpolation(xs) @ f(op.x) - f(xs)).max()
    assert err < 0.02  # equispaced degree-24 interpolation errs by about 1e3 here
    assert np.allclose(op.interpolation(op.x), np.eye(25))


@pytest.mark.parametrize("m", [2, 3, 4, 6])
def test_lobatto_segment_mesh_integrates_polynomials_of_its_order_exactly(m):
    """Lobatto IIIA on a segment mesh: x_j - x_0 = integral of x' holds exactly for x of
    degree <= m (x' interpolated exactly on m nodes; m = 2: trapezoid, exact for parabolas);
    quadrature weights sum to 1."""
    from drake_entry.planning.pseudospectral import SegmentMesh

    mesh = SegmentMesh(5, m)
    assert mesh.n_nodes == 5 * (m - 1) + 1 and mesh.weights.sum() == pytest.approx(1.0, abs=1e-14)
    for deg in range(1, m + 1):
        x, xdot = mesh.s**deg, deg * mesh.s ** (deg - 1)
        for seg in mesh.segment_nodes:
            assert x[seg[1:]] - x[seg[0]] == pytest.approx(mesh.integration @ xdot[seg], abs=1e-13)
    x, xdot = mesh.s ** (m + 1), (m + 1) * mesh.s**m  # one degree higher: no longer exact
    errors = [np.abs(x[seg[1:]] - x[seg[0]] - mesh.integration @ xdot[seg]).max() for seg in mesh.segment_nodes]
    assert max(errors) > 1e-10
    # the segment interpolant reproduces degree m - 1 polynomials between the nodes
    s = np.linspace(0.0, 1.0, 37)
    assert mesh.interpolation(s) @ mesh.s ** (m - 1) == pytest.approx(s ** (m - 1), abs=1e-12)


def test_segment_mesh_rejects_bad_sizes():
    from drake_entry.errors import ScenarioError
    from drake_entry.planning.pseudospectral import SegmentMesh

    with pytest.raises(ScenarioError, match="n_segments"):
        SegmentMesh(0, 3)
    with pytest.raises(ScenarioError, match="nodes_per_segment"):
        SegmentMesh(4, 1)
