"""Plan an entry with SCvx (paper 001): glide guess -> EntryProblem -> solve_scvx -> ScvxPlan,
with the answer re-checked between the nodes before it is called a success."""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np
from scipy.interpolate import CubicSpline

from ...atmosphere import Atmosphere
from ...dynamics import STATE_NAMES, flight_conditions
from ...planet import Earth
from ...vehicles import Vehicle
from ..result import PlanResult
from .engine import ScvxSettings, max_defect, max_violation, solve_scvx
from .entry import EntryProblem, EntryProblemSettings
from .guess import GlideGuess, glide_guess
from .mission import ScvxMission

#: the lossless gap is judged where the lift can act: L >= this fraction of g0
GAP_LIFT_FRACTION = 0.05
#: between-node re-check: relative tolerance on heat flux and load, absolute on gamma [rad]
BETWEEN_NODE_TOLERANCE = (0.02, 0.02, math.radians(0.2))


@dc.dataclass(kw_only=True)
class ScvxPlan(PlanResult):
    """An SCvx entry plan (a PlanResult over time; ``objective``: heat load [MJ/m^2] or t_f [s]).

    Attributes:
      time: node times [s]; states: (n, 6) SI; controls: (n, 2) = (u1, u2) at the mesh nodes;
        final_time: t_f [s].
      bank: atan2(u2, u1) [rad] and alpha: alpha(V) [rad], at the nodes.
      heat_load: integral of q dt [J/m^2] (the paper's objective, without the regulariser).
      lossless_gap: max(1 - |u|) over nodes where L >= 5 % g0; lossless_gap_all: over all nodes.
      max_defect, max_violation: largest scaled dynamics defect and constraint violation.
      between_nodes: worst relative excess of q and n and of gamma [rad] over their limits on
        the segment polynomials between the nodes (8 points per segment).
      miss_m: planned DRS point to the site [m]; drs: planned DRS altitude (geodetic) [m], Mach,
        vertical speed [m/s].
      peaks: max heat flux [W/m^2], max total load [g].
      guess: the glide guess it started from; history: the engine's IterationRecords.
    """

    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    final_time: float
    bank: np.ndarray
    alpha: np.ndarray
    heat_load: float
    lossless_gap: float
    lossless_gap_all: float
    max_defect: float
    max_violation: float
    between_nodes: dict
    miss_m: float
    drs: dict
    peaks: dict
    guess: GlideGuess | None = None
    history: list = dc.field(default_factory=list, repr=False)
    problem: EntryProblem | None = dc.field(default=None, repr=False)

    def evaluate(self, at) -> dict:
        """States (h, lon, lat, V, gamma, psi), u1, u2, bank and alpha at times ``at`` [s], on the
        plan's own segment polynomials."""
        t = np.clip(np.atleast_1d(np.asarray(at, float)), 0.0, self.final_time)
        P = self.problem.mesh.interpolation(t / self.final_time)
        X, U = P @ self.states, P @ self.controls
        out = {n: X[:, i] for i, n in enumerate(STATE_NAMES)}
        out.update(u1=U[:, 0], u2=U[:, 1], bank=np.arctan2(U[:, 1], U[:, 0]),
                   alpha=np.array([self.problem.alpha(float(v)) for v in X[:, 3]]))
        return out


def initial_decision(problem: EntryProblem, guess: GlideGuess) -> np.ndarray:
    """z from a glide guess: states by cubic spline at the mesh times, u = (cos, sin) of its bank."""
    t = problem.mesh.s * guess.final_time
    T, idx = np.unique(guess.time, return_index=True)
    X = CubicSpline(T, guess.states[idx])(t)
    bank = np.interp(t, T, guess.bank[idx])
    return problem.pack(X, np.stack([np.cos(bank), np.sin(bank)], axis=1), guess.final_time)


def _between_nodes(problem: EntryProblem, plan_states, plan_controls) -> dict:
    """Worst excess of q, n (relative) and gamma (rad) over their limits between the nodes."""
    mesh = problem.mesh
    s = (np.arange(mesh.n_segments)[:, None] + (np.arange(8)[None, :] + 0.5) / 8.0).ravel() / mesh.n_segments
    P = mesh.interpolation(s)
    X, U = P @ plan_states, P @ plan_controls
    lim = problem.vehicle.limits
    q = np.empty(len(s))
    n = np.empty(len(s))
    for k in range(len(s)):
        out = problem.node_outputs(X[k], U[k])
        q[k], n[k] = out[6], out[7]
    g_lo, g_hi = np.radians(problem.mission.flight_path_bounds_deg)
    return {"heat_flux": float(max(q.max() / lim.heat_flux_max - 1.0, 0.0)),
            "total_load": float(max(n.max() / lim.total_load_max - 1.0, 0.0)),
            "flight_path_rad": float(max((g_lo - X[:, 4]).max(), (X[:, 4] - g_hi).max(), 0.0))}


def plan_entry(vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission, *,
               problem_settings: EntryProblemSettings | None = None, settings: ScvxSettings | None = None,
               guess: GlideGuess | None = None, initial=None, progress=None) -> ScvxPlan:
    """Plan the mission: the glide guess (unless given), SCvx, then the between-node check.

    Args:
      initial: a previous ScvxPlan to start from instead of the guess (a warm start; its
        mesh may differ, it is interpolated).
      progress: ``progress(k, IterationRecord)`` after every iteration.
    """
    t0 = time.perf_counter()
    ps = problem_settings or EntryProblemSettings()
    if initial is None and guess is None:
        guess = glide_guess(vehicle, planet, atmosphere, mission)
    tf0 = initial.final_time if initial is not None else guess.final_time
    problem = EntryProblem(vehicle, planet, atmosphere, mission, ps, tf0)
    if initial is not None:
        ref = initial.evaluate(problem.mesh.s * tf0)
        X = np.stack([ref[k] for k in STATE_NAMES], axis=1)
        z0 = problem.pack(X, np.stack([ref["u1"], ref["u2"]], axis=1), tf0)
    else:
        z0 = initial_decision(problem, guess)
    build = time.perf_counter() - t0
    outcome = solve_scvx(problem, z0, settings, progress=progress)
    X, U, tf = problem.unpack(outcome.z)
    t = problem.mesh.s * tf
    alpha = np.array([problem.alpha(float(v)) for v in X[:, 3]])
    conds = [flight_conditions(x, 0.0, a, vehicle, planet, atmosphere) for x, a in zip(X, alpha)]
    q = np.array([c.heat_flux for c in conds])
    lift = np.array([c.lift for c in conds])
    norm_u = np.hypot(U[:, 0], U[:, 1])
    acting = lift >= GAP_LIFT_FRACTION * planet.g0
    gap = float(np.max(1.0 - norm_u[acting], initial=0.0))
    heat_load = float(tf * (problem.mesh.weights @ q))
    between = _between_nodes(problem, X, U)
    xf = X[-1]
    hstar = float(planet.atmospheric_altitude(xf[0], xf[2]))
    ev = outcome.evaluation
    tol_q, tol_n, tol_g = BETWEEN_NODE_TOLERANCE
    checked = (between["heat_flux"] <= tol_q and between["total_load"] <= tol_n
               and between["flight_path_rad"] <= tol_g)
    message = outcome.message
    if outcome.converged and not checked:
        message += (f"; converged but violated between the nodes (heat flux +{between['heat_flux']:.1%}, "
                    f"load +{between['total_load']:.1%}, gamma {math.degrees(between['flight_path_rad']):.2f} deg): "
                    f"refine the mesh")
    return ScvxPlan(
        success=outcome.converged and checked, message=message, iterations=outcome.iterations,
        build_time=build, solve_time=time.perf_counter() - t0 - build,
        objective=heat_load / 1e6 if ps.objective == "heat_load" else tf,
        time=t, states=X, controls=U, final_time=tf, bank=np.arctan2(U[:, 1], U[:, 0]), alpha=alpha,
        heat_load=heat_load, lossless_gap=gap,
        lossless_gap_all=float(np.max(1.0 - norm_u)), max_defect=max_defect(ev),
        max_violation=max_violation(ev), between_nodes=between, miss_m=problem.site_miss(xf),
        drs={"altitude_m": hstar, "mach": float(conds[-1].mach), "vertical_speed_m_s": float(xf[3] * math.sin(xf[4]))},
        peaks={"heat_flux_W_m2": float(q.max()), "total_load_g": float(max(c.total_load for c in conds))},
        guess=guess, history=outcome.history, problem=problem)
