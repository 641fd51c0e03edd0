"""What the solver sees: states, controls, time and the objective divided by typical sizes.
Every factor is chosen automatically, reported in the result (``NlpResult.scaling``) and can be overridden (``solve(..., scaling={...})``).

- states, controls, time: the problem's own (entry problems: canonical units of paper 002,
  altitude in 10 km, controls by their bounds); for a ``CustomProblem`` without them, the
  largest magnitude over the guess and the fixed boundary values (controls: their finite
  bounds first), and the guess's final time.
- objective: chosen after the transcription is built so that the largest partial
  derivative of the solver's cost with respect to the scaled variables is 1 at the guess
  (a cost of 1e-3 inside the solver, e.g. a final latitude in radians divided by the time
  unit, stalls SNOPT's optimality test short of the optimum); falls back to |J(guess)|,
  then 1, when the gradient vanishes.
- constraints: path and terminal rows divided by their ``PathConstraint.scale`` (default:
  the finite bound), defects in scaled state units.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["FIELDS", "Scaling", "resolve", "objective_factor"]

FIELDS = ("states", "controls", "time", "objective")


@dc.dataclass
class Scaling:
    """Scale factors [SI per scaled unit].

    Attributes:
      states: (n_states,). controls: (n_controls,). time: [s].
      objective: cost units per unit of the solver's cost (None until the transcription
        measures it).
      source: field -> where the factor came from ('problem', 'guess', 'user', 'gradient', ...).
    """

    states: np.ndarray
    controls: np.ndarray
    time: float
    objective: float | None = None
    source: dict = dc.field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"states": [float(v) for v in self.states], "controls": [float(v) for v in self.controls],
                "time_s": float(self.time), "objective": None if self.objective is None else float(self.objective),
                "source": dict(self.source)}


def _magnitude(*arrays) -> float:
    values = np.concatenate([np.abs(np.ravel(a)) for a in arrays])
    values = values[np.isfinite(values)]
    m = float(values.max()) if values.size else 0.0
    return m if m > 0.0 else 1.0


def resolve(problem, guess, override=None) -> Scaling:
    """The scaling for ``problem`` from its own scales, the guess (t, X, U) [SI] and
    ``override`` (a Scaling or a dict with any of FIELDS)."""
    t, X, U = guess
    sx, su, ts = problem.scales()
    source = {"states": "problem", "controls": "problem", "time": "problem"}
    if sx is None:
        x0l, x0h = problem.boundary_bounds("initial")
        xfl, xfh = problem.boundary_bounds("final")
        fixed = [np.where(lo == hi, lo, np.nan) for lo, hi in ((x0l, x0h), (xfl, xfh))]
        sx = np.array([_magnitude(X[:, i], fixed[0][i], fixed[1][i]) for i in range(problem.n_states)])
        source["states"] = "guess and boundary values"
    if su is None:
        _, _, ul, uh = problem.bounds_arrays()
        su = np.array([_magnitude(np.array([ul[j], uh[j]])) if np.isfinite(ul[j]) or np.isfinite(uh[j])
                       else _magnitude(U[:, j]) for j in range(problem.n_controls)])
        source["controls"] = "bounds, else guess"
    if ts is None:
        ts = float(t[-1])
        source["time"] = "guess final time"
    scaling = Scaling(np.asarray(sx, float), np.asarray(su, float), float(ts), None, source)
    return _apply_override(problem, scaling, override)


def _apply_override(problem, scaling: Scaling, override) -> Scaling:
    if override is None:
        return scaling
    if isinstance(override, Scaling):
        override = {k: getattr(override, k) for k in FIELDS if getattr(override, k) is not None}
    if not isinstance(override, dict):
        raise ScenarioError(f"scaling must be a Scaling or a dict with keys {', '.join(FIELDS)}")
    for key, value in override.items():
        if key not in FIELDS:
            raise ScenarioError(f"scaling.{key}: unknown field; allowed: {', '.join(FIELDS)}")
        size = {"states": problem.n_states, "controls": problem.n_controls}.get(key)
        v = np.asarray(value, float) if size else float(value)
        if size and v.shape != (size,):
            raise ScenarioError(f"scaling.{key}: needs {size} values, got shape {v.shape}")
        if not np.all(np.isfinite(v)) or np.any(v <= 0):
            raise ScenarioError(f"scaling.{key} = {value}: allowed finite values > 0")
        setattr(scaling, key, v)
        scaling.source[key] = "user"
    return scaling


def objective_factor(prog, guess_values: np.ndarray) -> tuple[float, str]:
    """(factor c, how) for the solver's cost c * J_scaled: 1 / the largest |d J_scaled / d z|
    at the guess over all costs of ``prog`` (evaluated with factor 1), else 1 / |J|, else 1."""
    from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff

    grad = np.zeros(prog.num_vars())
    value = 0.0
    for b in prog.GetAllCosts():
        idx = prog.FindDecisionVariableIndices(b.variables())
        out = b.evaluator().Eval(InitializeAutoDiff(guess_values[idx]))
        value += float(ExtractValue(out).sum())
        np.add.at(grad, idx, ExtractGradient(out).sum(axis=0))
    g = float(np.abs(grad).max()) if grad.size else 0.0
    if math.isfinite(g) and g > 0.0:
        return 1.0 / g, "gradient"
    if math.isfinite(value) and value != 0.0:
        return 1.0 / abs(value), "cost value"
    return 1.0, "unit"
