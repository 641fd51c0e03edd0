"""Is an NLP solution right between its nodes? (``success`` means verified.)

Two independent checks, both in the relative form of GPOPS-II (Patterson & Rao 2014,
eq. 39): an error in state i divided by 1 + max_k |x_i(t_k)|.

1. Dynamics between the nodes: on each interval [t_k, t_k+1] the transcription's own
   interpolants x(t), u(t) (result.state_function / control_function) must satisfy
   x(t_k+1) - x(t_k) = integral of f(x(t), u(t)) dt; the integral is Gauss-Legendre with
   ``QUADRATURE_POINTS`` points, so an interpolant that swings between the nodes (an
   under-resolved solution) shows here although the defects vanish at the nodes. The
   largest error per interval (``Verification.interval_errors``) is the estimate a mesh
   refinement would use.
2. The controls flown open loop by the plan verifier (the Drake Simulator on the problem's
   own dynamics, RK5 at accuracy 1e-11: drake_entry.diagrams.verification, passed in as
   ``verifier``) from the first node must end at the last node (``propagate``).

Path constraints are re-evaluated at the same quadrature points and their largest
relative violation reported (not part of the verdict: a constraint held at the nodes
typically dips by O(1e-3) between them).
"""
from __future__ import annotations

import dataclasses as dc

import numpy as np

from drake_entry.errors import DrakeEntryError
from drake_entry.models.geodesy import downtrack_crosstrack
from drake_entry.planning.nlp.evaluator import model_values
from drake_entry.planning.ocp import OptimalControlProblem
from drake_entry.planning.verification import OcpControls, require_verifier

__all__ = ["QUADRATURE_POINTS", "DYNAMICS_TOLERANCE", "PROPAGATION_TOLERANCE", "Verification", "state_magnitudes",
           "interval_errors", "verify", "PropagationCheck", "propagate", "terminal_error"]

QUADRATURE_POINTS = 8
#: default tolerances (relative, GPOPS-II form). 1e-3 between nodes is GPOPS-II's default
#: mesh tolerance. The open-loop flight accumulates and amplifies those errors over the whole
#: trajectory (entry dynamics are unstable in gamma on the final dive: 100 DirectCollocation
#: samples of the SCvx cross-check meet 6e-4 between nodes and end 0.14 deg of gamma, 68 m,
#: 0.08 m/s off, relative 0.0024), so its tolerance is 1e-2; the unverified wrong answer (196 km,
#: 160 m/s) is 0.02-0.03.
DYNAMICS_TOLERANCE = 1e-3
PROPAGATION_TOLERANCE = 1e-2


@dc.dataclass
class Verification:
    """Figures of the two checks (relative errors as in the module docstring).

    Attributes:
      verified: both within their tolerances.
      dynamics_error: largest between-node error; dynamics_where: state and interval.
      interval_errors: (nodes - 1,) largest error of each interval (mesh refinement).
      propagation_error: the propagated final state's largest relative error (nan when the
        propagation failed); propagation: its terminal errors in SI (``propagate``).
      path_violation: largest relative path-constraint violation between the nodes.
      dynamics_tolerance, propagation_tolerance: what was asked.
      flight: the propagation itself (PropagationCheck).
    """

    verified: bool
    dynamics_error: float
    dynamics_where: str
    interval_errors: np.ndarray
    propagation_error: float
    propagation: dict
    path_violation: float
    dynamics_tolerance: float
    propagation_tolerance: float
    flight: object = dc.field(repr=False, default=None)

    def as_dict(self) -> dict:
        return {"verified": self.verified, "dynamics_error": self.dynamics_error, "dynamics_where": self.dynamics_where,
                "propagation_error": self.propagation_error, "propagation": dict(self.propagation),
                "path_violation_between_nodes": self.path_violation, "dynamics_tolerance": self.dynamics_tolerance,
                "propagation_tolerance": self.propagation_tolerance}

    def summary(self) -> str:
        prop = self.propagation.get("failed") or (f"{self.propagation_error:.2g} (worst "
                                                  f"{self.propagation.get('worst_state', '')})")
        extra = ""
        if "position_m" in self.propagation:
            extra = f" ({self.propagation['position_m']:.3g} m, {self.propagation['velocity_m_s']:.3g} m/s)"
        return (f"dynamics between nodes {self.dynamics_error:.2g} (tolerance {self.dynamics_tolerance:g}, "
                f"worst {self.dynamics_where}); propagated controls end {prop}{extra} from the solution "
                f"(tolerance {self.propagation_tolerance:g}); path constraints between nodes within "
                f"{self.path_violation:.2g}")


def state_magnitudes(result) -> np.ndarray:
    """1 + max_k |x_i(t_k)| per state (the GPOPS-II normaliser)."""
    return 1.0 + np.abs(result.states).max(axis=0)


def interval_errors(problem, result, points: int = QUADRATURE_POINTS):
    """(errors (nodes-1, n_states) relative, path violation) of ``result`` (see module docstring)."""
    t = result.time
    xg, wg = np.polynomial.legendre.leggauss(points)
    h = np.diff(t)
    tq = (t[:-1, None] + 0.5 * h[:, None] * (xg[None, :] + 1.0)).ravel()  # (K * points,)
    Xq, Uq = result.state_function()(tq), result.control_function()(tq)
    f, g, _, _ = model_values(problem, Xq.T, Uq.T)
    integral = (0.5 * h[:, None, None] * wg[None, :, None] * f.T.reshape(len(h), points, -1)).sum(axis=1)
    err = np.abs(np.diff(result.states, axis=0) - integral) / state_magnitudes(result)
    viol = 0.0
    for c, row in zip(problem.path, g):
        excess = np.maximum(c.min - row, 0.0) + np.maximum(row - c.max, 0.0)
        viol = max(viol, float(np.nan_to_num(excess, nan=np.inf).max() / c.scale) if excess.size else 0.0)
    return err, viol


def verify(problem, result, *, verifier, dynamics_tolerance: float = DYNAMICS_TOLERANCE,
           propagation_tolerance: float = PROPAGATION_TOLERANCE) -> Verification:
    """Both checks on ``result`` (an NlpResult of ``problem``); ``verifier`` flies the controls
    (drake_entry.planning.verification)."""
    names = getattr(problem, "state_names", None) or [f"x{j}" for j in range(problem.n_states)]
    try:
        err, viol = interval_errors(problem, result)
        err = np.nan_to_num(err, nan=np.inf)
        k, i = np.unravel_index(int(np.argmax(err)), err.shape)
        where = f"{names[i]} on [{result.time[k]:.4g}, {result.time[k + 1]:.4g}] s"
    except DrakeEntryError as e:  # the interpolants leave a model's range between the nodes
        err, viol = np.full((len(result.time) - 1, problem.n_states), np.inf), np.inf
        where = f"models undefined between the nodes: {str(e).splitlines()[0][:160]}"
    check = propagate(problem, result, verifier)
    if "failed" in check.terminal_error:
        prop_err = float("nan")
    else:
        rel = np.abs(check.states[-1] - result.states[-1]) / state_magnitudes(result)
        prop_err = float(rel.max())
        check.terminal_error["worst_state"] = names[int(np.argmax(rel))]
    ok = bool(err.max() <= dynamics_tolerance and prop_err <= propagation_tolerance)
    return Verification(ok, float(err.max()), where, err.max(axis=1), prop_err, check.terminal_error, viol,
                        dynamics_tolerance, propagation_tolerance, check)


@dc.dataclass
class PropagationCheck:
    """Open-loop flight of the NLP controls (paper 002 'Results': the optimal controls flown,
    compared with the NLP states at t_f).

    Attributes:
      time [s], states (n, n_states) SI: the propagated trajectory.
      terminal_error: propagated minus NLP at t_f: downtrack_m, crosstrack_m, position_m
        (their root sum square, paper 002's 18.16 m), altitude_m, velocity_m_s,
        flight_path_deg (entry problems), or state_max for other problems; {'failed': reason}
        when the flight could not reach t_f.
    """

    time: np.ndarray
    states: np.ndarray
    terminal_error: dict


def propagate(problem, result, verifier, *, samples_per_interval: int = 256) -> PropagationCheck:
    """Fly ``result.controls`` from ``result.states[0]`` over [0, t_f] with ``verifier``:
    the LGL control interpolant sampled ``samples_per_interval`` times per node interval into
    a C2 spline (on the 125-node MaRV solution 16 samples leave 41 m of terminal miss, 64 leave
    1.5 m, 256 leave 0.04 m), DirectCollocation's first-order hold as it is."""
    fly = require_verifier(verifier, "propagate")
    t_nodes, tf = result.time, result.final_time
    if result.transcription == "lgl":
        tt = np.unique(np.concatenate([np.linspace(0.0, tf, samples_per_interval * len(t_nodes)), t_nodes]))
        controls = OcpControls(problem, result.states[0], tf, tt, np.reshape(result.control_function()(tt), (len(tt), -1)),
                               "cubic")
    else:
        controls = OcpControls(problem, result.states[0], tf, t_nodes, result.controls, "linear")
    flown = fly(controls)
    x_end = flown.states[-1]
    err = {"failed": flown.failure} if flown.failure else terminal_error(problem, result, x_end)
    return PropagationCheck(time=flown.time, states=flown.states, terminal_error=err)


def terminal_error(problem, result, x_end) -> dict:
    """Propagated minus NLP final state (paper 002 appendix eqs. 24-30 for the position)."""
    xf = result.states[-1]
    if not isinstance(problem, OptimalControlProblem):
        return {"state_max": float(np.max(np.abs(x_end - xf)))}
    x0 = result.states[0]
    R = problem.planet.reference_radius
    d, c = downtrack_crosstrack(np.array([x_end[1], xf[1]]), np.array([x_end[2], xf[2]]), x0[1], x0[2],
                                xf[1], xf[2], R)
    dd, dcr = float(d[0] - d[1]), float(c[0] - c[1])
    return {"downtrack_m": dd, "crosstrack_m": dcr, "position_m": float(np.hypot(dd, dcr)),
            "altitude_m": float(x_end[0] - xf[0]), "velocity_m_s": float(x_end[3] - xf[3]),
            "flight_path_deg": float(np.degrees(x_end[4] - xf[4]))}
