"""Shrinking-horizon re-solution: the optimal-control problem posed again from a measured state
with the horizon that remains, warm-started from the previous solution (paper 002's closing
motivation: terminal guidance that re-solves the problem at each guidance cycle).

    again = resolve_from(previous, x_now, elapsed_s, verifier=fly_controls)

The remaining problem keeps every final condition, path constraint and objective term of the
original; its initial state is fixed at ``x_now`` and its final time is the original's bounds
less the elapsed time. The warm start is the previous solution from ``elapsed_s`` to its end on
the new clock, its states moved by the measured offset ``x_now - x_prev(elapsed_s)`` at the
start, fading linearly to none at the end (so the guess starts at the measured state and still
meets the final conditions the previous solution met). By the principle of optimality, from a
state on the previous optimum the remaining optimum is the previous one's tail (tested on the
brachistochrone, where it is the rest of the cycloid).
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["MIN_HORIZON_S", "GUESS_SAMPLES", "remaining_problem", "shifted_guess", "resolve_from"]

#: the shortest horizon worth re-solving [s of the problem's clock]
MIN_HORIZON_S = 1e-3
#: samples of the previous solution in the warm start
GUESS_SAMPLES = 200


def remaining_problem(problem, x_now, elapsed_s: float):
    """``problem`` from the state ``x_now`` (every state of its layout, SI) after ``elapsed_s``
    [s]: the initial state fixed there, the final-time bounds less ``elapsed_s``."""
    x = np.asarray(x_now, float).ravel()
    names = tuple(problem.state_names)
    if x.size != len(names) or not np.all(np.isfinite(x)):
        raise ScenarioError(f"x_now: expected {len(names)} finite values ({', '.join(names)}), got {x.tolist()}")
    if not (math.isfinite(elapsed_s) and elapsed_s >= 0.0):
        raise ScenarioError(f"elapsed_s = {elapsed_s}: allowed finite values >= 0 s")
    lo, hi = problem.final_time_bounds
    if hi - elapsed_s < MIN_HORIZON_S:
        raise ScenarioError(f"elapsed_s = {elapsed_s} s leaves no horizon: the final time is at most {hi} s")
    bounds = (max(lo - elapsed_s, MIN_HORIZON_S), None if math.isinf(hi) else hi - elapsed_s)
    return dc.replace(problem, initial={n: float(v) for n, v in zip(names, x)}, final_time=bounds)


def shifted_guess(previous, x_now, elapsed_s: float, samples: int = GUESS_SAMPLES):
    """(t [s], states, controls) of ``previous`` (an NlpResult) from ``elapsed_s`` to its end on
    the new clock, the states moved by the measured offset fading to none at the end."""
    tf = previous.final_time
    if not elapsed_s < tf:
        raise ScenarioError(f"elapsed_s = {elapsed_s} s is past the previous solution's final time {tf:.6g} s")
    t = np.linspace(elapsed_s, tf, samples)
    X = previous.state_function()(t)
    U = previous.control_function()(t)
    offset = np.asarray(x_now, float).ravel() - X[0]
    fade = 1.0 - (t - elapsed_s) / (tf - elapsed_s)
    return t - elapsed_s, X + fade[:, None] * offset[None, :], U


def resolve_from(previous, x_now, elapsed_s: float, *, problem=None, nodes: int | None = None, **solve_options):
    """Re-solve ``previous.problem`` (or ``problem``: the same layout, e.g. with terminal windows)
    from ``x_now`` after ``elapsed_s`` [s], warm-started from ``previous`` (``shifted_guess``).

    Args:
      nodes: the re-solution's nodes (default: the previous solution's).
      solve_options: passed to ``nlp.solve`` (transcription default: the previous one's, and
        on LGL its segments; verifier, tolerance, solver, ...).

    Returns the NlpResult on the remaining horizon's clock (t = 0 at ``x_now``); its
    ``success`` is the solve's (verified when a verifier is given).
    """
    from drake_entry.planning import nlp

    base = previous.problem if problem is None else problem
    if base is None:
        raise ScenarioError("resolve_from needs the problem: the previous result carries none, give problem=")
    remaining = remaining_problem(base, x_now, elapsed_s)
    solve_options.setdefault("transcription", previous.transcription)
    if solve_options["transcription"] == "lgl" == previous.transcription:
        solve_options.setdefault("segments", previous.segments)
    return nlp.solve(remaining, nodes=previous.nodes if nodes is None else nodes,
                     guess=shifted_guess(previous, x_now, elapsed_s), **solve_options)
