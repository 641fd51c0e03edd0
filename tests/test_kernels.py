"""Compiled kernels (models.kernels) against the Drake expressions they are written from: every
expression kind, branches and tables at and between their breaks, the cache, the errors."""
import math

import numpy as np
import pytest
from pydrake.symbolic import Expression, Variable, if_then_else, logical_and, logical_not, logical_or
from pydrake.symbolic import max as smax
from pydrake.symbolic import min as smin

from drake_entry.errors import UnsupportedScalarError
from drake_entry.models import atmosphere as atm
from drake_entry.models import kernels
from drake_entry.models.kernels import Kernel, compile_kernels, kernel_source

X, Y, Z = Variable("x"), Variable("y"), Variable("z")
#: numpy's object loops on Expressions (np.sin(x) and the like) report stray floating-point flags
pytestmark = pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("DRAKE_ENTRY_KERNEL_CACHE", str(tmp_path))


def _evaluate(outputs, point):
    env = dict(zip((X, Y, Z), point))
    return np.array([o.Evaluate(env) for o in outputs])


def _run(outputs, points, tag="test", compare=True):
    k = compile_kernels([Kernel("f", tuple(outputs), (X, Y, Z))], tag=tag)
    got = []
    for p in points:
        out = np.empty(len(outputs))
        k["f"](np.asarray(p, float), out)
        got.append(out)
    return np.array(got), np.array([_evaluate(outputs, p) for p in points]) if compare else None, k


def test_every_expression_kind_is_drakes_value():
    """Sums, products, quotients, powers, the unary and binary functions, min/max and nested
    if_then_else with and/or/not conditions, at random points: equal to Drake's Evaluate to 1e-14."""
    x, y, z = Expression(X), Expression(Y), Expression(Z)
    outputs = [3.0 + 2.0 * x - y * z / 4.0, x ** 2 + y ** 3 + abs(z) ** 0.5, np.exp(-x) * np.log(2.0 + y * y),
               np.sin(x) + np.cos(y) + np.tan(0.3 * z), np.arcsin(0.5 * np.tanh(x)) + np.arccos(0.4 * np.sin(y)),
               np.arctan(z) + np.arctan2(y, x), np.sinh(0.2 * x) * np.cosh(0.1 * y), np.sqrt(1.0 + z * z),
               smin(x, y) + smax(y, z), np.floor(3.0 * x) + np.ceil(2.0 * y),
               if_then_else(logical_and(x < y, logical_or(z >= 0.0, logical_not(x > 0.5))), x * y, if_then_else(y <= z, z - y, x / (1.0 + y * y))),
               Expression(7.5)]
    rng = np.random.default_rng(3)
    got, want, _ = _run(outputs, rng.uniform(-2.0, 2.0, (300, 3)))
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14)


def test_a_shared_value_is_written_once_outside_the_branches():
    """A value used in both branches (and outside) is computed once, before them."""
    x, y = Expression(X), Expression(Y)
    shared = np.exp(np.sin(x) * y)
    src = kernel_source(Kernel("f", (if_then_else(x < 0.0, shared + 1.0, 2.0 * shared), shared), (X, Y, Z)))
    assert src.count("math.exp(") == 1 and src.index("math.exp(") < src.index("if (")


def test_a_table_is_a_look_up_whose_size_does_not_grow_with_its_pieces():
    """A US76-style piecewise table of 200 cubics (models.atmosphere.piecewise) is written as a
    binary search of constant arrays: a few statements, not 200 branches (the piece at the
    zero break, where x - 0 is x, has a formula of its own: dispatched on); its values equal
    Drake's at every break (the piece to the right), between breaks and beyond both ends; a NaN
    argument gives NaN (Drake refuses to evaluate it)."""
    breaks = np.linspace(0.0, 100.0, 201)
    coeffs = np.random.default_rng(5).normal(size=(200, 4))
    x = Expression(X)

    def piece(i):
        t = x - breaks[i]
        c3, c2, c1, c0 = coeffs[i]
        return ((c3 * t + c2) * t + c1) * t + c0

    table = atm.piecewise(x, list(breaks), piece)
    source = kernel_source(Kernel("f", (table,), (X, Y, Z)))
    assert "np.searchsorted" in source and source.count("\n") < 30 and "(v[0] <" not in source
    points = [[b, 0.0, 0.0] for b in breaks] + [[b + 0.37, 0.0, 0.0] for b in breaks] + [[-5.0, 0, 0], [150.0, 0, 0]]
    got, want, _ = _run([table], points)
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13)
    nan, _, _ = _run([table], [[math.nan, 0.0, 0.0]], compare=False)
    assert math.isnan(nan[0, 0])


def test_the_us76_atmosphere_compiles_to_its_own_values():
    """US76 (seven layers below 86 km, a 1-km spline table above) as density and temperature
    kernels, against the float model at 2000 altitudes from -5 to 1000 km (1e-13)."""
    model = atm.US76Atmosphere()
    rho, T = model.symbolic_profile(Expression(X))
    h = np.concatenate([np.linspace(-5e3, 1e6, 1997), [86e3, 11e3, 1e6]])
    got, _, k = _run([rho, T], [[v, 0.0, 0.0] for v in h])
    want = model.derivatives(h)
    np.testing.assert_allclose(got[:, 0], want[0].value, rtol=1e-13)
    np.testing.assert_allclose(got[:, 1], want[1].value, rtol=1e-13)
    assert k.statements["f"] < 200  # the 914 upper-table pieces are two look-ups


def test_a_domain_error_is_nan_not_an_exception():
    """Where Drake's evaluation raises (sqrt(-1), log(-1), 1/0), a kernel returns NaN or inf:
    the caller checks (FNPEG's predicted flight stops with its reason)."""
    got, _, _ = _run([np.sqrt(Expression(X)), np.log(Expression(Y)), Expression(X) / Expression(Z)],
                     [[-1.0, -1.0, 0.0]], compare=False)
    assert math.isnan(got[0, 0]) and math.isnan(got[0, 1]) and got[0, 2] == -math.inf


def test_the_module_is_written_once_under_its_hash_and_reused(tmp_path):
    k1 = compile_kernels([Kernel("f", (Expression(X) * 2.0,), (X,))], tag="twice")
    k2 = compile_kernels([Kernel("f", (Expression(X) * 2.0,), (X,))], tag="twice")
    assert k1 is k2 and k1.path.parent == tmp_path and k1.path.name.startswith("twice_")
    k3 = compile_kernels([Kernel("f", (Expression(X) * 3.0,), (X,))], tag="twice")
    assert k3.path != k1.path
    out = np.empty(1)
    k3["f"](np.array([2.0]), out)
    assert out[0] == 6.0


def test_a_variable_outside_the_kernel_is_named():
    with pytest.raises(UnsupportedScalarError, match="variable y is not among the kernel's variables"):
        kernel_source(Kernel("f", (Expression(X) + Expression(Y),), (X,)))


def test_the_cache_directory_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("DRAKE_ENTRY_KERNEL_CACHE", str(tmp_path / "k"))
    assert kernels.kernel_cache_dir() == tmp_path / "k"
    monkeypatch.delenv("DRAKE_ENTRY_KERNEL_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert kernels.kernel_cache_dir() == tmp_path / "xdg" / "drake_entry" / "kernels"


def test_a_read_only_cache_falls_back_to_a_temporary_directory(tmp_path, monkeypatch):
    """A cache directory that cannot be written (a read-only home on a cluster node) does not stop
    the work: the module is written and compiled in this user's temporary directory."""
    blocked = tmp_path / "file"
    blocked.write_text("a file, not a directory")
    monkeypatch.setenv("DRAKE_ENTRY_KERNEL_CACHE", str(blocked / "kernels"))
    monkeypatch.setattr(kernels, "_scratch_dir", lambda: tmp_path / "scratch")
    k = compile_kernels([Kernel("f", (Expression(X) * 5.0,), (X,))], tag="fallback")
    assert k.path.parent == tmp_path / "scratch"
    out = np.empty(1)
    k["f"](np.array([2.0]), out)
    assert out[0] == 10.0
