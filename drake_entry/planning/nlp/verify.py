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
2. The controls flown open loop by the Drake Simulator (diagrams.propagation: RK5,
   accuracy 1e-11) from the first node must end at the last node.

Path constraints are re-evaluated at the same quadrature points and their largest
relative violation reported (not part of the verdict: a constraint held at the nodes
typically dips by O(1e-3) between them).
"""
from __future__ import annotations

import dataclasses as dc

import numpy as np

from drake_entry.errors import DrakeEntryError
from drake_entry.planning.nlp.evaluator import model_values

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
        propagation failed); propagation: its terminal errors in SI (diagrams.propagation).
      path_violation: largest relative path-constraint violation between the nodes.
      dynamics_tolerance, propagation_tolerance: what was asked.
      flight: the propagation itself (diagrams.propagation.PropagationCheck).
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


def verify(problem, result, *, dynamics_tolerance: float = DYNAMICS_TOLERANCE,
           propagation_tolerance: float = PROPAGATION_TOLERANCE) -> Verification:
    """Both checks on ``result`` (an NlpResult of ``problem``)."""
    from drake_entry.diagrams.propagation import propagate  # the Drake Simulator flies the controls

    names = getattr(problem, "state_names", None) or [f"x{j}" for j in range(problem.n_states)]
    try:
        err, viol = interval_errors(problem, result)
        err = np.nan_to_num(err, nan=np.inf)
        k, i = np.unravel_index(int(np.argmax(err)), err.shape)
        where = f"{names[i]} on [{result.time[k]:.4g}, {result.time[k + 1]:.4g}] s"
    except DrakeEntryError as e:  # the interpolants leave a model's range between the nodes
        err, viol = np.full((len(result.time) - 1, problem.n_states), np.inf), np.inf
        where = f"models undefined between the nodes: {str(e).splitlines()[0][:160]}"
    check = propagate(problem, result)
    if "failed" in check.terminal_error:
        prop_err = float("nan")
    else:
        rel = np.abs(check.states[-1] - result.states[-1]) / state_magnitudes(result)
        prop_err = float(rel.max())
        check.terminal_error["worst_state"] = names[int(np.argmax(rel))]
    ok = bool(err.max() <= dynamics_tolerance and prop_err <= propagation_tolerance)
    return Verification(ok, float(err.max()), where, err.max(axis=1), prop_err, check.terminal_error, viol,
                        dynamics_tolerance, propagation_tolerance, check)
