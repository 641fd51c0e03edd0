"""Vectorised evaluation of a model's symbolic form: ``ExpressionTape``.

The models (drake_entry.models) are written once for float, AutoDiffXd and symbolic
Expression scalars. Called with symbolic Variables they return Drake Expressions (table
look-ups as ``if_then_else`` pieces, as the native plant uses them). An ExpressionTape
flattens those Expressions once into a list of NumPy operations with their common
sub-expressions shared, then evaluates them at many points at once: the values, and with
``gradients=True`` their Jacobian with respect to the variables by forward-mode
differentiation of every operation (the chain rule an AutoDiffXd applies, on arrays).

Why: a planner that evaluates the model at 100 nodes calls the Python model 100 times (about
40 us each) and, for a linearisation, builds 100 AutoDiffXd evaluations (about 300 us each).
The tape evaluates all nodes in one pass of array operations. Drake's own
``Expression.Evaluate`` walks the tree per point (slower than the Python model for these
trees) and the symbolic Jacobian grows too large to evaluate, hence this module.

Table look-ups stay out of the tape: an atmosphere (hundreds of spline pieces as
``if_then_else``, which a vectorised pass would all compute) enters the trace through
``TracedAtmosphere`` as the uninterpreted functions ``density(h)`` and ``temperature(h)``, and the
tape calls the atmosphere's own array path for them (values and altitude derivatives).

Semantics, as the float and AutoDiffXd paths: ``if_then_else`` takes the branch of its
condition at each point (and that branch's derivative); ``min``/``max`` the derivative of the
argument chosen; ``abs`` the sign; ``floor``/``ceil`` derivative 0. Both branches of a
condition are computed at every point, so floating-point warnings of the branch not taken are
silenced.
"""
from __future__ import annotations

import math
import operator

import numpy as np
from pydrake.symbolic import Expression, ExpressionKind, Formula, FormulaKind, Variable, uninterpreted_function

from drake_entry.errors import UnsupportedScalarError
from drake_entry.models.atmosphere import Atmosphere

__all__ = ["ExpressionTape", "TracedAtmosphere"]

_UNARY = {  # kind -> (value, derivative d f / d a as a function of (a, f))
    ExpressionKind.Log: (np.log, lambda a, f: 1.0 / a),
    ExpressionKind.Exp: (np.exp, lambda a, f: f),
    ExpressionKind.Sqrt: (np.sqrt, lambda a, f: 0.5 / f),
    ExpressionKind.Sin: (np.sin, lambda a, f: np.cos(a)),
    ExpressionKind.Cos: (np.cos, lambda a, f: -np.sin(a)),
    ExpressionKind.Tan: (np.tan, lambda a, f: 1.0 + f * f),
    ExpressionKind.Asin: (np.arcsin, lambda a, f: 1.0 / np.sqrt(1.0 - a * a)),
    ExpressionKind.Acos: (np.arccos, lambda a, f: -1.0 / np.sqrt(1.0 - a * a)),
    ExpressionKind.Atan: (np.arctan, lambda a, f: 1.0 / (1.0 + a * a)),
    ExpressionKind.Sinh: (np.sinh, lambda a, f: np.cosh(a)),
    ExpressionKind.Cosh: (np.cosh, lambda a, f: np.sinh(a)),
    ExpressionKind.Tanh: (np.tanh, lambda a, f: 1.0 - f * f),
    ExpressionKind.Abs: (np.abs, lambda a, f: np.sign(a)),
    ExpressionKind.Floor: (np.floor, lambda a, f: np.zeros_like(a)),
    ExpressionKind.Ceil: (np.ceil, lambda a, f: np.zeros_like(a)),
}
_COMPARE = {FormulaKind.Lt: operator.lt, FormulaKind.Leq: operator.le, FormulaKind.Gt: operator.gt,
            FormulaKind.Geq: operator.ge, FormulaKind.Eq: operator.eq, FormulaKind.Neq: operator.ne}


class ExpressionTape:
    """``outputs`` (Expressions or floats) of ``variables`` as one vectorised evaluator.

    ``functions``: name -> f(*argument arrays) returning (value, [d value / d argument, ...]),
    for the uninterpreted functions in ``outputs`` (``TracedAtmosphere.functions``).
    ``tape(points)`` with points (n, len(variables)) returns the values (n, len(outputs));
    ``tape(points, gradients=True)`` returns (values, Jacobians (n, len(outputs),
    len(variables))). ``size`` is the number of operations after sharing.
    """

    def __init__(self, outputs, variables, functions: dict | None = None):
        self.variables = list(variables)
        self.functions = dict(functions or {})
        self.n_in = len(self.variables)
        self._ops = []  # (slot, kind, args): kind names an operation, args slots or constants
        self._slots = {}  # expression text -> slot
        self._formulas = {}
        self._constants = {}  # slot -> value of constant slots
        for i, v in enumerate(self.variables):
            self._slots[Expression(v).to_string()] = i
        self._n = self.n_in
        self.output_slots = [self._slot(o) for o in outputs]
        self.size = len(self._ops)

    # ----- building -------------------------------------------------------------------------
    def _new(self, kind, args, constant=None):
        slot = self._n
        self._n += 1
        if constant is not None:
            self._constants[slot] = constant
        else:
            self._ops.append((slot, kind, args))
        return slot

    def _slot(self, e) -> int:
        if isinstance(e, Variable):
            e = Expression(e)
        if not isinstance(e, Expression):
            return self._new("constant", (), float(e))
        key = e.to_string()
        if key in self._slots:
            return self._slots[key]
        kind = e.get_kind()
        if kind == ExpressionKind.Constant:
            slot = self._new("constant", (), float(e.Evaluate()))
        elif kind == ExpressionKind.Var:
            raise UnsupportedScalarError(f"ExpressionTape: variable {key} is not among the tape's variables")
        else:
            _, args = e.Unapply()
            if kind == ExpressionKind.Add:  # constant + sum of terms
                slot = self._new("add", (float(args[0]), [self._slot(a) for a in args[1:]]))
            elif kind == ExpressionKind.Mul:  # constant * product of factors
                slot = self._new("mul", (float(args[0]), [self._slot(a) for a in args[1:]]))
            elif kind in (ExpressionKind.Div, ExpressionKind.Pow, ExpressionKind.Atan2, ExpressionKind.Min,
                          ExpressionKind.Max):
                slot = self._new(kind.name.lower(), tuple(self._slot(a) for a in args))
            elif kind in _UNARY:
                slot = self._new(kind, (self._slot(args[0]),))
            elif kind == ExpressionKind.IfThenElse:
                slot = self._new("if", (self._formula(args[0]), self._slot(args[1]), self._slot(args[2])))
            elif kind == ExpressionKind.UninterpretedFunction and args[0] in self.functions:
                slot = self._new("call", (args[0], [self._slot(a) for a in args[1]]))
            else:
                raise UnsupportedScalarError(f"ExpressionTape: no vectorised form of {kind.name} ({key[:80]})")
        self._slots[key] = slot
        return slot

    def _formula(self, f: Formula):
        key = f.to_string()
        if key in self._formulas:
            return self._formulas[key]
        kind = f.get_kind()
        _, args = f.Unapply()
        if kind in _COMPARE:
            node = ("compare", kind, self._slot(args[0]), self._slot(args[1]))
        elif kind in (FormulaKind.And, FormulaKind.Or):
            node = (kind.name.lower(), [self._formula(a) for a in args])
        elif kind == FormulaKind.Not:
            node = ("not", self._formula(args[0]))
        elif kind in (FormulaKind.True_, FormulaKind.False_):
            node = ("bool", kind == FormulaKind.True_)
        else:
            raise UnsupportedScalarError(f"ExpressionTape: no vectorised form of the condition {key[:80]}")
        self._formulas[key] = node
        return node

    # ----- evaluation -----------------------------------------------------------------------
    def __call__(self, points, gradients: bool = False):
        p = np.asarray(points, float)
        if p.ndim != 2 or p.shape[1] != self.n_in:
            raise ValueError(f"ExpressionTape needs points of shape (n, {self.n_in}); got {p.shape}")
        n = p.shape[0]
        val = [None] * self._n
        der = [None] * self._n if gradients else None
        for i in range(self.n_in):
            val[i] = p[:, i]
            if gradients:
                g = np.zeros((n, self.n_in))
                g[:, i] = 1.0
                der[i] = g
        for slot, c in self._constants.items():
            val[slot] = c
        with np.errstate(all="ignore"):
            for slot, kind, args in self._ops:
                val[slot], d = self._apply(kind, args, val, der)
                if gradients:
                    der[slot] = d
        values = np.column_stack([np.broadcast_to(val[s], (n,)) for s in self.output_slots])
        if not gradients:
            return values
        jac = np.zeros((n, len(self.output_slots), self.n_in))
        for k, s in enumerate(self.output_slots):
            if der[s] is not None:
                jac[:, k, :] = der[s]
        return values, jac

    def _condition(self, node, val):
        kind = node[0]
        if kind == "compare":
            return _COMPARE[node[1]](val[node[2]], val[node[3]])
        if kind == "and":
            return np.logical_and.reduce([self._condition(a, val) for a in node[1]])
        if kind == "or":
            return np.logical_or.reduce([self._condition(a, val) for a in node[1]])
        if kind == "not":
            return np.logical_not(self._condition(node[1], val))
        return node[1]

    def _apply(self, kind, args, val, der):
        """(value, derivative or None) of one operation; der None: values only."""
        grad = der is not None
        if kind == "add":
            c, terms = args
            v = c + sum(val[t] for t in terms)
            return v, (_sum([der[t] for t in terms]) if grad else None)
        if kind == "mul":
            c, factors = args
            vals = [val[f] for f in factors]
            v = c * math.prod(vals) if len(vals) > 1 else c * vals[0]
            if not grad:
                return v, None
            parts = []
            for i, f in enumerate(factors):
                if der[f] is None:
                    continue
                others = c * math.prod(vals[:i] + vals[i + 1:]) if len(vals) > 1 else c
                parts.append(_scale(others, der[f]))
            return v, _sum(parts)
        if kind == "div":
            a, b = val[args[0]], val[args[1]]
            v = a / b
            return v, (_sum([_scale(1.0 / b, der[args[0]]), _scale(-v / b, der[args[1]])]) if grad else None)
        if kind == "pow":
            a, b = val[args[0]], val[args[1]]
            v = a ** b
            if not grad:
                return v, None
            da, db = der[args[0]], der[args[1]]
            parts = [_scale(b * a ** (b - 1.0), da)]
            if db is not None:
                parts.append(_scale(v * np.log(a), db))
            return v, _sum(parts)
        if kind == "atan2":  # atan2(y, x)
            y, x = val[args[0]], val[args[1]]
            v = np.arctan2(y, x)
            r2 = x * x + y * y
            return v, (_sum([_scale(x / r2, der[args[0]]), _scale(-y / r2, der[args[1]])]) if grad else None)
        if kind in ("min", "max"):
            a, b = val[args[0]], val[args[1]]
            first = a <= b if kind == "min" else a >= b
            v = np.where(first, a, b)
            return v, (_where(first, der[args[0]], der[args[1]]) if grad else None)
        if kind == "call":
            name, slots = args
            v, partials = self.functions[name](*(val[a] for a in slots))
            return v, (_sum([_scale(p, der[a]) for p, a in zip(partials, slots)]) if grad else None)
        if kind == "if":
            cond = self._condition(args[0], val)
            v = np.where(cond, val[args[1]], val[args[2]])
            return v, (_where(cond, der[args[1]], der[args[2]]) if grad else None)
        f, df = _UNARY[kind]
        a = val[args[0]]
        v = f(a)
        return v, (_scale(df(a, v), der[args[0]]) if grad else None)


def _scale(factor, d):
    """factor (n,) or scalar times a derivative (n, m) or None."""
    if d is None:
        return None
    return (factor[:, None] if np.ndim(factor) else factor) * d


def _sum(parts):
    parts = [p for p in parts if p is not None]
    if not parts:
        return None
    total = parts[0]
    for p in parts[1:]:
        total = total + p
    return total


def _where(cond, a, b):
    if a is None and b is None:
        return None
    c = np.asarray(cond)
    c = c[:, None] if c.ndim else c
    a = 0.0 if a is None else a
    b = 0.0 if b is None else b
    return np.where(c, a, b)


class TracedAtmosphere(Atmosphere):
    """``base`` as the symbolic trace of an ExpressionTape sees it: density and temperature are
    the uninterpreted functions ``density(h)`` and ``temperature(h)`` (h the altitude the
    atmosphere is given), which ``functions`` evaluates on arrays with ``base``'s own array path
    (its range check included). Everything else (speed of sound, gas constants) is ``base``'s."""

    def __init__(self, base: Atmosphere):
        self.base = base
        self.name, self.h_min, self.h_max = base.name, base.h_min, base.h_max
        self.gas_constant, self.gamma = base.gas_constant, base.gamma
        self.functions = {"density": self._density, "temperature": self._temperature}

    def symbolic_profile(self, h) -> tuple:
        h = Expression(h) if isinstance(h, Variable) else h
        return uninterpreted_function("density", [h]), uninterpreted_function("temperature", [h])

    def density_derivatives(self, h):
        return self.base.density_derivatives(h)

    def temperature_derivatives(self, h):
        return self.base.temperature_derivatives(h)

    def _density(self, h):
        d = self.base.density_derivatives(np.atleast_1d(np.asarray(h, float)))
        return d.value, [d.d_h]

    def _temperature(self, h):
        t = self.base.temperature_derivatives(np.atleast_1d(np.asarray(h, float)))
        return t.value, [t.d_h]
