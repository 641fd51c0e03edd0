"""NLP path: entry optimal control by Legendre pseudospectral (LGL) collocation or Drake's
DirectCollocation, solved with Ipopt or SNOPT (paper 002).

    result = solve(problem, transcription="lgl" | "dircol", solver="ipopt" | "snopt", nodes=N)

``problem`` is an ``OptimalControlProblem`` (entry dynamics, planning/ocp.py) or a
``CustomProblem``. The NLP runs in scaled units (problem.scales(): canonical units as in
paper 002, altitude in 10 km, controls by their bounds); results are SI.

LGL (paper 002 eqs. 12-14, Fahroo & Ross): states and controls at the N LGL nodes
tau_k of [-1, 1], t = (tau + 1) t_f / 2. The defects are split so every nonlinear
binding stays small (one per node): F_k = (t_f / 2) f(x_k, u_k) (nonlinear, per node) and
D X = F (linear, per state). Costates come from the KKT multipliers of D X = F (eq. 15):
lambda(t_k) = nu_k / w_k, converted back to SI.

DirectCollocation: Drake's Hermite-Simpson transcription of systems.ocp_plant (the same
scaled dynamics as a Drake System) with N samples; the running cost is the trapezoid rule
over the samples; costates are estimated at the segment midpoints from the collocation
multipliers, lambda(t_k+1/2) = 3 nu_k / (2 h_k).

The result reports the Hamiltonian H = L + lambda' f along the solution (zero on an
extremal with free final time, paper 002 Fig. 10) and ``propagate`` (diagrams.propagation)
flies the controls with the Drake Simulator to check the terminal state.

Modules: result (NlpResult, extremal controls, summary), guess (initial guesses),
evaluator (node values and Jacobians), transcription (shared parts), lgl, dircol.
"""
from __future__ import annotations

import time as _time

import numpy as np
from pydrake.solvers import IpoptSolver, SnoptSolver, SolverOptions

from ...errors import ScenarioError
from .dircol import _DircolTranscription
from .guess import initial_guess
from .lgl import _LglTranscription
from .result import NlpError, NlpResult, extremal_controls, summary  # noqa: F401 (API)
from .transcription import COSTATE_SIGN  # noqa: F401 (API)

TRANSCRIPTIONS = ("lgl", "dircol")
SOLVERS = ("ipopt", "snopt")


def solve(problem, *, transcription: str = "lgl", solver: str = "ipopt", nodes: int = 40, guess=None,
          tolerance: float = 1e-8, max_iterations: int = 3000, verbose: bool = False) -> NlpResult:
    """Solve ``problem`` (see module docstring).

    Args:
      transcription: 'lgl' (Legendre pseudospectral, paper 002 eqs. 12-14) or 'dircol'.
      solver: 'ipopt' (default) or 'snopt'.
      nodes: LGL nodes or DirectCollocation samples (>= 3).
      guess: an NlpResult, or (t [s], states (n, nx), controls (n, nu)) SI, or None for the
        built-in propagated guess (``initial_guess``).
      tolerance: solver optimality and feasibility tolerance (scaled units).
      max_iterations: solver iteration limit.
    """
    if transcription not in TRANSCRIPTIONS:
        raise ScenarioError(f"transcription '{transcription}' is unknown; allowed: {', '.join(TRANSCRIPTIONS)}")
    if solver not in SOLVERS:
        raise ScenarioError(f"solver '{solver}' is unknown; allowed: {', '.join(SOLVERS)}")
    if not (isinstance(nodes, (int, np.integer)) and nodes >= 3):
        raise ScenarioError(f"nodes must be an integer >= 3, got {nodes}")
    if not 0 < tolerance < 1:
        raise ScenarioError(f"tolerance = {tolerance} is out of range; allowed (0, 1)")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) or max_iterations < 1:
        raise ScenarioError(f"max_iterations = {max_iterations} is out of range; allowed: an integer >= 1")
    engine = IpoptSolver() if solver == "ipopt" else SnoptSolver()
    if not engine.available() or not engine.enabled():
        raise NlpError(f"solver '{solver}' is not available in this pydrake build")
    if guess is None:
        guess = initial_guess(problem)
    elif isinstance(guess, NlpResult):
        guess = (guess.time, guess.states, guess.controls)
    _check_guess(problem, guess)
    t_build = _time.perf_counter()
    tx = _LglTranscription(problem, nodes) if transcription == "lgl" else _DircolTranscription(problem, nodes)
    tx.set_guess(*guess)
    build_time = _time.perf_counter() - t_build
    options = SolverOptions()
    if solver == "ipopt":
        options.SetOption(engine.solver_id(), "tol", tolerance)
        options.SetOption(engine.solver_id(), "constr_viol_tol", tolerance)
        options.SetOption(engine.solver_id(), "max_iter", int(max_iterations))
        options.SetOption(engine.solver_id(), "print_level", 5 if verbose else 0)
    else:
        options.SetOption(engine.solver_id(), "Major optimality tolerance", tolerance)
        options.SetOption(engine.solver_id(), "Major feasibility tolerance", tolerance)
        options.SetOption(engine.solver_id(), "Major iterations limit", int(max_iterations))
        options.SetOption(engine.solver_id(), "Iterations limit", int(max_iterations) * 100)
        if verbose:
            options.SetOption(engine.solver_id(), "Print file", "snopt.out")
    t0 = _time.perf_counter()
    res = engine.Solve(tx.prog, tx.initial_guess, options)
    solve_time = _time.perf_counter() - t0
    return tx.result(res, solver, solve_time, build_time)


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

