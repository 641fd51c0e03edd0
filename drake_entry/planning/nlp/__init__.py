"""NLP path: entry optimal control by Legendre pseudospectral (LGL) collocation or Drake's
DirectCollocation, solved with Ipopt or SNOPT (paper 002).

    result = solve(problem, transcription="lgl" | "dircol" | "hermite_simpson", solver="auto" | "snopt" | "ipopt",
                   nodes=N)

``problem`` is an ``OptimalControlProblem`` (entry dynamics, planning/ocp.py) or a
``CustomProblem``. The NLP runs in scaled units (scaling: canonical units as in paper 002,
altitude in 10 km, controls by their bounds, the objective by its gradient at the guess;
reported in ``result.scaling``); results are SI.

LGL (paper 002 eqs. 12-14, Fahroo & Ross): states and controls at the N LGL nodes
tau_k of [-1, 1], t = (tau + 1) t_f / 2. One constraint (one per segment) holds the defects
D X - (t_f / 2) f(X, U) = 0 and the path rows, evaluated by one vectorised model call with
its exact sparse Jacobian (lgl, evaluator). Costates come from the defects' KKT multipliers
(eq. 15): lambda(t_k) = nu_k / w_k, converted back to SI. ``segments=S`` splits the N nodes
into S equal LGL segments sharing their end nodes (Ross & Fahroo's knotting): the same
N, S dense differentiation blocks of (N - 1) / S + 1 nodes instead of one of N.

DirectCollocation: Drake's Hermite-Simpson transcription of planning.ocp_system (the same
scaled dynamics as a Drake System) with N samples; the running cost is the trapezoid rule
over the samples; costates are estimated at the segment midpoints from the collocation
multipliers, lambda(t_k+1/2) = 3 nu_k / (2 h_k). hermite_simpson poses the same NLP (same rows,
cost and costates) with LGL's machinery: a constraint per part of about 25 intervals,
vectorised model calls at the samples and midpoints, the Jacobian assembled with its sparsity
declared.

The result reports the Hamiltonian H = L + lambda' f along the solution (zero on an
extremal with free final time, paper 002 Fig. 10) and ``verify.propagate`` flies the controls
with the verifier it is given (the Drake Simulator: drake_entry.diagrams.verification) to
check the terminal state.

``success`` means verified (verify: dynamics between the nodes and the controls flown by the
``verifier``); a converged answer that fails the check says "converged but inaccurate", and
one solved without a verifier says "not verified" and is not a success (``converged`` keeps
the solver's word).

``refine=True`` raises the node count until the between-node error meets the tolerance
(mesh); ``solver='auto'`` (default) tries SNOPT, then Ipopt from the same start.

Modules: result (NlpResult, extremal controls, summary), guess (initial guesses), scaling
(the factors the solver sees), status (solver verdicts in words), verify, mesh (refinement),
evaluator (node values and Jacobians), transcription (shared parts), node_program (what lgl and
hermite_simpson share), lgl, dircol, hermite_simpson, catalogue
(published problems with their optima).
"""
from __future__ import annotations

import math
import tempfile
import time as _time

import numpy as np
from pydrake.solvers import IpoptSolver, SnoptSolver, SolverOptions

from drake_entry.errors import ScenarioError
from drake_entry.planning.nlp.dircol import _DircolTranscription
from drake_entry.planning.nlp.evaluator import SolveProgress
from drake_entry.planning.nlp.guess import initial_guess
from drake_entry.planning.nlp.hermite_simpson import _HermiteSimpsonTranscription
from drake_entry.planning.nlp.lgl import _LglTranscription, nodes_per_segment, segment_compatible
from drake_entry.planning.nlp.mesh import MAX_NODES, MeshStep, mesh_error, next_nodes  # noqa: F401 (API)
from drake_entry.planning.nlp.result import (  # noqa: F401 (API)
    TRANSCRIPTION_LABELS,
    NlpError,
    NlpResult,
    extremal_controls,
    segment_words,
    summary,
)
from drake_entry.planning.nlp.scaling import Scaling  # noqa: F401 (API)
from drake_entry.planning.nlp.scaling import resolve as acceleration_scaling
from drake_entry.planning.nlp.status import restartable, verdict
from drake_entry.planning.nlp.transcription import COSTATE_SIGN  # noqa: F401 (API)
from drake_entry.planning.nlp.verify import (  # noqa: F401 (API)
    DYNAMICS_TOLERANCE,
    PROPAGATION_TOLERANCE,
    PropagationCheck,
    Verification,
    propagate,
)
from drake_entry.planning.nlp.verify import verify as verify_solution
from drake_entry.planning.progress import wanted

__all__ = ["MAX_NODES", "MeshStep", "mesh_error", "next_nodes", "TRANSCRIPTION_LABELS", "NlpError", "NlpResult",
           "extremal_controls", "segment_words", "summary", "Scaling", "COSTATE_SIGN", "DYNAMICS_TOLERANCE",
           "PROPAGATION_TOLERANCE", "PropagationCheck", "Verification", "propagate", "TRANSCRIPTIONS",
           "RESTART_VIOLATION", "SOLVERS", "solve", "check_options", "auto_solvers", "default_solver"]

TRANSCRIPTIONS = ("lgl", "dircol", "hermite_simpson")
#: a solver stopped near an optimum (status.restartable) at a point this feasible (largest
#: scaled violation) is restarted once from that point
RESTART_VIOLATION = 1e-6
SOLVERS = ("ipopt", "snopt")


def solve(problem, *, transcription: str = "lgl", solver: str = "auto", nodes: int = 40, guess=None,
          tolerance: float = 1e-8, max_iterations: int = 3000, verbose: bool = False, scaling=None,
          solver_options: dict | None = None, log_file: str | None = None, verifier=None,
          dynamics_tolerance: float = DYNAMICS_TOLERANCE,
          propagation_tolerance: float = PROPAGATION_TOLERANCE, refine: bool = False,
          max_nodes: int | None = None, progress="auto", segments: int = 1) -> NlpResult:
    """Solve ``problem`` (see module docstring); ``success`` only when verified.

    Args:
      transcription: 'lgl' (Legendre pseudospectral, paper 002 eqs. 12-14), 'dircol' (Drake's
        DirectCollocation, Hermite-Simpson) or 'hermite_simpson' (the same NLP, vectorised).
      solver: 'snopt', 'ipopt' or 'auto' (default: SNOPT when this pydrake build has it,
        else Ipopt; see default_solver()).
      nodes: LGL nodes or DirectCollocation samples (>= 3).
      segments: LGL only: equal segments sharing their end nodes ((nodes - 1) a multiple of
        segments, >= 3 nodes per segment; 1: paper 002's global polynomial). A refined mesh
        keeps the segments and rounds its node count up to one they share.
      guess: an NlpResult, or (t [s], states (n, nx), controls (n, nu)) SI, or None for the
        built-in propagated guess (``initial_guess``).
      tolerance: solver optimality and feasibility tolerance (scaled units).
      max_iterations: solver (major) iteration limit.
      verbose: the solver's log (Ipopt: to the console; SNOPT: to ``log_file`` or a
        temporary file named in the result).
      scaling: override any of the automatic scale factors (nlp.scaling: a dict with
        states, controls, time, objective, or a Scaling).
      solver_options: further options by the solver's own names, set last (e.g.
        {"linear_solver": "mumps"} for Ipopt, {"Hessian full memory": 1} for SNOPT).
      log_file: where the solver writes its log.
      verifier: flies the controls for the verification (drake_entry.planning.verification;
        the Drake one is drake_entry.diagrams.verification.fly_controls); with it the solution
        is checked between the nodes and by its flown controls (nlp.verify); without it the
        answer is not verified and ``success`` is False (``converged``: the solver's word).
      dynamics_tolerance: the verification's between-node tolerance (relative).
      propagation_tolerance: the verification's tolerance on the flown controls (relative).
      refine: mesh refinement (nlp.mesh): start on ``nodes`` and raise the node count,
        each mesh warm-started from the last solution, until the between-node error meets
        ``dynamics_tolerance`` (and the flown controls ``propagation_tolerance``) or
        ``max_nodes`` is reached; the meshes are in ``result.mesh_history``.
      max_nodes: refinement's node cap (default nlp.mesh.MAX_NODES: LGL 150, Hermite-Simpson 400).
      progress: a line on stderr every 5 s once a solve has run 5 s (elapsed time, evaluations,
        objective, LGL collocation violation: evaluator.SolveProgress): True, False, or 'auto'
        (when stderr is a terminal). Ctrl-C stops the solve with KeyboardInterrupt, as under
        either solver (SNOPT reports it as a RuntimeError naming it, which is re-raised as such).
    """
    check_options(transcription=transcription, solver=solver, nodes=nodes, tolerance=tolerance,
                  max_iterations=max_iterations, dynamics_tolerance=dynamics_tolerance,
                  propagation_tolerance=propagation_tolerance, progress=progress, refine=refine, max_nodes=max_nodes,
                  segments=segments)
    names = auto_solvers() if solver == "auto" else (solver,)
    if solver == "auto" and solver_options:
        raise ScenarioError("solver_options are by the solver's own names: give solver='snopt' or 'ipopt' with them")
    show = wanted(progress)
    engines = {name: _engine(name) for name in names}
    cap = max(MAX_NODES[transcription], nodes) if max_nodes is None else max_nodes  # checked by check_options
    if segments > 1:  # the largest node count the segments share (nodes is one: check_options)
        cap = segments * ((cap - 1) // segments) + 1
    t_guess = _time.perf_counter()
    if guess is None:
        guess = initial_guess(problem)
    elif isinstance(guess, NlpResult):
        guess = (guess.time, guess.states, guess.controls)
    guess = _check_guess(problem, guess)
    guess_time = _time.perf_counter() - t_guess
    options = {name: _solver_options(engine, name, tolerance, max_iterations, verbose, solver_options, log_file)
               for name, engine in engines.items()}
    history, build_time, solve_time, target = [], 0.0, 0.0, dynamics_tolerance
    calls, callback_time = 0, 0.0
    first_guess = guess
    while True:
        mesh_time, failed = 0.0, []
        # auto: SNOPT, then Ipopt if it fails; a refined mesh whose warm start fails is tried
        # again from the first guess (each solver in turn: SNOPT's second start before Ipopt's
        # thousands of iterations)
        starts = [("", guess)] + ([(" from the first guess", first_guess)] if guess is not first_guess else [])
        for name, engine in engines.items():
            for label, start in starts:
                result, words, diagnosis = _solve_mesh(problem, transcription, name, engine, nodes, start, scaling,
                                                       options[name][0], show, segments)
                mesh_time, build_time = mesh_time + result.solve_time, build_time + result.build_time
                calls, callback_time = calls + result.callback_calls, callback_time + result.callback_time
                words = words + label
                if result.converged:
                    break
                failed.append(words)
            if result.converged:
                break
        if failed:
            after = "auto solver after" if name != next(iter(engines)) else "after"
            words = f"{words} ({after} '{failed[0]}')" if result.converged else "; ".join(failed)
        solve_time += mesh_time
        result.solver, result.log_file, result.guess_time = name, options[name][1], guess_time
        result.build_time, result.solve_time, result.mesh_history = build_time, solve_time, history
        result.callback_calls, result.callback_time = calls, callback_time
        if refine:
            error = mesh_error(problem, result) if result.converged else math.nan
            history.append(MeshStep(int(nodes), error, result.converged, mesh_time))
        if not result.converged:
            mesh = f" on mesh {len(history)} ({nodes} nodes)" if refine else ""
            result.success, result.message = False, f"not solved{mesh}: {words}; {diagnosis}"
            return result
        if verifier is None and not refine:
            result.success, result.message = False, f"solved, not verified (no verifier given): {words}"
            return result
        if refine and history[-1].error > target and nodes < cap:
            nodes, guess = _next_mesh(transcription, history, target, cap, segments), (result.time, result.states,
                                                                                        result.controls)
            continue
        if verifier is None:
            result.success = False
            result.message = (f"solved, not verified (no verifier given): {words}; " if history[-1].error <= target
                              else f"converged but inaccurate: {words}; ") + _mesh_words(history, target, cap)
            return result
        t_verify = _time.perf_counter()
        check = verify_solution(problem, result, verifier=verifier, dynamics_tolerance=dynamics_tolerance,
                                propagation_tolerance=propagation_tolerance)
        result.verify_time = _time.perf_counter() - t_verify
        result.verification = check
        if refine and not check.verified and nodes < cap and check.dynamics_error <= target:
            # between the nodes it meets the tolerance, the flight does not: tighten and go on
            target = check.dynamics_error / 10.0
            nodes, guess = _next_mesh(transcription, history, target, cap, segments), (result.time, result.states,
                                                                                        result.controls)
            continue
        result.success = check.verified
        result.message = (f"solved and verified: {words}; " if check.verified else
                          f"converged but inaccurate: {words}; ") + check.summary()
        if refine:
            result.message += "; " + _mesh_words(history, dynamics_tolerance, cap)
        return result


def check_options(*, transcription: str = "lgl", solver: str = "auto", nodes: int = 40, tolerance: float = 1e-8,
                  max_iterations: int = 3000, dynamics_tolerance: float = DYNAMICS_TOLERANCE,
                  propagation_tolerance: float = PROPAGATION_TOLERANCE, progress="auto", refine: bool = False,
                  max_nodes: int | None = None, segments: int = 1) -> None:
    """``solve``'s options checked (a ScenarioError naming the option and its allowed range), so a
    caller can refuse bad options before a first, coarse solve."""
    if transcription not in TRANSCRIPTIONS:
        raise ScenarioError(f"transcription '{transcription}' is unknown; allowed: {', '.join(TRANSCRIPTIONS)}")
    if solver not in SOLVERS + ("auto",):
        raise ScenarioError(f"solver '{solver}' is unknown; allowed: auto, {', '.join(SOLVERS)}")
    if not (isinstance(nodes, (int, np.integer)) and nodes >= 3):
        raise ScenarioError(f"nodes must be an integer >= 3, got {nodes}")
    if not 0 < tolerance < 1:
        raise ScenarioError(f"tolerance = {tolerance} is out of range; allowed (0, 1)")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) or max_iterations < 1:
        raise ScenarioError(f"max_iterations = {max_iterations} is out of range; allowed: an integer >= 1")
    for name, value in (("dynamics_tolerance", dynamics_tolerance), ("propagation_tolerance", propagation_tolerance)):
        if not 0 < value < 1:
            raise ScenarioError(f"{name} = {value} is out of range; allowed (0, 1)")
    if progress not in (True, False, "auto"):
        raise ScenarioError(f"progress = {progress!r}; allowed: True, False, 'auto'")
    if segments != 1:
        if transcription != "lgl":
            raise ScenarioError(f"segments = {segments!r} applies to the lgl transcription only; "
                                f"'{transcription}' takes segments = 1")
        nodes_per_segment(int(nodes), segments)
    if refine and max_nodes is not None and not (isinstance(max_nodes, (int, np.integer))
                                                 and not isinstance(max_nodes, bool) and max_nodes >= nodes):
        raise ScenarioError(f"max_nodes = {max_nodes} is out of range; allowed: an integer >= nodes ({nodes})")


def auto_solvers() -> tuple:
    """The solvers solver='auto' tries in turn: SNOPT (when this pydrake build has it), then
    Ipopt from the same start when SNOPT does not converge. SNOPT first for speed: Drake
    gives Ipopt no Hessian of Python constraints, so Ipopt runs limited-memory BFGS and needs
    hundreds to thousands of iterations on entry problems (Betts' shuttle at 40 LGL nodes:
    1 610 Ipopt iterations, 60 s; SNOPT 5 s). Ipopt second for robustness: on the
    brachistochrone's singular start (v = 0) SNOPT can stop at info 3 or 13 where Ipopt's
    interior point converges from the same guess (docs/methods/nlp.md)."""
    return tuple(name for name in ("snopt", "ipopt") if _engine(name, check=False) is not None)


def default_solver() -> str:
    """The first solver solver='auto' tries ('snopt' when available, else 'ipopt')."""
    return auto_solvers()[0]


def _next_mesh(transcription, history, target, cap, segments) -> int:
    """mesh.next_nodes rounded up to a node count the LGL ``segments`` share."""
    nodes = next_nodes(transcription, history, target, cap)
    return nodes if segments == 1 else segment_compatible(nodes, segments)


def _engine(name: str, check: bool = True):
    """The Drake solver object (None, or NlpError with ``check``, when this build lacks it)."""
    engine = IpoptSolver() if name == "ipopt" else SnoptSolver()
    if engine.available() and engine.enabled():
        return engine
    if check:
        raise NlpError(f"solver '{name}' is not available in this pydrake build")
    return None


def _solve_mesh(problem, transcription, solver, engine, nodes, guess, scaling, options, show: bool = False,
                segments: int = 1):
    """One transcription and solve on ``nodes`` nodes (LGL: in ``segments`` segments): (NlpResult
    with ``converged`` and this mesh's build and solve times, the solver's verdict in words, the
    violation diagnosis when not converged); ``show``: progress lines on stderr (SolveProgress)."""
    t_build = _time.perf_counter()
    scales = acceleration_scaling(problem, guess, scaling)
    tx = (_LglTranscription(problem, nodes, scales, segments) if transcription == "lgl"
          else _HermiteSimpsonTranscription(problem, nodes, scales) if transcription == "hermite_simpson"
          else _DircolTranscription(problem, nodes, scales, float(guess[0][-1])))
    tx.set_guess(*guess)
    tx.scale_objective()
    build_time = _time.perf_counter() - t_build
    t0, calls0, seconds0 = _time.perf_counter(), tx.timer.calls, tx.timer.seconds
    if show:
        tx.timer.progress = SolveProgress(f"{transcription} {nodes} nodes{segment_words(segments)}, {solver}")
        tx.timer.progress.start()
    res = _interruptible(engine.Solve, tx.prog, tx.initial_guess, options)
    converged, words = verdict(res, solver)
    if not converged and restartable(res, solver) and tx.worst_violation(res)[0] <= RESTART_VIOLATION:
        res = _interruptible(engine.Solve, tx.prog, res.GetSolution(), options)  # one warm restart (status.restartable)
        converged, restart_words = verdict(res, solver)
        words = f"{restart_words} after a warm restart from '{words}'"
    solve_time = _time.perf_counter() - t0
    calls, seconds = tx.timer.calls - calls0, tx.timer.seconds - seconds0
    result = tx.result(res)
    result.converged = converged
    result.build_time, result.solve_time = build_time, solve_time
    result.callback_calls, result.callback_time = calls, seconds
    diagnosis = "" if result.converged else tx.diagnose()
    tx.release()
    return result, words, diagnosis


def _interruptible(solve, *args):
    """``solve(*args)``; a Ctrl-C inside a Python callback reaches the caller as KeyboardInterrupt
    (SNOPT wraps it in a RuntimeError that names it; Ipopt passes it on)."""
    try:
        return solve(*args)
    except RuntimeError as e:
        if "KeyboardInterrupt" in str(e):
            raise KeyboardInterrupt from None
        raise


def _mesh_words(history, tolerance, cap) -> str:
    """The refinement in words: node counts and errors per mesh."""
    steps = ", ".join(f"{m.nodes}: {m.error:.2g}" for m in history)
    end = "" if history[-1].error <= tolerance else f"; stopped at max_nodes = {cap} above the tolerance {tolerance:g}"
    return f"mesh refinement (nodes: between-node error) {steps}{end}"


def _solver_options(engine, solver, tolerance, max_iterations, verbose, extra, log_file):
    """SolverOptions: ours first, then the user's ``extra`` by the solver's own names."""
    options = SolverOptions()
    sid = engine.solver_id()
    if solver == "ipopt":
        ours = {"tol": tolerance, "constr_viol_tol": tolerance, "max_iter": int(max_iterations),
                "print_level": 5 if verbose else 0}
        if log_file:
            ours.update(output_file=str(log_file), file_print_level=5)
    else:
        ours = {"Major optimality tolerance": tolerance, "Major feasibility tolerance": tolerance,
                "Major iterations limit": int(max_iterations), "Iterations limit": int(max_iterations) * 100}
        if verbose and not log_file:
            log_file = tempfile.NamedTemporaryFile(prefix="snopt_", suffix=".out", delete=False).name
        if log_file:
            ours["Print file"] = str(log_file)
    if extra is not None and not isinstance(extra, dict):
        raise ScenarioError("solver_options must be a dict of option name -> value")
    for key, value in {**ours, **(extra or {})}.items():
        if isinstance(value, bool) or not isinstance(value, (int, float, str, np.integer, np.floating)):
            raise ScenarioError(f"solver_options['{key}'] = {value!r}: allowed an int, float or str")
        value = int(value) if isinstance(value, np.integer) else float(value) if isinstance(value, np.floating) \
            else value
        options.SetOption(sid, key, value)
    return options, (str(log_file) if log_file else None)


def _check_guess(problem, guess):
    """(t [s] (n,), states (n, n_states), controls (n, n_controls)), finite, t increasing."""
    try:
        t, X, U = (np.asarray(g, float) for g in guess)
    except (TypeError, ValueError):
        raise ScenarioError("guess must be an NlpResult or (t, states, controls) arrays") from None
    n = t.shape[0] if t.ndim == 1 else -1
    want = f"(t ({n},), states ({n}, {problem.n_states}), controls ({n}, {problem.n_controls}))"
    if n < 2 or X.shape != (n, problem.n_states) or U.shape != (n, problem.n_controls):
        raise ScenarioError(f"guess shapes t {t.shape}, states {X.shape}, controls {U.shape}; expected {want}")
    if not (np.isfinite(t).all() and np.isfinite(X).all() and np.isfinite(U).all()) or np.any(np.diff(t) <= 0):
        raise ScenarioError("guess must be finite with strictly increasing times")
    return t, X, U

