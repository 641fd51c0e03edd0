"""The fields every planner result carries, whatever the method (the way every SciPy
optimiser returns an ``OptimizeResult``): ``success``, ``message``, ``iterations``,
``build_time``, ``solve_time``, ``objective``, and ``evaluate(at)`` for the reference at
times or energies (``variable`` says which)."""
from __future__ import annotations

import dataclasses as dc
import math
from typing import ClassVar

__all__ = ["PlanResult"]


@dc.dataclass(kw_only=True)
class PlanResult:
    """Base of planner results.

    Attributes:
      success: the answer was checked and holds (never just the solver's word).
      message: the verdict in words, with the diagnosis when it failed.
      iterations: solver iterations (summed over sub-problems; 0 where none are reported).
      build_time, solve_time: wall time [s] to build the problem and in the solver.
      objective: the optimal cost in the method's units (nan where nothing is optimised).
    """

    success: bool = False
    message: str = ""
    iterations: int = 0
    build_time: float = 0.0
    solve_time: float = 0.0
    objective: float = math.nan

    #: the independent variable of ``evaluate``: 'time' [s] or 'energy' [J/kg]
    variable: ClassVar[str] = "time"

    def evaluate(self, at) -> dict:
        """The reference at ``at`` (times or energies, see ``variable``): named arrays, SI."""
        raise NotImplementedError
