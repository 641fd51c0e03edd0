"""``drake-entry optimize``: an optimal reference by the NLP path (paper 002: LGL pseudospectral
or DirectCollocation, SNOPT or Ipopt), verified between the nodes and flown by the Drake
Simulator, with figures in the form of paper 002 Figs. 1-10. CLI layer."""
from __future__ import annotations

import json
import os
import sys
import time

from drake_entry.cli.common import Command
from drake_entry.errors import ScenarioError

__all__ = ["add_arguments", "run", "COMMANDS"]


def add_arguments(parser) -> None:
    parser.add_argument("problem", help="packaged problem (marv, shefex3) or a problem YAML path")
    parser.add_argument("--nodes", type=int, default=None, help="LGL nodes / collocation samples (default: the YAML)")
    parser.add_argument("--transcription", choices=("lgl", "dircol", "hermite_simpson"), default=None,
                        help="Legendre pseudospectral (paper 002), Drake's DirectCollocation, or the same "
                             "Hermite-Simpson NLP vectorised (default: the YAML)")
    parser.add_argument("--segments", type=int, default=None, metavar="S",
                        help="LGL only: S equal segments sharing their end nodes, (nodes - 1) a multiple of S "
                             "(default: the YAML's solve.segments, 1 = one global polynomial)")
    parser.add_argument("--solver", choices=("auto", "ipopt", "snopt"), default=None,
                        help="NLP solver; auto tries SNOPT, then Ipopt (default: the YAML)")
    parser.add_argument("--tolerance", type=float, default=None,
                        help="solver optimality and feasibility tolerance, scaled units (default: the YAML)")
    parser.add_argument("--coarse", type=int, default=None, metavar="N",
                        help="first solve with N nodes (LGL: one polynomial) and start the full solve from it "
                             "(0 = the propagated guess; default: the YAML's coarse_nodes)")
    parser.add_argument("--max-iterations", type=int, default=None, metavar="N",
                        help="solver iteration limit (default: the YAML's solve.max_iterations)")
    parser.add_argument("--refine", action="store_true",
                        help="mesh refinement: raise the node count until the between-node error meets the "
                             "verification tolerance (default: the YAML's solve.refine)")
    parser.add_argument("--max-nodes", type=int, default=None, metavar="N",
                        help="mesh refinement's node cap (default: the YAML's solve.max_nodes, else 150 LGL / "
                             "400 Hermite-Simpson)")
    parser.add_argument("--no-propagate", action="store_true",
                        help="skip the verification (between-node dynamics and the Drake flight of the "
                             "controls): the answer is reported converged, not verified (success false), "
                             "and the exit code is 0 when it converged")
    parser.add_argument("--out", default="out/optimize",
                        help="output directory: solution table, summary.json, figures (default: out/optimize)")
    parser.add_argument("--format", choices=("parquet", "csv"), default="csv",
                        help="solution table format (default: csv)")


def run(args) -> int:
    """Solve, verify, write the solution table, summary.json and figures; exit 0 when verified,
    130 after Ctrl-C (one line, nothing written)."""
    t0 = time.perf_counter()
    try:
        return _solve_and_write(args)
    except KeyboardInterrupt:
        print(f"drake-entry optimize: interrupted after {time.perf_counter() - t0:.0f} s; nothing was written",
              file=sys.stderr)
        return 130


def _solve_and_write(args) -> int:
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning import nlp
    from drake_entry.planning.nlp.plots import nlp_solution_plots
    from drake_entry.planning.ocp_yaml import load_problem
    from drake_entry.tables import write_table

    problem, settings = load_problem(args.problem)
    nodes = settings.nodes if args.nodes is None else args.nodes
    transcription = args.transcription or settings.transcription
    segments = settings.segments if args.segments is None else args.segments
    solver = args.solver or settings.solver
    tol = settings.tolerance if args.tolerance is None else args.tolerance
    max_iterations = settings.max_iterations if args.max_iterations is None else args.max_iterations
    refine = args.refine or settings.refine
    # the main solve's options first: a bad one is refused before the coarse solve runs
    max_nodes = (args.max_nodes or settings.max_nodes or None) if refine else None
    nlp.check_options(transcription=transcription, solver=solver, nodes=nodes, tolerance=tol,
                      max_iterations=max_iterations, dynamics_tolerance=settings.dynamics_tolerance,
                      propagation_tolerance=settings.propagation_tolerance, refine=refine, max_nodes=max_nodes,
                      segments=segments)
    guess = None
    coarse_nodes = settings.coarse_nodes if args.coarse is None else args.coarse
    if coarse_nodes and coarse_nodes < 3:
        raise ScenarioError(f"--coarse {coarse_nodes} is out of range; allowed: 0 (start from the propagated guess) "
                            f"or an integer >= 3")
    if coarse_nodes and coarse_nodes < nodes:
        print(f"coarse solve: {transcription}, {coarse_nodes} nodes, {solver} ...", flush=True)
        coarse = nlp.solve(problem, transcription=transcription, solver=solver, nodes=coarse_nodes,
                           tolerance=max(tol, 1e-6), max_iterations=max_iterations, progress=True)
        print(f"  {coarse.message}; J = {coarse.objective:.6g} in {coarse.solve_time:.1f} s")
        guess = coarse if coarse.converged else None
    how = (f"mesh refinement from {nodes} nodes" if refine else f"{nodes} nodes") + nlp.segment_words(segments)
    print(f"solve: {problem.name}, {transcription}, {how}, {solver} ...", flush=True)
    result = nlp.solve(problem, transcription=transcription, solver=solver, nodes=nodes, tolerance=tol,
                       max_iterations=max_iterations, guess=guess, segments=segments,
                       verifier=None if args.no_propagate else fly_controls,
                       refine=refine, max_nodes=max_nodes, dynamics_tolerance=settings.dynamics_tolerance,
                       propagation_tolerance=settings.propagation_tolerance, progress=True)
    check = result.verification.flight if result.verification is not None else None
    info = nlp.summary(problem, result, check)
    os.makedirs(args.out, exist_ok=True)
    cols = {"time_s": result.time}
    for i, name in enumerate(problem.state_names):
        cols[name] = result.states[:, i]
    for j, name in enumerate(problem.control_names):
        cols[name] = result.controls[:, j]
    if result.costates is not None and len(result.costate_time) == len(result.time):
        for i, name in enumerate(problem.state_names):
            cols[f"lambda_{name}"] = result.costates[:, i]
        cols["hamiltonian"] = result.hamiltonian
    write_table(cols, os.path.join(args.out, f"solution.{args.format}"))
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(info, f, indent=2, default=float)
    ext = None
    try:
        ext = nlp.extremal_controls(problem, result)
    except ValueError:
        pass
    pngs = nlp_solution_plots(problem, result, args.out, propagated=check, extremal=ext,
                              title=f"{problem.name}: {nlp.TRANSCRIPTION_LABELS[transcription]} {result.nodes} nodes"
                                    f"{nlp.segment_words(segments)}, {result.solver}")
    print(json.dumps(info, indent=2, default=float))
    print(f"wrote solution, summary.json and {len(pngs)} plots to {args.out}")
    return 0 if result.success or (args.no_propagate and result.converged) else 1


COMMANDS = (Command("optimize", "optimal reference by the NLP path (paper 002), verified and flown by Drake",
                    add_arguments, run),)
