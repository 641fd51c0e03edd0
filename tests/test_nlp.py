"""NLP path (paper 002): transcriptions against analytic optima, costates (eq. 15),
extremal controls (eqs. 22-23), bad input and infeasibility diagnosis."""
import dataclasses as dc
import math

import numpy as np
import pytest

from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.planning import nlp
from drake_entry.planning.nlp import catalogue
from drake_entry.planning.ocp import CustomProblem, PathConstraint
from drake_entry.planning.ocp_yaml import load_problem


def solve(problem, **options):
    """nlp.solve verified by the Drake flight of its controls (the verifier every caller passes)."""
    return nlp.solve(problem, verifier=fly_controls, **options)


def double_integrator(**kw):
    """min int u^2/2, x'' = u, (0, 0) -> (1, 0) in 1 s: u = 6 - 12 t, J = 6,
    lambda_x = -12, lambda_v = 12 t - 6."""
    args = dict(state_names=("x", "v"), control_names=("u",), dynamics_function=lambda x, u: np.array([x[1], u[0]]),
                initial={"x": 0.0, "v": 0.0}, final={"x": 1.0, "v": 0.0}, final_time=1.0,
                lagrange_function=lambda x, u: 0.5 * u[0] ** 2)
    args.update(kw)
    return CustomProblem(**args)


def brachistochrone(xf=2.0, yf=1.0):
    """Minimum time from (0, 0) at rest to (xf, yf), y down (nlp.catalogue), t_f in [0.1, 5] s."""
    return dc.replace(catalogue.brachistochrone(xf, yf)[0], final_time=(0.1, 5.0))


def cycloid_time(xf, yf):
    """Exact minimum time: the cycloid through (xf, yf) (nlp.catalogue)."""
    return catalogue.brachistochrone(xf, yf)[1]["final_time_s"]


@pytest.mark.parametrize("solver", ["ipopt", "snopt"])
def test_lgl_double_integrator_control_objective_and_costates_are_exact(solver):
    r = solve(double_integrator(), transcription="lgl", solver=solver, nodes=12)
    assert r.success, r.message
    t = r.time
    assert r.objective == pytest.approx(6.0, abs=1e-7)
    assert np.abs(r.controls[:, 0] - (6 - 12 * t)).max() < 1e-5
    # eq. 15: lambda = nu / w
    assert np.abs(r.costates[:, 0] + 12.0).max() < 1e-5
    assert np.abs(r.costates[:, 1] - (12 * t - 6)).max() < 1e-5
    assert np.abs(r.hamiltonian - r.hamiltonian.mean()).max() < 1e-5  # constant H (autonomous)


@pytest.mark.parametrize("transcription, nodes, tol", [("lgl", 12, 1e-6), ("dircol", 48, 5e-3),
                                                      ("hermite_simpson", 48, 5e-3)])
def test_terminal_constraint_binds_on_the_final_node_only(transcription, nodes, tol):
    """x(1) free but x(1) + v(1) >= 1 at the final node with v(1) = 0: the rest-to-rest optimum
    (J = 6) with the constraint active; the same row on the path would forbid the start."""
    reach = PathConstraint(lambda x, u, env: x[0] + x[1], min=1.0, name="reach")
    r = solve(double_integrator(final={"v": 0.0}, terminal=[reach]), transcription=transcription, nodes=nodes)
    assert r.success, r.message
    assert r.states[-1, 0] == pytest.approx(1.0, abs=1e-7)
    assert r.objective == pytest.approx(6.0, rel=tol)
    loose = PathConstraint(lambda x, u, env: x[0] + x[1], min=0.5, name="reach")
    r = solve(double_integrator(final={"v": 0.0}, terminal=[loose]), transcription=transcription, nodes=nodes)
    assert r.states[-1, 0] == pytest.approx(0.5, abs=1e-7)  # still active, at its own bound
    assert r.objective == pytest.approx(6.0 * 0.25, rel=tol)  # J scales with the distance squared


@pytest.mark.parametrize("transcription", ["dircol", "hermite_simpson"])
def test_dircol_double_integrator_converges_at_second_order(transcription):
    errs = []
    for n in (12, 24, 48):
        r = solve(double_integrator(), transcription=transcription, nodes=n)
        assert r.success, r.message
        errs.append(abs(r.objective - 6.0))
        tm = r.costate_time
        assert np.abs(r.costates[:, 1] - (12 * tm - 6)).max() < 0.04 * 12 / n * 12
    assert errs[0] / errs[2] > 12  # ~16 for second order (trapezoid cost)


@pytest.mark.parametrize("transcription,nodes,tol", [("lgl", 20, 2e-5), ("dircol", 40, 2e-3),
                                                    ("hermite_simpson", 40, 2e-3)])
def test_brachistochrone_minimum_time_equals_the_cycloid(transcription, nodes, tol):
    # Ipopt: SNOPT (auto's first try) runs into its iteration limit on dircol here (48 s)
    r = solve(brachistochrone(), transcription=transcription, nodes=nodes, solver="ipopt")
    assert r.success, r.message
    T = cycloid_time(2.0, 1.0)
    assert r.final_time == pytest.approx(T, rel=tol)
    assert r.objective == pytest.approx(T, rel=tol)
    if transcription == "lgl":  # free final time, M = t_f: H = -dM/dt_f = -1 along the extremal
        assert np.abs(r.hamiltonian[1:-1] + 1.0).max() < 1e-3


@pytest.mark.parametrize("solver", ["ipopt", "snopt"])
def test_segmented_lgl_double_integrator_costates_are_exact_at_the_knots_too(solver):
    """Three LGL segments of 5 nodes sharing their end nodes (13 nodes): J, u and the
    costates exact, at the knots (nodes 4 and 8: both segments' multipliers, each times its
    segment length, over the summed weights) as between them."""
    r = solve(double_integrator(), transcription="lgl", solver=solver, nodes=13, segments=3)
    assert r.success, r.message
    assert r.segments == 3 and r.nodes == 13
    t = r.time
    assert t[[4, 8]] == pytest.approx([1 / 3, 2 / 3], abs=1e-15)
    assert r.objective == pytest.approx(6.0, abs=1e-7)
    assert np.abs(r.controls[:, 0] - (6 - 12 * t)).max() < 1e-5
    assert np.abs(r.costates[:, 0] + 12.0).max() < 1e-5
    assert np.abs(r.costates[:, 1] - (12 * t - 6)).max() < 1e-5
    assert np.abs(r.hamiltonian - r.hamiltonian.mean()).max() < 1e-5


@pytest.mark.parametrize("transcription", ["lgl", "hermite_simpson", "dircol"])
def test_a_solved_program_and_its_transcription_are_freed(transcription):
    """The program's Python callbacks hold their transcription, which held the program: a cycle
    through C++ that the collector cannot see, every solve's program kept alive."""
    import gc

    def alive():
        gc.collect()
        return sum(1 for o in gc.get_objects() if type(o).__name__ in ("MathematicalProgram", "_LglTranscription",
                                                                       "_HermiteSimpsonTranscription",
                                                                       "_DircolTranscription"))

    before = alive()
    r = solve(brachistochrone(), transcription=transcription, nodes=12, solver="ipopt")
    assert r.converged and alive() == before


def test_segmented_lgl_brachistochrone_and_its_piecewise_interpolant():
    """3 segments of 8 nodes: the cycloid's time to 2e-5 and H = -1 to 1e-3 between the knots;
    the result's interpolant is each segment's own polynomial (a function with a kink at the
    knots is reproduced exactly, which one polynomial through all the nodes would not)."""
    r = solve(brachistochrone(), transcription="lgl", nodes=22, segments=3, solver="ipopt")
    assert r.success, r.message
    assert r.final_time == pytest.approx(cycloid_time(2.0, 1.0), rel=2e-5)
    assert np.abs(r.hamiltonian[1:-1] + 1.0).max() < 1e-3
    knot1, knot2 = r.time[7], r.time[14]

    def kinked(t):  # continuous, a polynomial on each segment, kinks at the knots
        return np.abs(t - knot1) + (t - knot2) * np.abs(t - knot2) + t**5

    piece = dc.replace(r, states=np.column_stack([kinked(r.time)] * 3))
    tt = np.linspace(0.0, r.final_time, 301)
    want = kinked(tt)
    assert piece.state_function()(tt)[:, 0] == pytest.approx(want, abs=1e-12)
    whole = dc.replace(piece, segments=1).state_function()(tt)[:, 0]
    assert np.abs(whole - want).max() > 1e-3


def test_propagated_controls_reach_the_nlp_final_state():
    p = brachistochrone()
    r = solve(p, nodes=20)
    check = nlp.propagate(p, r, fly_controls)
    assert check.terminal_error["state_max"] < 1e-4
    assert check.states[-1, 0] == pytest.approx(2.0, abs=1e-4)


def test_infeasible_problem_is_diagnosed_not_raised():
    """|u| <= 1 cannot move 1 m and stop in 1 s (needs |u| = 4 at bang-bang)."""
    r = solve(double_integrator(control_bounds={"u": (-1.0, 1.0)}), nodes=10, max_iterations=200)
    assert not r.success
    assert "largest violation" in r.message and "defects" in r.message and "collocation row at node" in r.message


@pytest.mark.parametrize("segments", [None, 1, 3])
def test_a_violated_row_is_named_by_its_state_or_path_quantity_and_node(segments):
    """row_words on Betts' heating-limited shuttle at 10 nodes (6 states, one path row): a
    collocation row by its state and node (LGL node-major in each segment: row k nx + i; Hermite-
    Simpson interval-major), a path row by its quantity and node, in the whole mesh's numbering."""
    problem, _ = catalogue.shuttle_crossrange(heating_limit=True)
    tx, _ = _transcription_at(problem, 10, segments=segments)
    names, path = problem.state_names, problem.path[0].label
    last = tx.parts[-1]
    binding = tx.collocation[-1]
    unit = "the interval from node" if segments is None else "node"
    assert tx.row_words(binding, 2 * 6 + 3) == f": the {names[3]} collocation row at {unit} {last.start + 2}"
    assert tx.row_words(binding, last.n_rows + last.path_nodes - 1) == f": path {path} at node {last.start + last.path_nodes - 1}"
    assert tx.row_words(binding, last.n_rows) == f": path {path} at node {last.start}"
    if segments == 3:  # the first segment's constraint names its own nodes
        assert tx.row_words(tx.collocation[0], 6) == f": the {names[0]} collocation row at node 1"
    parts = {b.evaluator().get_description() for b in tx.collocation}
    other = next(b for b in tx.prog.GetAllConstraints() if b.evaluator().get_description() not in parts)
    assert tx.row_words(other, 0) == ""  # a bound or terminal constraint: its description alone


def test_bad_options_and_problems_are_rejected_with_the_allowed_values():
    p = double_integrator()
    with pytest.raises(ValueError, match="allowed: lgl, dircol"):
        solve(p, transcription="hermite")
    with pytest.raises(ValueError, match="allowed: auto, ipopt, snopt"):
        solve(p, solver="knitro")
    with pytest.raises(ValueError, match="nodes must be an integer >= 3"):
        solve(p, nodes=2)
    with pytest.raises(ScenarioError, match=r"nodes = 12 with segments = 3: nodes - 1 must be a multiple of segments "
                                            r"with at least 3 nodes per segment; allowed near it: 10 or 13"):
        solve(p, nodes=12, segments=3)
    with pytest.raises(ScenarioError, match="allowed near it: 9$"):
        solve(p, nodes=5, segments=4)
    with pytest.raises(ScenarioError, match="segments = 0; allowed: an integer >= 1"):
        solve(p, nodes=12, segments=0)
    with pytest.raises(ScenarioError, match="segments = 2 applies to the lgl transcription only"):
        solve(p, nodes=13, segments=2, transcription="hermite_simpson")
    with pytest.raises(ValueError, match="unknown state 'z'"):
        double_integrator(final={"z": 1.0})
    with pytest.raises(ValueError, match="min <= max"):
        PathConstraint("dynamic_pressure", min=5.0, max=1.0)


def test_problem_yaml_errors_name_the_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("vehicle: marv\ninitial: {altitud_km: {value: 3.0}}\nfinal_time_s: {value: 10.0}\n"
                   "objective: [{kind: final_time}]\n")
    with pytest.raises(ScenarioError, match=r"initial.altitud_km: unknown field; allowed: altitude_km"):
        load_problem(str(bad))
    bad.write_text("vehicle: marv\nfinal_time_s: {value: 10.0}\nobjective: [{kind: min_fuel}]\n")
    with pytest.raises(ScenarioError, match="objective kind 'min_fuel' is unknown"):
        load_problem(str(bad))


def test_marv_solution_satisfies_paper_002_constraints_and_extremal_controls():
    """Paper 002 eqs. 16-18 hold at the nodes; eq. 23 (with the u_max^2 the Hamiltonian
    gives) reproduces the NLP controls from the costates."""
    p, _ = load_problem("marv")
    r = nlp.solve(p, nodes=24, solver="snopt", tolerance=1e-7)  # the nodes only: 24 is coarse
    assert r.converged and not r.success and "not verified" in r.message, r.message
    X, U = r.states, r.controls
    assert X[0, 0] == pytest.approx(37000.0) and X[-1, 0] == pytest.approx(0.0, abs=1e-3)
    assert math.degrees(X[-1, 1]) == pytest.approx(25.15, abs=1e-8)
    assert X[-1, 3] == pytest.approx(1219.0, abs=1e-6) and math.degrees(X[-1, 4]) == pytest.approx(-89.0, abs=1e-8)
    assert abs(X[-1, 6]) < 1e-8  # obliquity
    q = np.array([p.conditions(x, u).dynamic_pressure for x, u in zip(X, U)])
    a = np.array([p.conditions(x, u).total_load for x, u in zip(X, U)])
    assert q.min() >= 12000.0 * (1 - 1e-6) and a.max() <= 45.0 * (1 + 1e-6)
    assert np.all(np.abs(np.degrees(U[:, 0])) <= 10.0 + 1e-6) and np.all(np.abs(np.degrees(U[:, 1])) <= 30.0 + 1e-6)
    ext = nlp.extremal_controls(p, r)
    assert np.abs(ext - U).max() < 1e-6 * 100


@pytest.mark.parametrize("transcription, segments", [("lgl", 1), ("lgl", 4), ("dircol", 1), ("hermite_simpson", 1)])
def test_user_path_callable_binds_on_every_transcription(transcription, segments):
    """v <= 1.2 (the free optimum peaks at 1.5) as a user callable: active, met at the nodes,
    and the cost rises above the free optimum (DirectCollocation evaluates it in AutoDiff)."""
    p = double_integrator(path=[PathConstraint(lambda x, u, env: x[1], max=1.2, name="speed")])
    r = solve(p, transcription=transcription, nodes=21, segments=segments)
    assert r.success, r.message
    assert r.states[:, 1].max() == pytest.approx(1.2, abs=1e-6)
    assert r.objective > 6.0 * 1.05


def test_user_dynamic_pressure_callable_equals_the_builtin_constraint():
    """A user's q(x, u) callable as a path constraint gives the built-in constraint's optimum (24
    LGL nodes; at 16 SNOPT stops infeasible, info 13, with numpy 2.4 / drake 1.51)."""
    p, _ = load_problem("marv")
    builtin = nlp.solve(p, nodes=24, solver="snopt", tolerance=1e-7)
    user = [PathConstraint(lambda x, u, env: env.dynamic_pressure, min=12000.0, name="q_user")] + p.path[1:]
    mine = nlp.solve(p.with_(path=user), nodes=24, solver="snopt", tolerance=1e-7, guess=builtin)
    assert builtin.converged and mine.converged
    assert mine.objective == pytest.approx(builtin.objective, rel=1e-6)


def test_optimize_command_writes_solution_summary_and_the_ten_figures(tmp_path):
    import json

    from drake_entry.cli import main

    out = tmp_path / "opt"
    rc = main(["optimize", "marv", "--nodes", "24", "--coarse", "0", "--solver", "snopt", "--tolerance", "1e-7",
               "--out", str(out), "--no-propagate"])
    assert rc == 0
    info = json.load(open(out / "summary.json"))
    assert not info["success"] and info["converged"] and info["verification"] is None  # converged, not verified
    assert info["nodes"] == 24 and info["final_time_s"] > 0 and info["scaling"]["time_s"] > 0
    assert info["extremal_control_max_diff_deg_s"] < 1e-3
    assert len(list(out.glob("fig*.png"))) == 10 and (out / "solution.csv").exists()
    assert main(["optimize", "no_such_problem", "--out", str(out)]) == 2
    # --segments reaches the solve (4 LGL segments of 7 nodes, stopped after 3 iterations: exit 1, unconverged)
    rc = main(["optimize", "marv", "--nodes", "25", "--segments", "4", "--coarse", "0", "--solver", "snopt",
               "--max-iterations", "3", "--out", str(out), "--no-propagate"])
    info = json.load(open(out / "summary.json"))
    assert rc == 1 and not info["converged"] and (info["nodes"], info["segments"]) == (25, 4)
    assert "iteration limit" in info["message"]


def test_objective_terms_have_their_geometric_values():
    """Mayer terms against hand values: great-circle miss, crossrange sign (+ right of the
    initial heading), final latitude; the heat-load integrand is the vehicle's heat flux."""
    from drake_entry.planning.ocp import ObjectiveTerm

    p, _ = load_problem("marv")
    R = p.planet.reference_radius
    xf = np.array([0.0, math.radians(1.0), 0.0, 1219.0, math.radians(-89.0), 0.0, 0.0, 0.0])
    miss = p.with_(objective=[ObjectiveTerm("miss_distance", target=(0.0, 0.0), squared=False)])
    assert miss.mayer(xf, 100.0) == pytest.approx(R * math.radians(1.0), rel=1e-9)
    north = xf.copy()
    north[1], north[2] = math.radians(5.0), 0.01  # initial heading is east: north is to the left
    cross = p.with_(objective=[ObjectiveTerm("final_crossrange")])
    assert cross.mayer(north, 100.0) == pytest.approx(-R * 0.01, rel=1e-6)
    lat = p.with_(objective=[ObjectiveTerm("final_latitude", weight=-1.0)])
    assert lat.mayer(north, 100.0) == pytest.approx(-0.01)
    heat = p.with_(objective=[ObjectiveTerm("heat_load")])
    x = np.array([30000.0, 0, 0, 5000.0, 0, 1.5, 0.2, 0.0])
    rho = p.atmosphere.density(30000.0)
    assert heat.lagrangian(x, np.zeros(2)) == pytest.approx(p.vehicle.heat_flux(rho, 5000.0), rel=1e-12)


@pytest.mark.slow
def test_marv_60_nodes_reproduces_the_reported_solution():
    """Reduced size of docs/results/paper002_marv (README): J, t_f, the altitude maxima on
    the q = 12 kPa bound, the bank near 180 deg at t_f and the extremal controls."""
    p, _ = load_problem("marv")
    r = solve(p, nodes=60, solver="snopt", tolerance=1e-7)
    # converged; 60 nodes are not verified (between-node gamma error 0.0012 > 1e-3, the flown
    # controls reach gamma = -90 deg 0.6 s before t_f): the reported solution has 125 nodes
    assert r.converged and not r.success and r.verification.dynamics_error < 2e-3, r.message
    assert r.objective == pytest.approx(17.6556, rel=1e-4) and r.final_time == pytest.approx(808.46, abs=0.05)
    info = nlp.summary(p, r)
    maxima = info["altitude_maxima"]
    assert len(maxima) == 3 and all(abs(m["dynamic_pressure_kPa"] - 12.0) < 0.4 for m in maxima)
    assert abs(info["final_bank_deg"] - 180.0) < 5.0
    assert info["extremal_control_max_diff_deg_s"] < 1e-4


# -- scaling, free final time, verified success, statuses, options, guesses -------------------

def test_objective_scale_is_chosen_from_the_gradient_reported_and_overridable():
    p, best = catalogue.brachistochrone()
    r = solve(p, nodes=20)
    assert r.success, r.message
    assert r.scaling.source["objective"] == "gradient" and r.scaling.source["time"] == "guess final time"
    assert r.objective == pytest.approx(best["objective"], rel=2e-5)
    mine = solve(p, nodes=20, scaling={"objective": 2.0, "time": 1.0})
    assert mine.scaling.objective == 2.0 and mine.scaling.source["objective"] == "user"
    assert mine.objective == pytest.approx(best["objective"], rel=2e-5)
    with pytest.raises(ScenarioError, match=r"scaling.speed: unknown field; allowed: states, controls, time, objective"):
        solve(p, nodes=20, scaling={"speed": 1.0})
    with pytest.raises(ScenarioError, match=r"scaling.states: needs 3 values"):
        solve(p, nodes=20, scaling={"states": [1.0, 2.0]})
    with pytest.raises(ScenarioError, match=r"scaling.time = -1.0: allowed finite values > 0"):
        solve(p, nodes=20, scaling={"time": -1.0})


def test_free_final_time_forms_give_their_bounds():
    for final_time, bounds in ((None, (0.0, math.inf)), ((None, 5.0), (0.0, 5.0)), ((0.5, None), (0.5, math.inf))):
        assert tuple(dc.replace(brachistochrone(), final_time=final_time).final_time_bounds) == bounds, final_time


# each form once, each transcription at least once: the free time's NLP bounds reach the cycloid
@pytest.mark.parametrize("final_time, transcription, nodes, tol", [
    (None, "lgl", 20, 2e-5), ((None, 5.0), "dircol", 40, 2e-3), ((0.5, None), "lgl", 20, 2e-5)])
def test_free_final_time_as_none_or_an_open_interval(final_time, transcription, nodes, tol):
    p = dc.replace(brachistochrone(), final_time=final_time)
    r = solve(p, transcription=transcription, nodes=nodes)
    assert r.converged, r.message
    assert r.final_time == pytest.approx(cycloid_time(2.0, 1.0), rel=tol)


def test_final_time_forms_are_checked():
    for bad, match in ((("a", 2.0), "final_time"), ((5.0, 1.0), "0 <= min <= max"), (0.0, "0 <= min <= max")):
        with pytest.raises(ScenarioError, match=match):
            dc.replace(brachistochrone(), final_time=bad)


def test_under_resolved_solve_converges_but_is_not_called_success():
    """The false-success guard: 24 LGL nodes on MARV satisfy the NLP at the nodes (SNOPT
    info 1) but the dynamics between the nodes are off by ~4 % and the flown controls do
    not follow; the solver's word alone called this a success."""
    p, _ = load_problem("marv")
    r = solve(p, nodes=24, solver="snopt", tolerance=1e-7)
    assert r.converged and not r.success
    assert r.message.startswith("converged but inaccurate: SNOPT: optimality conditions satisfied (info 1)")
    v = r.verification
    assert v.dynamics_error > 10 * v.dynamics_tolerance and not v.verified
    assert not v.propagation_error <= v.propagation_tolerance  # nan when the propagation stopped early


def test_solver_statuses_are_in_words_and_options_pass_through(tmp_path):
    r = solve(double_integrator(), nodes=12, solver="ipopt", solver_options={"max_iter": 1})
    assert not r.success and not r.converged
    assert r.message.startswith("not solved: Ipopt: Max iteration exceeded (status 1)"), r.message
    r = solve(double_integrator(), nodes=12, solver="snopt", solver_options={"Major iterations limit": 1})
    assert not r.success and "SNOPT: major iteration limit reached (info 32)" in r.message, r.message
    with pytest.raises(ScenarioError, match=r"solver_options\['tol'\] = \[1\]: allowed an int, float or str"):
        solve(double_integrator(), nodes=12, solver="ipopt", solver_options={"tol": [1]})
    log = tmp_path / "snopt.out"
    r = solve(double_integrator(), nodes=12, solver="snopt", log_file=str(log))
    assert r.success and r.log_file == str(log) and log.exists()


def test_guess_bracket_is_superlinear_and_bisects_where_a_value_is_missing():
    """The entry guess's root finder (regula falsi, Illinois): x^3 + x - 1 on [0, 1] to 1e-12
    in at most 9 trials (bisection needs 40); an end without a value (a flight that did not
    land) gives the midpoint."""
    from drake_entry.planning.nlp.guess import _Bracket

    def f(x):
        return x ** 3 + x - 1.0

    root = 0.6823278038280193  # the real root (Cardano)
    b = _Bracket(0.0, 1.0, f(0.0), f(1.0))
    for trials in range(1, 40):
        x = b.trial()
        assert b.lo < x < b.hi
        b.keep(x, f(x), to_hi=f(x) > 0)
        if abs(x - root) < 1e-12:
            break
    assert abs(x - root) < 1e-12 and trials <= 9, (trials, x)
    assert _Bracket(0.0, 1.0, None, f(1.0)).trial() == 0.5
    assert _Bracket(0.0, 1.0, f(0.0), None).trial() == 0.5


def test_entry_guess_respects_the_control_bounds_and_meets_the_final_conditions():
    """Betts' shuttle: bank in [-89, 1] deg, no max-L/D alpha in its polynomial aero (found
    numerically), final h, V and gamma fixed, final position free."""
    from drake_entry.planning.nlp.catalogue import shuttle_crossrange

    p, _ = shuttle_crossrange()
    a = p.alpha_bar
    ld = [np.divide(*p.vehicle.aero.coefficients(a + d, 20.0)) for d in (-math.radians(0.5), 0.0, math.radians(0.5))]
    assert ld[1] >= max(ld[0], ld[2])  # the numerical max-L/D alpha
    t, X, U = nlp.initial_guess(p)
    _, _, ul, uh = p.bounds_arrays()
    assert np.all(U >= ul - 1e-12) and np.all(U <= uh + 1e-12)
    xfl, xfh = p.boundary_bounds("final")
    fixed = np.isfinite(xfl) & (xfl == xfh)
    assert X[-1, fixed] == pytest.approx(xfl[fixed], rel=1e-12)
    assert X[0, :6] == pytest.approx(p.boundary_bounds("initial")[0][:6], rel=1e-12)


# -- published optima with the defaults, mesh refinement, heating with alpha ------------


# The four published optima with the library defaults (verified, within 1e-4 of the published
# objective, the final times within 0.1 %) are solved once per session, by example 10's test.


def test_auto_solver_tries_snopt_then_ipopt():
    from pydrake.solvers import SnoptSolver

    assert nlp.default_solver() == ("snopt" if SnoptSolver().available() and SnoptSolver().enabled() else "ipopt")
    assert nlp.auto_solvers()[-1] == "ipopt"
    # auto falls back on Ipopt from the same start: SNOPT stops (info 3 or 13) on the
    # brachistochrone's singular start (v = 0) at 40 LGL nodes and tolerance 1e-8, Ipopt converges
    r = solve(catalogue.brachistochrone()[0], nodes=40)
    if nlp.default_solver() == "snopt":
        assert r.solver == "ipopt" and "(auto solver after 'SNOPT: " in r.message, r.message
    assert r.success
    with pytest.raises(ScenarioError, match="solver_options are by the solver's own names"):
        solve(double_integrator(), solver_options={"tol": 1e-6})
    with pytest.raises(ScenarioError, match="solver 'knitro' is unknown; allowed: auto, ipopt, snopt"):
        solve(double_integrator(), solver="knitro")


@pytest.mark.parametrize("transcription,start", [("lgl", 5), ("dircol", 6), ("hermite_simpson", 6)])
def test_mesh_refinement_raises_the_nodes_until_the_between_node_error_meets_the_tolerance(transcription, start):
    """From a mesh too coarse for the tolerance, each mesh warm-started from the last: the
    errors in mesh_history fall to the tolerance, the last mesh is the result's and verified."""
    problem, published = catalogue.brachistochrone()
    r = solve(problem, transcription=transcription, nodes=start, refine=True, dynamics_tolerance=1e-6)
    steps = r.mesh_history
    assert r.success, r.message
    assert len(steps) >= 2 and steps[0].nodes == start and steps[0].error > 1e-6
    assert all(b.nodes > a.nodes for a, b in zip(steps, steps[1:]))
    assert steps[-1].error <= 1e-6 and steps[-1].nodes == r.nodes == len(r.time)
    assert r.verification.dynamics_error == pytest.approx(steps[-1].error, rel=1e-9)
    assert r.objective == pytest.approx(published["objective"], rel=1e-4)
    assert "mesh refinement (nodes: between-node error) " + f"{start}: " in r.message
    assert r.solve_time == pytest.approx(sum(m.solve_time for m in steps), rel=1e-9)


def test_segmented_mesh_refinement_keeps_its_segments():
    """Two LGL segments from 9 nodes: every mesh is a node count the two segments share
    (odd), the errors fall to the tolerance and the answer is the cycloid's. (From 5 or 7
    nodes, like 4 on one polynomial, the built-in guess leads to the straight slide, 25 %
    slower and exact between the nodes: verification checks accuracy, not optimality.)"""
    problem, published = catalogue.brachistochrone()
    r = solve(problem, nodes=9, segments=2, refine=True, dynamics_tolerance=1e-6)
    assert r.success, r.message
    nodes = [m.nodes for m in r.mesh_history]
    assert len(nodes) >= 2 and nodes[0] == 9 and all(n % 2 == 1 for n in nodes) and r.segments == 2
    assert r.mesh_history[-1].error <= 1e-6
    assert r.objective == pytest.approx(published["objective"], rel=1e-4)
    r = solve(problem, nodes=5, segments=2, refine=True, max_nodes=10, dynamics_tolerance=1e-12)
    assert r.nodes == 9 and "stopped at max_nodes = 9" in r.message  # the cap rounded down to a shared count


def test_mesh_refinement_stops_at_max_nodes_and_says_so():
    problem, _ = catalogue.brachistochrone()
    r = solve(problem, nodes=5, refine=True, max_nodes=6, dynamics_tolerance=1e-9)
    assert not r.success and r.converged and r.nodes == 6
    assert [m.nodes for m in r.mesh_history] == [5, 6]
    assert "stopped at max_nodes = 6 above the tolerance 1e-09" in r.message
    with pytest.raises(ScenarioError, match=r"max_nodes = 3 is out of range; allowed: an integer >= nodes \(4\)"):
        solve(problem, nodes=4, refine=True, max_nodes=3)


def test_next_mesh_size_follows_each_transcriptions_convergence_rate():
    step = nlp.MeshStep
    # LGL, one mesh: 1.5 N; two meshes: log(error) extrapolated linearly in N to half the tolerance
    assert nlp.next_nodes("lgl", [step(40, 1e-2, True, 0.0)], 1e-3, 150) == 60
    n = nlp.next_nodes("lgl", [step(40, 1e-2, True, 0.0), step(60, 1e-3 * 2.0, True, 0.0)], 1e-3, 150)
    slope = math.log(5.0) / 20.0
    assert n == math.ceil(60 + math.log(2.0 / 0.5) / slope)
    # growth between 1.25 N and 2 N (LGL) / 3 N (dircol), capped at max_nodes
    assert nlp.next_nodes("lgl", [step(40, 1e-2, True, 0.0), step(60, 9.9e-3, True, 0.0)], 1e-3, 150) == 120
    assert nlp.next_nodes("lgl", [step(40, 1e-2, True, 0.0), step(60, 9.9e-3, True, 0.0)], 1e-3, 100) == 100
    # Hermite-Simpson: N (error / (tolerance / 2))^(1/4)
    assert nlp.next_nodes("dircol", [step(40, 1.6e-2, True, 0.0)], 2e-3, 400) == 80
    assert nlp.next_nodes("dircol", [step(40, 1.1e-3, True, 0.0)], 1e-3, 400) == 50


def test_a_solver_stop_near_the_optimum_is_restartable():
    from drake_entry.planning.nlp.status import restartable

    class Details:
        def __init__(self, info=None, words=""):
            self.info, self.words = info, words

        def ConvertStatusToString(self):
            return self.words

    class Result:
        def __init__(self, details):
            self.details = details

        def get_solver_details(self):
            return self.details

    assert restartable(Result(Details(info=3)), "snopt") and restartable(Result(Details(info=41)), "snopt")
    assert not restartable(Result(Details(info=13)), "snopt") and not restartable(Result(Details(info=1)), "snopt")
    assert restartable(Result(Details(words="Stop at acceptable point")), "ipopt")
    assert not restartable(Result(Details(words="Infeasible problem detected")), "ipopt")


def test_betts_heating_form_equals_the_imperial_formula_and_needs_alpha():
    """q = q_a(alpha) q_r: Betts 2010 Sec. 6.1 in BTU/ft^2/s against constraints.HeatFlux (SI)."""
    from drake_entry.models.constraints import HeatFlux, make_heat_flux

    ft, slug, btu = 0.3048, 14.593902937, 1055.05585262
    hf = HeatFlux.betts_shuttle()
    for rho_imp, v_imp, a_deg in ((1e-7, 20000.0, 40.0), (3e-6, 9000.0, 17.5), (2e-5, 2500.0, 0.0)):
        q_r = 17700.0 * math.sqrt(rho_imp) * (1e-4 * v_imp) ** 3.07
        q_a = 1.0672181 - 0.19213774e-1 * a_deg + 0.21286289e-3 * a_deg ** 2 - 0.10117249e-5 * a_deg ** 3
        q_si = hf(rho_imp * slug / ft ** 3, v_imp * ft, math.radians(a_deg))
        assert q_si / (btu / ft ** 2) == pytest.approx(q_a * q_r, rel=1e-12)
    assert hf.factor(0.0) == pytest.approx(1.0672181, rel=1e-15)
    with pytest.raises(ScenarioError, match="'betts_shuttle' has an angle-of-attack factor: this caller gives no alpha"):
        hf(1e-4, 7000.0)
    # any form takes a factor (e.g. from a vehicle YAML), the unit of alpha as given
    sg = make_heat_flux("sutton_graves", nose_radius=0.5, alpha_factor=(1.0, 0.5), alpha_unit="rad")
    assert sg(1e-4, 7000.0, 0.2) == pytest.approx(1.1 * make_heat_flux("sutton_graves", nose_radius=0.5)(1e-4, 7000.0))
    with pytest.raises(ScenarioError, match="alpha_unit = 'grad'; allowed: deg, rad"):
        make_heat_flux("sutton_graves", nose_radius=0.5, alpha_factor=(1.0,), alpha_unit="grad")
    with pytest.raises(ScenarioError, match="has its own angle-of-attack factor"):
        make_heat_flux("betts_shuttle", nose_radius=1.0, alpha_factor=(1.0,))


def test_heating_limit_holds_at_the_nodes_of_the_constrained_shuttle():
    """Betts' heating-limited shuttle at 40 LGL nodes: the limit binds (70 BTU/ft^2/s at the
    nodes), so the crossrange is below the unconstrained 34.1412 deg."""
    problem, published = catalogue.shuttle_crossrange(heating_limit=True)
    r = nlp.solve(problem)
    q = np.array([float(problem.conditions(x, u).heat_flux) for x, u in zip(r.states, r.controls)])
    limit = 70.0 * catalogue.BTU_FT2_S
    assert q.max() <= limit * (1 + 1e-6) and q.max() >= limit * (1 - 1e-6)
    assert math.degrees(-r.objective) < 34.1412 - 3.0


def test_plant_reports_undefined_models_as_nan_to_the_solver_and_raises_for_the_simulator():
    """A Hermite-Simpson midpoint may probe an altitude below the atmosphere's range (Betts'
    shuttle on DirectCollocation: h = -9.8 km raised out of the solve before): with
    undefined_as_nan the derivatives are NaN (the line search backs off), else the error."""
    from pydrake.autodiffutils import AutoDiffXd

    from drake_entry.errors import ModelRangeError
    from drake_entry.planning.ocp_system import OptimalControlPlant

    problem, _ = catalogue.shuttle_crossrange()
    below = np.array([-20e3, 0.0, 0.0, 7000.0, -0.1, 1.5])
    for undefined_as_nan in (True, False):
        plant = OptimalControlPlant(problem, undefined_as_nan=undefined_as_nan)
        for system in (plant, plant.ToAutoDiffXd()):
            context = system.CreateDefaultContext()
            scalar = AutoDiffXd if system is not plant else float
            context.SetContinuousState([scalar(v) for v in below])
            system.get_input_port(0).FixValue(context, [scalar(0.3), scalar(-0.5)])
            if undefined_as_nan:
                xdot = system.EvalTimeDerivatives(context).CopyToVector()
                values = [v.value() if scalar is AutoDiffXd else v for v in xdot]
                assert np.all(np.isnan(values))
            else:
                with pytest.raises(ModelRangeError, match="outside the exponential range"):
                    system.EvalTimeDerivatives(context)


@pytest.mark.parametrize("transcription", ["lgl", "dircol", "hermite_simpson"])
def test_solve_time_is_split_into_our_callbacks_and_the_solver(transcription):
    """callback_calls / callback_time count the Python callbacks the solver made (LGL: the
    one constraint and the cost; dircol: the plant's derivatives, once per sample and
    midpoint; hermite_simpson: the one constraint and the cost, two vectorised model calls
    (samples, midpoints) per new point) and nothing outside the solver: the model calls
    match, the time is a share of solve_time."""
    calls = {"n": 0}
    base = brachistochrone()

    def dynamics(x, u):
        calls["n"] += 1
        return base.dynamics_function(x, u)

    problem = dc.replace(base, dynamics_function=dynamics)
    r = nlp.solve(problem, transcription=transcription, solver="ipopt", nodes=12)
    assert r.converged
    assert 0.0 < r.callback_time < r.solve_time
    if transcription == "lgl":
        # one vectorised model call per new point, cached between the constraint and the cost
        assert 0 < r.callback_calls and calls["n"] <= r.callback_calls
    elif transcription == "hermite_simpson":
        assert 0 < r.callback_calls and calls["n"] <= 2 * r.callback_calls
    else:
        # the plant evaluates the dynamics once per call; the other callbacks (the Mayer cost,
        # once per NLP evaluation) are under 1 / 23 of them (23 samples and midpoints)
        assert r.callback_calls >= 10 * 12 and calls["n"] >= (1 - 1 / 23) * r.callback_calls


def test_yaml_verification_tolerances_default_to_the_library_and_are_checked():
    from drake_entry.planning.ocp_yaml import SolveSpec, validate_solve

    s = SolveSpec()
    assert (s.dynamics_tolerance, s.propagation_tolerance) == (nlp.DYNAMICS_TOLERANCE, nlp.PROPAGATION_TOLERANCE)
    with pytest.raises(ScenarioError, match=r"solve.dynamics_tolerance = 2.0 is out of range; allowed \(0, 1\)"):
        validate_solve(dc.replace(s, dynamics_tolerance=2.0))
    assert s.segments == 1  # paper 002's one polynomial unless asked
    with pytest.raises(ScenarioError, match=r"solve.segments = 0 is out of range; allowed: an integer >= 1"):
        validate_solve(dc.replace(s, segments=0))


def test_a_long_solve_prints_its_progress_and_ctrl_c_stops_it(monkeypatch, capsys):
    """Progress lines (elapsed, evaluations, objective, LGL collocation violation) once a solve
    has run PROGRESS_AFTER_S (0 here), the violation falling from the guess to the answer; a
    Ctrl-C inside a callback reaches the caller as KeyboardInterrupt under both solvers."""
    from drake_entry.planning import progress
    from drake_entry.planning.nlp import evaluator
    from drake_entry.planning.nlp.catalogue import brachistochrone

    monkeypatch.setattr(progress, "PROGRESS_AFTER_S", 0.0)
    monkeypatch.setattr(progress, "PROGRESS_INTERVAL_S", 0.0)
    r = nlp.solve(brachistochrone()[0], nodes=15, solver="ipopt", progress=True)
    assert r.converged
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("  [lgl 15 nodes, ipopt]")]
    assert len(lines) > 5 and all("evaluations" in ln and "(Ctrl-C stops the solve)" in ln for ln in lines)
    violations = [float(ln.split("largest collocation violation ")[1].split()[0]) for ln in lines
                  if "violation" in ln]
    assert violations[0] > 1e-3 and violations[-1] < 1e-6
    # in 2 segments (a constraint each): the evaluations are the solver's, not every callback
    r = nlp.solve(brachistochrone()[0], nodes=15, segments=2, solver="ipopt", progress=True)
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("  [lgl 15 nodes in 2 segments, ipopt]")]
    counted = int(lines[-1].split(" evaluations")[0].split()[-1])
    assert r.converged and len(lines) > 5 and 0 < 2 * counted <= r.callback_calls
    assert nlp.solve(brachistochrone()[0], nodes=15, solver="ipopt", progress=False).converged
    assert "evaluations" not in capsys.readouterr().err
    with pytest.raises(ScenarioError, match="progress = 'yes'; allowed: True, False, 'auto'"):
        nlp.solve(brachistochrone()[0], nodes=15, progress="yes")

    calls = {"n": 0}
    original = evaluator._NodeEvaluator.evaluate

    def interrupted(self, Xs, Us):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return original(self, Xs, Us)

    monkeypatch.setattr(evaluator._NodeEvaluator, "evaluate", interrupted)
    for name in nlp.auto_solvers():
        calls["n"] = 0
        with pytest.raises(KeyboardInterrupt):
            nlp.solve(brachistochrone()[0], nodes=15, solver=name, progress=False)


def _transcription_at(problem, nodes, seed=0, segments=None):
    """The vectorised Hermite-Simpson transcription of ``problem`` (LGL on ``segments``
    segments when given) at its guess, perturbed by 1 % (scaled): (transcription, scaled
    variables in z order)."""
    from drake_entry.planning.nlp.hermite_simpson import _HermiteSimpsonTranscription
    from drake_entry.planning.nlp.lgl import _LglTranscription
    from drake_entry.planning.nlp.scaling import resolve

    guess = nlp.initial_guess(problem)
    scales = resolve(problem, guess, None)
    tx = (_HermiteSimpsonTranscription(problem, nodes, scales) if segments is None
          else _LglTranscription(problem, nodes, scales, segments))
    tx.set_guess(*guess)
    z = tx.initial_guess[[tx.prog.FindDecisionVariableIndex(v) for v in tx.z]]
    return tx, z * (1.0 + 0.01 * np.random.default_rng(seed).standard_normal(z.size))


@pytest.mark.parametrize("segments, hs_part_intervals", [(None, None), (None, 4), (1, None), (3, None)])
def test_vectorised_jacobians_equal_finite_differences_inside_their_declared_sparsity(segments, hs_part_intervals,
                                                                                     monkeypatch):
    """The assembled Jacobian of each part's collocation and path rows against central
    differences of the rows themselves, on Betts' heating-limited shuttle (6 states, 2
    controls, one path row) at 10 nodes: Hermite-Simpson (one part, or two of 4 and 5
    intervals; chain rule through the midpoint state x_c, the t_f column), LGL on one polynomial and on 3 segments of 4 nodes
    (a part each, over its own nodes and t_f; each knot with both segments' rows, its path
    row in the first): within 1e-8 relative to the largest entry, and no entry outside the
    pattern given to the solver; the segments declare fewer entries."""
    from drake_entry.planning.nlp import hermite_simpson

    if hs_part_intervals:
        monkeypatch.setattr(hermite_simpson, "PART_INTERVALS", hs_part_intervals)
    problem, _ = catalogue.shuttle_crossrange(heating_limit=True)
    tx, z_all = _transcription_at(problem, 10, segments=segments)
    assert len(tx.parts) == (2 if hs_part_intervals else segments or 1)
    assert tx.tf is not None and tx.n_path == 1
    rows = {None: 10 - 1, 1: 10, 3: 3 * 4}[segments]
    assert tx.n_rows == rows * 6 and sum(p.path_nodes for p in tx.parts) == 10
    where = {tx.prog.FindDecisionVariableIndex(v): i for i, v in enumerate(tx.z)}
    for part in tx.parts:
        z = z_all[[where[tx.prog.FindDecisionVariableIndex(v)] for v in tx.part_variables(part)]]
        values, J = tx._values_jacobian(part, z)
        assert values.shape == (part.n_rows + part.path_nodes,) and J.shape == (values.size, z.size)
        numeric = np.zeros_like(J)
        for j in range(z.size):
            e = 1e-6 * max(1.0, abs(z[j]))
            a, b = z.copy(), z.copy()
            a[j] += e
            b[j] -= e
            numeric[:, j] = (tx._values_jacobian(part, a)[0] - tx._values_jacobian(part, b)[0]) / (2 * e)
        assert np.abs(J - numeric).max() <= 1e-8 * np.abs(J).max()
        pattern = set(tx._sparsity(part))
        assert set(zip(*np.nonzero(J))) <= pattern and set(zip(*np.nonzero(np.abs(numeric) > 1e-9))) <= pattern
    if segments == 3:
        single = _transcription_at(problem, 10, segments=1)[0]
        assert sum(len(tx._sparsity(p)) for p in tx.parts) < len(single._sparsity(single.parts[0]))


def test_model_values_dynamics_only_gives_the_same_dynamics_and_skips_the_rest():
    """Hermite-Simpson's midpoints need f only: the same f to the bit, no path rows, L zero,
    vectorised and node by node."""
    from drake_entry.planning.nlp.evaluator import model_values

    problem, _ = catalogue.shuttle_crossrange(heating_limit=True)
    t, X, U = nlp.initial_guess(problem)
    for vectorised in (True, False):
        f, g, L, _ = model_values(problem, X[::50].T, U[::50].T, vectorised)
        f_only, g_only, L_only, _ = model_values(problem, X[::50].T, U[::50].T, vectorised, dynamics_only=True)
        assert np.array_equal(f, f_only) and g.shape[0] == 1 and g_only.shape == (0, f.shape[1])
        assert not np.any(L_only)


@pytest.mark.slow  # two NLP solves, about 13 s of a core: CI's slow set
def test_hermite_simpson_is_drakes_direct_collocation_nlp():
    """The vectorised transcription poses the NLP of Drake's DirectCollocation (same rows,
    trapezoid cost, first-order-hold controls): Betts' shuttle at 40 samples, SNOPT from the
    same guess, the same optimum (objective to 1e-9, states to 1e-6 of their range, t_f to
    1e-6) and the same costates from the multipliers (to 1e-5), with about 40x fewer callbacks
    (measured 220 against 8760)."""
    problem, _ = catalogue.shuttle_crossrange()
    guess = nlp.initial_guess(problem)
    drake_dc = solve(problem, transcription="dircol", solver="snopt", nodes=40, guess=guess)
    ours = solve(problem, transcription="hermite_simpson", solver="snopt", nodes=40, guess=guess)
    assert drake_dc.converged and ours.converged, (drake_dc.message, ours.message)
    assert ours.objective == pytest.approx(drake_dc.objective, rel=1e-9)
    assert ours.final_time == pytest.approx(drake_dc.final_time, rel=1e-6)
    span = np.ptp(drake_dc.states, axis=0) + 1e-12
    assert np.abs((ours.states - drake_dc.states) / span).max() < 1e-6
    assert np.abs(ours.costates - drake_dc.costates).max() <= 1e-5 * np.abs(drake_dc.costates).max()
    assert ours.costate_time == pytest.approx(drake_dc.costate_time, rel=1e-6)
    assert ours.callback_calls * 10 < drake_dc.callback_calls
