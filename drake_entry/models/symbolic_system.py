"""Algebraic Drake systems from symbolic model expressions, shared by the native plant
(systems/native_plant.py), FNPEG's native predictor (guidance/fnpeg/predictor.py) and the
native optimal-control plant (planning/ocp_system.py)."""
from __future__ import annotations

from pydrake.symbolic import Expression, Variable
from pydrake.systems.primitives import SymbolicVectorSystem

__all__ = ["stateless", "expression"]

_CONSTANT = Variable("constant")


def stateless(inputs: list, outputs: list) -> SymbolicVectorSystem:
    """A SymbolicVectorSystem computing ``outputs`` (Expressions) from ``inputs`` (Variables),
    evaluated in C++. It carries one constant continuous state (derivative 0): Drake 1.51
    aborts the process when a diagram with continuous state asks a SymbolicVectorSystem
    without dynamics for its derivatives."""
    return SymbolicVectorSystem(state=[_CONSTANT], input=inputs, dynamics=[Expression(0.0)], output=outputs)


def expression(v) -> Expression:
    """``v`` as a symbolic Expression: a model value that came out a plain number (a term
    without the state, e.g. a constant derivative) wrapped, an Expression as it is."""
    return v if isinstance(v, Expression) else Expression(float(v))
