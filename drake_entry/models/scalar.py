"""Scalar-type helpers so every model is written once for float, AutoDiffXd and Expression.

NumPy's ufuncs (``np.sin``, ``np.sqrt``, ...) dispatch to pydrake's AutoDiffXd and
symbolic Expression methods, so analytic models simply use ``np``. Models that look a
value up in a table (US76 layers, aerodynamic splines) branch on the numeric value and
return an AutoDiffXd built by the chain rule from the analytic partial derivatives
(``lift``); they refuse symbolic input with a clear error.
"""
from __future__ import annotations

import numpy as np
from pydrake.autodiffutils import AutoDiffXd
from pydrake.symbolic import Expression, Variable

from drake_entry.errors import UnsupportedScalarError

__all__ = ["is_autodiff", "is_symbolic", "value_of", "lift", "clamp", "promote"]


def is_autodiff(x) -> bool:
    """True when x is a pydrake AutoDiffXd scalar."""
    return isinstance(x, AutoDiffXd)


def is_symbolic(x) -> bool:
    """True when x is a pydrake symbolic Expression or Variable."""
    return isinstance(x, (Expression, Variable))


def value_of(x):
    """The numeric value of a float, ndarray or AutoDiffXd (for table look-ups)."""
    if isinstance(x, AutoDiffXd):
        return x.value()
    if is_symbolic(x):
        raise UnsupportedScalarError(
            "this model is a table look-up and cannot take a symbolic Expression; "
            "use an analytic model (ExponentialAtmosphere, an analytic aero fit) for symbolic work"
        )
    return x


def lift(inputs, value: float, partials):
    """Combine a value and its partial derivatives into the scalar type of ``inputs``.

    Args:
      inputs: the arguments the value was computed from (floats or AutoDiffXd).
      value: the function value at the inputs' numeric values.
      partials: d value / d input_i, one per input.

    Returns a float when no input is AutoDiffXd, otherwise an AutoDiffXd whose gradient
    is sum_i partial_i * grad(input_i) (the chain rule).
    """
    grad = None
    for x, p in zip(inputs, partials):
        if isinstance(x, AutoDiffXd):
            g = float(p) * x.derivatives()
            grad = g if grad is None else grad + g
    if grad is None:
        return value
    return AutoDiffXd(float(value), grad)


def clamp(x, lo: float, hi: float):
    """x limited to [lo, hi]; the derivative is zero where the bound is active."""
    if is_symbolic(x):
        from pydrake.symbolic import max as smax
        from pydrake.symbolic import min as smin

        return smin(smax(x, lo), hi)
    v = value_of(x)
    if isinstance(v, np.ndarray):
        return np.clip(x, lo, hi)
    if v < lo:
        return lo if not is_autodiff(x) else AutoDiffXd(lo, 0.0 * x.derivatives())
    if v > hi:
        return hi if not is_autodiff(x) else AutoDiffXd(hi, 0.0 * x.derivatives())
    return x


def promote(x):
    """A bare symbolic Variable becomes an Expression (numpy ufuncs warn on Variables)."""
    return Expression(x) if isinstance(x, Variable) else x
