"""Neighbouring-optimal feedback from an optimal solution's costates (the feedback paper 002's
accurate costates make possible; Bryson & Ho, Applied Optimal Control, Sec. 6.3).

About an optimal solution x*(t), u*(t) with costates lambda(t) (``NlpResult.costates``: dJ/dx,
SI), a small deviation dx is steered by the minimiser of the second variation of J,

    1/2 dx_f' Q_f dx_f + 1/2 int (dx' H_xx dx + 2 dx' H_xu du + du' H_uu du) dt,
    dx' = A dx + B du,

with H = L + lambda' f the Hamiltonian (L the objective's Lagrange integrand,
``problem.lagrangian``; f ``problem.dynamics``), A = f_x, B = f_u. Its Riccati equation

    -S' = H_xx + S A + A' S - (S B + H_xu) H_uu^-1 (B' S + H_ux),   S(t_f) = Q_f,

gives the law u = u*(t) - K(t) (x - x*(t)), K = H_uu^-1 (B' S + H_ux): the same TrackingLaw the
time-varying LQR (planning.tracking) gives, with the weights the problem's own curvature rather
than chosen ones. The solution's terminal constraints are replaced by the TVLQR's terminal
penalty (``TrackingWeights.terminal_scale``) in the units of H_uu (a simplification of the
sweep method with terminal multipliers, stated), and the path-constraint multipliers (e.g.
paper 002's q >= 12 kPa where it is active) are not part of H: the LGL result does not carry
them. H's second derivatives are central differences of its AutoDiff gradient.
"""
from __future__ import annotations

import time

import numpy as np
from pydrake.autodiffutils import ExtractGradient, InitializeAutoDiff
from scipy.integrate import solve_ivp

from drake_entry.errors import ScenarioError
from drake_entry.planning.tracking import TrackingLaw, TrackingWeights, lerp, resample, scaled_linearisation

__all__ = ["HESSIAN_STEP", "DIVERGED", "hamiltonian_gradient", "hamiltonian_hessian", "without_odd_even_mode",
           "neighbouring_optimal"]

#: relative step of the central differences of H's gradient (of each variable's scale)
HESSIAN_STEP = 1.0e-5
#: S beyond this (scaled units) is a diverging Riccati solution: a conjugate point
DIVERGED = 1.0e12


class _Diverged(Exception):
    def __init__(self, t: float):
        super().__init__(t)
        self.t = float(t)


def hamiltonian_gradient(problem, costate, x, u) -> np.ndarray:
    """dH/d(x, u) [SI] of H = L + lambda' f at (x, u) (AutoDiff)."""
    nx = problem.n_states
    z = InitializeAutoDiff(np.concatenate([x, u]))[:, 0]
    H = problem.lagrangian(z[:nx], z[nx:]) + np.dot(np.asarray(costate, float), problem.dynamics(z[:nx], z[nx:]))
    return ExtractGradient(np.array([H]))[0]


def hamiltonian_hessian(problem, costate, x, u, scale) -> np.ndarray:
    """d2H/d(x, u)2 [SI] (n_x + n_u square, symmetrised) by central differences of the
    gradient with steps HESSIAN_STEP x ``scale`` (per variable, SI)."""
    z = np.concatenate([x, u]).astype(float)
    nx, n = problem.n_states, z.size
    out = np.zeros((n, n))
    for i in range(n):
        h = HESSIAN_STEP * scale[i]
        zp, zm = z.copy(), z.copy()
        zp[i] += h
        zm[i] -= h
        out[:, i] = (hamiltonian_gradient(problem, costate, zp[:nx], zp[nx:])
                     - hamiltonian_gradient(problem, costate, zm[:nx], zm[nx:])) / (2.0 * h)
    return 0.5 * (out + out.T)


def without_odd_even_mode(values) -> np.ndarray:
    """Node values (n, m) filtered by (1/4, 1/2, 1/4) between neighbours (the ends kept): removes
    the node-to-node alternation the LGL covector mapping leaves in the costates of the
    position and velocity states with active path constraints, keeps values linear in the node
    index. For a law from LGL costates."""
    v = np.asarray(values, float)
    out = v.copy()
    out[1:-1] = 0.25 * v[:-2] + 0.5 * v[1:-1] + 0.25 * v[2:]
    return out


def neighbouring_optimal(problem, time_s, states, controls, costate_time, costates, weights: TrackingWeights,
                         samples: int = 120) -> TrackingLaw:
    """The neighbouring-optimal law about a solution (module docstring).

    Args: time_s (n,), states (n, n_x), controls (n, n_u): the solution [SI]; costate_time (m,)
    and costates (m, n_x): its costates (linearly interpolated in time); weights: the state and
    control scales (numerics) and the terminal penalty; samples: times the matrices are
    evaluated at. Raises ScenarioError when H_uu is not positive definite or the Riccati
    solution diverges (a conjugate point of the second variation), naming the time.
    """
    t0 = time.perf_counter()
    time_s, states, controls = (np.asarray(a, float) for a in (time_s, states, controls))
    costate_time, costates = np.asarray(costate_time, float), np.asarray(costates, float)
    nx, nu = problem.n_states, problem.n_controls
    sx, su, _, R_w, Qf_w = weights.matrices(problem.state_names, problem.control_names)
    ts = np.linspace(time_s[0], time_s[-1], samples)
    xs, us, lam = resample(ts, time_s, states), resample(ts, time_s, controls), resample(ts, costate_time, costates)
    A_s, B_s = scaled_linearisation(problem, ts, xs, us, sx, su)
    scale = np.concatenate([sx, su])
    W = np.array([hamiltonian_hessian(problem, l, x, u, scale) for l, x, u in zip(lam, xs, us)])
    W_s = W * scale[None, :, None] * scale[None, None, :]  # in scaled variables
    Q_s, N_s, R_s = W_s[:, :nx, :nx], W_s[:, :nx, nx:], W_s[:, nx:, nx:]
    for k, R in enumerate(R_s):
        if np.linalg.eigvalsh(R).min() <= 0.0:
            raise ScenarioError(f"neighbouring-optimal feedback: H_uu is not positive definite at t = {ts[k]:.1f} s "
                                f"(eigenvalues {np.linalg.eigvalsh(R)}); the Legendre-Clebsch condition fails")
    # the terminal penalty in H_uu's units: the TVLQR's Q_f relative to its R = I
    Qf = Qf_w * float(np.mean([np.trace(R) / nu for R in R_s])) / float(np.trace(R_w) / nu)

    def rhs(t, s):
        if not np.all(np.isfinite(s)) or np.abs(s).max() > DIVERGED:
            raise _Diverged(t)
        S = s.reshape(nx, nx)
        Ak, Bk, Qk, Nk, Rk = (lerp(ts, M, t) for M in (A_s, B_s, Q_s, N_s, R_s))
        G = S @ Bk + Nk
        dS = -(Qk + S @ Ak + Ak.T @ S - G @ np.linalg.solve(Rk, G.T))
        return (0.5 * (dS + dS.T)).ravel()

    try:
        sol = solve_ivp(rhs, (ts[-1], ts[0]), Qf.ravel(), t_eval=ts[::-1], rtol=1e-6, atol=1e-9, method="LSODA")
        failure = None if sol.status == 0 and sol.t.size == ts.size else (float(sol.t[-1]), sol.message)
    except _Diverged as e:
        failure = (e.t, f"|S| beyond {DIVERGED:g}")
    if failure is not None:
        raise ScenarioError(f"neighbouring-optimal feedback: the Riccati equation of the second variation diverges "
                            f"at t = {failure[0]:.1f} s of {ts[-1]:.1f} s ({failure[1]}: a conjugate point, H_xx "
                            f"not positive enough there)")
    S_s = sol.y.T[::-1].reshape(-1, nx, nx)
    K_s = np.array([np.linalg.solve(R, B.T @ S + N.T) for R, B, S, N in zip(R_s, B_s, S_s, N_s)])
    gains = K_s * su[None, :, None] / sx[None, None, :]
    return TrackingLaw(time_s, states, controls, ts, gains, time.perf_counter() - t0)
