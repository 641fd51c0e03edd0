"""NLP results: the solution record, and what is derived from it after the solve
(extremal controls from the costates, a summary)."""
from __future__ import annotations

import dataclasses as dc

import numpy as np

from drake_entry.errors import DrakeEntryError, ScenarioError
from drake_entry.planning.nlp.evaluator import model_values
from drake_entry.planning.ocp import OptimalControlProblem
from drake_entry.planning.pseudospectral import SegmentMesh
from drake_entry.planning.result import PlanResult

__all__ = ["NlpResult", "TRANSCRIPTION_LABELS", "segment_words", "NlpError", "extremal_controls", "summary"]


@dc.dataclass
class NlpResult(PlanResult):
    """Solution of an optimal-control problem (a PlanResult: ``evaluate(t)`` gives the
    states and controls at times t [s]).

    Attributes:
      success: the solver converged AND the solution is verified (``verification``: the
        dynamics between the nodes and the Drake-propagated controls within tolerance).
      message: the solver's verdict and the verification in words ("converged but
        inaccurate: ..." with the figures when the check fails).
      time: node times [s] (nodes,). states: (nodes, n_states) SI in the problem's state
        order ([h, lon, lat, V, gamma, psi] first). controls: (nodes, n_controls) SI.
      objective: J in the problem's cost units (Lagrange terms integrated in seconds).
      costates: (nodes, n_states) d J / d x, SI (LGL: at the nodes; dircol, hermite_simpson: at segment
        midpoints, see costate_time), or None if the solver returned no multipliers.
      costate_time: times of the costate rows [s].
      hamiltonian: H = L + lambda' f at costate_time [cost units / s].
      converged: the solver's own verdict (SNOPT info 1, Ipopt status 0).
      verification: nlp.verify.Verification (None when solved without a verifier).
      scaling: nlp.scaling.Scaling, the factors the solver saw.
      guess_time, build_time, solve_time, verify_time: wall time [s] of the initial guess,
        the transcription, the solver and the verification; ``total_time`` their sum.
      transcription, solver, nodes; iterations: 0 (Drake's Ipopt and SNOPT bindings do not
        report them); mesh_history: nlp.mesh.MeshStep (nodes, between-node error, converged,
        solve time) per mesh of a refined solve (empty otherwise); build_time and solve_time
        are summed over the meshes.
      callback_calls, callback_time: calls of the Python callbacks the solver made (the
        constraint, costs, and for dircol the plant's derivatives) and their wall time [s]
        (models, Jacobians, AutoDiff packing), summed like solve_time; solve_time minus
        callback_time is the solver's own time with Drake's conversions.
      max_defect: largest scaled dynamics/constraint violation at the nodes.
      log_file: the solver's log (solve(log_file=...) or verbose SNOPT), else None.
      segments: LGL segments sharing their end nodes (1: the paper's global polynomial).
    """

    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    costates: np.ndarray | None
    costate_time: np.ndarray | None
    hamiltonian: np.ndarray | None
    transcription: str
    nodes: int
    max_defect: float
    solver: str = ""
    converged: bool = False
    verification: object = None
    scaling: object = None
    guess_time: float = 0.0
    verify_time: float = 0.0
    callback_calls: int = 0
    callback_time: float = 0.0
    mesh_history: list = dc.field(default_factory=list)
    log_file: str | None = None
    segments: int = 1
    problem: object = dc.field(repr=False, default=None)

    @property
    def total_time(self) -> float:
        """Wall time of the whole solve() [s]: guess, transcription, solver, verification."""
        return self.guess_time + self.build_time + self.solve_time + self.verify_time

    @property
    def final_time(self) -> float:
        return float(self.time[-1])

    def evaluate(self, at) -> dict:
        """States and controls at times ``at`` [s] by the transcription's own interpolant,
        named by the problem's state and control names (x0.., u0.. without a problem)."""
        t = np.atleast_1d(np.asarray(at, float))
        X, U = self.state_function()(t), self.control_function()(t)
        xn = getattr(self.problem, "state_names", None) or [f"x{i}" for i in range(X.shape[1])]
        un = getattr(self.problem, "control_names", None) or [f"u{j}" for j in range(U.shape[1])]
        return {**{n: X[:, i] for i, n in enumerate(xn)}, **{n: U[:, j] for j, n in enumerate(un)}}

    def control_function(self):
        """u(t) [SI] between the nodes: the Lagrange interpolant of the LGL nodes (the
        method's own representation) or first-order hold for dircol and hermite_simpson."""
        t, U = self.time, self.controls
        if self.transcription == "lgl":
            return self._lgl_interpolant(U)

        def u(tt):
            return np.column_stack([np.interp(np.atleast_1d(tt), t, U[:, j]) for j in range(U.shape[1])])
        return u

    def _lgl_interpolant(self, values):
        """t [s] -> each LGL segment's Lagrange polynomial through its nodes' ``values``
        (pseudospectral.SegmentMesh on s = t / t_f; times clipped to [0, t_f])."""
        mesh = SegmentMesh(self.segments, (len(self.time) - 1) // self.segments + 1)
        tf = self.time[-1]
        return lambda tt: mesh.interpolation(np.atleast_1d(np.asarray(tt, float)) / tf) @ values

    def state_function(self):
        """x(t) [SI] between the nodes: the Lagrange interpolant for LGL, the cubic Hermite
        spline with the dynamics as slopes for dircol and hermite_simpson (Hermite-Simpson's own)."""
        t, X = self.time, self.states
        if self.transcription == "lgl":
            return self._lgl_interpolant(X)
        if self.problem is None:
            return lambda tt: np.column_stack([np.interp(np.atleast_1d(tt), t, X[:, j]) for j in range(X.shape[1])])
        from scipy.interpolate import CubicHermiteSpline

        f, _, _, _ = model_values(self.problem, X.T, self.controls.T)
        spline = CubicHermiteSpline(t, X, f.T, axis=0)
        return lambda tt: spline(np.clip(np.atleast_1d(tt), t[0], t[-1]))


#: transcriptions by name in figures and messages
TRANSCRIPTION_LABELS = {"lgl": "LGL", "dircol": "DirectCollocation", "hermite_simpson": "Hermite-Simpson"}


def segment_words(segments: int) -> str:
    """' in S segments' for LGL segments (S > 1), else '': for progress lines and titles."""
    return f" in {segments} segments" if segments > 1 else ""


class NlpError(DrakeEntryError, RuntimeError):
    """The NLP could not be built (bad options or problem)."""



def extremal_controls(problem, result: NlpResult) -> np.ndarray:
    """Rates u* that minimise the Hamiltonian given the costates (paper 002 eqs. 22-23):
    dH/du = 2 k2 u / u_max^2 + lambda_alpha = 0 gives u*_alpha = -u_max^2 lambda_alpha / (2 k2)
    (and likewise for sigma), clipped to the rate bounds; at the costate times, SI.

    The paper prints u_max / (2 k) in eq. 23; differentiating its eq. 11 gives u_max^2
    (the square is missing in eqs. 22-23)."""
    if not isinstance(problem, OptimalControlProblem) or problem.controls != "rates":
        raise ScenarioError("extremal_controls needs an entry problem with controls='rates'")
    terms = [t for t in problem.objective if t.kind == "control_margin"]
    if len(terms) != 1 or any(t.kind in ("lagrange",) for t in problem.objective):
        raise ScenarioError("extremal_controls needs exactly one control_margin term and no user Lagrange term")
    if result.costates is None:
        raise ScenarioError("the result has no costates (the solver returned no multipliers)")
    t = terms[0]
    lam = result.costates
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # extreme bounds: inf, then clipped
        u = np.column_stack([-np.float64(t.u_alpha_max) ** 2 * lam[:, 6] / (2.0 * t.weight * t.k[1]),
                             -np.float64(t.u_sigma_max) ** 2 * lam[:, 7] / (2.0 * t.weight * t.k[2])])
    _, _, ul, uh = problem.bounds_arrays()
    return np.clip(u, ul, uh)


def summary(problem, result: NlpResult, check=None) -> dict:
    """Figures of merit of a solution (paper 002 'Results' for entry problems): objective,
    final time, solve time, the local altitude maxima and the dynamic pressure there,
    final bank, largest |H| at interior nodes, extremal-control match and, with ``check``
    (an nlp.verify.PropagationCheck), the propagated terminal errors."""
    out = {"success": result.success, "converged": result.converged, "message": result.message,
           "transcription": result.transcription, "solver": result.solver, "nodes": result.nodes,
           "segments": result.segments, "objective": result.objective, "final_time_s": result.final_time,
           "solve_time_s": result.solve_time,
           "build_time_s": result.build_time, "guess_time_s": result.guess_time, "verify_time_s": result.verify_time,
           "callback_calls": result.callback_calls, "callback_time_s": result.callback_time,
           "total_time_s": result.total_time, "max_constraint_violation_scaled": result.max_defect,
           "verification": None if result.verification is None else result.verification.as_dict(),
           "scaling": None if result.scaling is None else result.scaling.as_dict(),
           "mesh_history": [list(m) for m in result.mesh_history]}
    if result.hamiltonian is not None:
        inner = result.hamiltonian[1:-1] if result.hamiltonian.size > 2 else result.hamiltonian
        out["hamiltonian_interior_max_abs"] = float(np.abs(inner).max())
        out["hamiltonian_interior_rms"] = float(np.sqrt(np.mean(inner ** 2)))
        out["hamiltonian_interior_mean"] = float(np.mean(inner))
    if isinstance(problem, OptimalControlProblem):
        t = np.linspace(0.0, result.final_time, 4001)
        x = result.state_function()(t)
        h = x[:, 0]
        peaks = [i for i in range(1, len(t) - 1) if h[i] >= h[i - 1] and h[i] > h[i + 1]]
        out["altitude_maxima"] = [{"time_s": float(t[i]), "altitude_km": float(h[i] / 1e3),
                                   "dynamic_pressure_kPa": float(problem.conditions(x[i], np.zeros(problem.n_controls))
                                                                  .dynamic_pressure / 1e3)} for i in peaks]
        if problem.bank_index[0] == "state":
            bank = result.states[:, problem.bank_index[1]]
            out["final_bank_deg"] = float(np.degrees(bank[-1]))
            out["max_bank_deg"] = float(np.degrees(np.abs(bank).max()))
        if problem.controls == "rates":
            out["max_alpha_deg"] = float(np.degrees(result.states[:, 6].max()))
            try:
                ext = extremal_controls(problem, result)
                U = result.controls if len(result.costate_time) == len(result.time) else \
                    0.5 * (result.controls[:-1] + result.controls[1:])
                out["extremal_control_max_diff_deg_s"] = float(np.degrees(np.abs(ext - U).max()))
            except ValueError:
                pass
    if check is not None:
        out["propagated_terminal_error"] = check.terminal_error
    return out
