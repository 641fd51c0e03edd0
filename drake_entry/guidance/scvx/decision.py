"""A trajectory as SCvx's decision vector: the states at the mesh nodes with the bank and alpha
(states following their rate limits where the formulation makes them states, or the lossless
bank's (cos, sin) controls) and t_f, scaled and packed by the EntryProblem. The planner's
initial guesses and re-plans, and the direct form of the mission (as_ocp), start from it."""
from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline

from drake_entry.guidance.scvx.entry import EntryProblem
from drake_entry.guidance.scvx.guess import GlideGuess

__all__ = ["decision_from_trajectory", "initial_decision"]


def _rate_limited(t, target, rate_limit, lower, upper):
    """A path that follows ``target`` within bounds and at most ``rate_limit`` [1/s], and its rate."""
    path = np.empty(len(t))
    path[0] = np.clip(target[0], lower, upper)
    for k in range(1, len(t)):
        step = rate_limit * (t[k] - t[k - 1])
        path[k] = np.clip(path[k - 1] + np.clip(target[k] - path[k - 1], -step, step), lower, upper)
    return path, np.clip(np.gradient(path, t), -rate_limit, rate_limit)


def decision_from_trajectory(problem: EntryProblem, states, bank, alpha, tf: float, lossless_controls=None):
    """Scaled z from a trajectory at the mesh nodes: states (n, 6), bank and alpha [rad] (n,),
    t_f [s]. Where bank or alpha are states they follow the given ones within their bounds and
    rate limits (their rates are the controls), starting from the mission's held entry bank and
    alpha where it holds them; the lossless bank takes ``lossless_controls``
    (n, 2) if given, else (cos, sin) of the bank."""
    t = problem.mesh.s * tf
    X, U = [np.asarray(states, float)], []
    f, m, v = problem.formulation, problem.mission, problem.vehicle
    held = (lambda path, value: np.concatenate([[math.radians(value)], path[1:]]) if value is not None else path)
    if f.bank == "lossless":
        if lossless_controls is None and problem.rate_chords:
            bank, _ = _rate_limited(t, np.unwrap(bank), v.bank_rate_limit, -math.inf, math.inf)
        U.append(lossless_controls if lossless_controls is not None else np.stack([np.cos(bank), np.sin(bank)], axis=1))
    else:
        sigma, rate = _rate_limited(t, held(np.unwrap(bank), m.entry_bank_deg), v.bank_rate_limit, -v.bank_limit,
                                    v.bank_limit)
        X.append(sigma[:, None])
        U.append(rate[:, None])
    if f.alpha == "rate":
        lo, hi = np.radians(m.alpha_bounds_deg)
        a, rate = _rate_limited(t, held(np.asarray(alpha, float), m.entry_alpha_deg),
                                math.radians(m.alpha_rate_limit_deg_s), lo, hi)
        X.append(a[:, None])
        U.append(rate[:, None])
    return problem.pack(np.concatenate(X, axis=1), np.concatenate(U, axis=1), tf)


def initial_decision(problem: EntryProblem, guess: GlideGuess) -> np.ndarray:
    """z from a glide guess: states by cubic spline at the mesh times, its bank, and its alpha
    where it has one (a re-plan's) else the mission's alpha(V)."""
    t = problem.mesh.s * guess.final_time
    T, idx = np.unique(guess.time, return_index=True)
    X = CubicSpline(T, guess.states[idx])(t)
    bank = np.interp(t, T, guess.bank[idx])
    if guess.alpha is not None:
        alpha = np.interp(t, T, guess.alpha[idx])
    else:
        alpha = np.array([problem.alpha(float(V)) for V in X[:, 3]])
    return decision_from_trajectory(problem, X, bank, alpha, guess.final_time)
