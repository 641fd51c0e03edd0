"""Algebraic Drake systems from symbolic model expressions, shared by the native plant
(systems/native_plant.py) and FNPEG's native predictor (guidance/fnpeg/predictor.py)."""
from __future__ import annotations

from pydrake.symbolic import Expression, Variable
from pydrake.systems.primitives import SymbolicVectorSystem

__all__ = ["stateless"]

_CONSTANT = Variable("constant")


def stateless(inputs: list, outputs: list) -> SymbolicVectorSystem:
    """A SymbolicVectorSystem computing ``outputs`` (Expressions) from ``inputs`` (Variables),
    evaluated in C++. It carries one constant continuous state (derivative 0): Drake 1.51
    aborts the process when a diagram with continuous state asks a SymbolicVectorSystem
    without dynamics for its derivatives."""
    return SymbolicVectorSystem(state=[_CONSTANT], input=inputs, dynamics=[Expression(0.0)], output=outputs)
