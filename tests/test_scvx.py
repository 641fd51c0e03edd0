"""SCvx (paper 001): the engine on problems with known answers, the entry problem's Jacobians
against finite differences, the glide guess, and the nominal SPHYNX plan flown by Drake."""
import dataclasses as dc
import math

import numpy as np
import pytest
import scipy.sparse as sp

from drake_entry.diagrams.verification import fly_controls
from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.decision import initial_decision
from drake_entry.guidance.scvx.engine import (
    ConvexifiableProblem,
    Evaluation,
    Linearisation,
    ScvxSettings,
    defect_correction,
    golden_section,
    max_violation,
    solve_scvx,
)
from drake_entry.guidance.scvx.entry import EntryProblem, heading_regulariser_sign
from drake_entry.guidance.scvx.guess import glide_guess
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.planner import plan_controls, plan_entry
from drake_entry.guidance.scvx.settings import PAPER_LOSSLESS, EntryProblemSettings
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle


class Circle(ConvexifiableProblem):
    """min x + y subject to x^2 + y^2 - 1 = 0 (a non-convex equality): optimum (-1, -1)/sqrt(2),
    and y >= -0.5 as a buffered inequality in a second variant: optimum (-sqrt(3)/2, -1/2)."""


    def __init__(self, y_min=None):
        self.n_z, self.lower, self.upper = 2, np.full(2, -3.0), np.full(2, 3.0)
        self.n_defects = 1
        self.y_min = y_min
        self.n_inequalities = 0 if y_min is None else 1

    def evaluate(self, z):
        g = np.array([] if self.y_min is None else [self.y_min - z[1]])
        return Evaluation(float(z.sum()), np.array([z @ z - 1.0]), g, np.zeros(0))

    def linearise(self, z):
        G = sp.csc_matrix(np.zeros((0, 2)) if self.y_min is None else np.array([[0.0, -1.0]]))
        return Linearisation(self.evaluate(z), np.ones(2), sp.csc_matrix(2.0 * z[None, :]), G)


@pytest.mark.parametrize("y_min, expected", [(None, (-math.sqrt(0.5), -math.sqrt(0.5))),
                                             (-0.5, (-math.sqrt(0.75), -0.5))])
def test_engine_finds_the_optimum_on_a_circle(y_min, expected):
    # from the left: (sqrt(3)/2, -1/2) is a local minimum too (f rises along the arc from it)
    for tolerance in (1e-4, 1e-6):  # the default, and a tighter one the objective must then meet
        out = solve_scvx(Circle(y_min), np.array([-2.0, 0.5]),
                         ScvxSettings(max_iterations=60, decrease_tolerance=tolerance))
        assert out.converged, out.message
        # first-order stationarity to the decrease tolerance (the default's converges 2.7e-5 from
        # the vertex: the projection makes it feasible with the objective's decrease below 2.4e-4)
        assert out.z.sum() == pytest.approx(sum(expected), abs=tolerance * (1 + abs(sum(expected))))
        assert out.z == pytest.approx(expected, abs=1e-3)
        assert abs(out.evaluation.defects[0]) <= 1e-6


class CircleInDisc(Circle):
    """min x + y on x^2 + y^2 = 1 inside the disc |z - (0, 1)| <= 1 (a buffered Lorentz cone the
    engine re-centres on each step): the arc 30-150 deg, optimum (-sqrt(3)/2, 1/2)."""

    def evaluate(self, z):
        ev = super().evaluate(z)
        return dc.replace(ev, convex_violations=np.array([max(0.0, np.hypot(z[0], z[1] - 1.0) - 1.0)]))

    def add_convex_constraints(self, prog, z):
        buffer = prog.NewContinuousVariables(1, "buffer")
        A = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        prog.AddLorentzConeConstraint(A, np.array([1.0, 0.0, -1.0]), np.concatenate([z, buffer]))
        return buffer


@pytest.mark.parametrize("solver", ["clarabel", "scs"])
def test_engine_keeps_a_convex_cone_on_z_while_solving_for_the_step(solver):
    """With SCS the sub-problem's variables are the step dz = z - zb and the problem's cone,
    stated on z, is shifted to each zb (ShiftedCone); Clarabel solves z. Both end at the
    cone-bound optimum; SCS with its own tolerances (ScvxSettings.for_solver) and accuracy
    refinement."""
    out = solve_scvx(CircleInDisc(), np.array([-2.0, 0.5]), ScvxSettings.for_solver(solver, max_iterations=80))
    assert out.converged, out.message
    tol = 1e-5 if solver == "clarabel" else 1e-3  # SCS: 8e-4 measured
    assert out.z == pytest.approx([-math.sqrt(0.75), 0.5], abs=tol)
    assert out.evaluation.convex_violations[0] <= (1e-6 if solver == "clarabel" else 1e-5)


def test_engine_refuses_a_convex_constraint_it_cannot_shift():
    """On the step (SCS) every convex constraint must be re-centred; only Lorentz cones are."""

    class WithLinear(Circle):
        def add_convex_constraints(self, prog, z):
            prog.AddLinearConstraint(z[0] >= -0.5)
            return np.empty(0, dtype=object)

    with pytest.raises(TypeError, match="Lorentz cones only"):
        solve_scvx(WithLinear(), np.array([-2.0, 0.5]), ScvxSettings.for_solver("scs"))


def test_engine_reports_an_infeasible_problem_with_its_constraint():
    """x^2 + y^2 = 1 with y >= 2 cannot hold: the engine stops at the least-infeasible point,
    the top of the circle (0, 1) where y misses its bound by exactly 1 (the l1 merit's minimum
    of the violation on the circle), and names that constraint and its violation."""

    class Named(Circle):
        def describe_inequality(self, i):
            return "y lower bound"

    out = solve_scvx(Named(y_min=2.0), np.array([0.5, 0.5]), ScvxSettings(max_iterations=40))
    assert not out.converged
    assert out.message.startswith("stationary at an infeasible point")
    assert "largest violation 1 (y lower bound)" in out.message
    assert out.z == pytest.approx([0.0, 1.0], abs=0.01)
    assert max_violation(out.evaluation) == pytest.approx(1.0, abs=1e-3)


def test_defect_correction_is_the_least_norm_step_that_cancels_the_defects():
    """The second-order correction: C dz = -c with dz = 0 on the fixed variables and |dz| the
    smallest such (numpy's least-norm solution on the free columns)."""
    rng = np.random.default_rng(3)
    C = sp.random(6, 10, density=0.5, random_state=rng, format="csc") + sp.eye(6, 10, k=2, format="csc")
    c = rng.normal(size=6)
    free = np.ones(10, bool)
    free[[0, 5]] = False
    dz = defect_correction(C, c, free)  # its KKT system carries a 1e-12 regularisation
    assert C @ dz == pytest.approx(-c, rel=1e-9, abs=1e-9)
    assert dz[~free] == pytest.approx(0.0, abs=0.0)
    assert dz[free] == pytest.approx(np.linalg.lstsq(C.toarray()[:, free], -c, rcond=None)[0], rel=1e-9, abs=1e-9)


def test_second_order_correction_cuts_the_iterations_on_the_circle():
    """On the circle the correction returns each step to x^2 + y^2 = 1: the optimum (within the
    first-order tolerance: 5e-4 along the arc is 2e-7 of objective) in fewer iterations than the
    plain linear model (measured 22 against 27)."""
    plain = solve_scvx(Circle(), np.array([-2.0, 0.5]), ScvxSettings(second_order_correction=False))
    corrected = solve_scvx(Circle(), np.array([-2.0, 0.5]), ScvxSettings())
    assert corrected.converged and plain.converged
    assert corrected.z == pytest.approx([-math.sqrt(0.5)] * 2, abs=1e-3)
    assert corrected.z.sum() == pytest.approx(-math.sqrt(2.0), abs=1e-6)
    assert abs(corrected.evaluation.defects[0]) <= 1e-6
    assert corrected.iterations < plain.iterations


def test_golden_section_finds_the_minimum_of_a_parabola_within_its_bracket():
    calls = []

    def merit(a):
        calls.append(a)
        return (a - 0.3) ** 2

    alpha, value = golden_section(merit, merit(1.0), 12)
    assert alpha == pytest.approx(0.3, abs=2e-3) and value == pytest.approx(0.0, abs=1e-5)
    alpha, _ = golden_section(lambda a: -a, -1.0, 5)  # monotone: the full step stays
    assert alpha == 1.0


def test_settings_reject_bad_values_with_the_field_named():
    with pytest.raises(ScenarioError, match="trust_factor"):
        ScvxSettings(trust_factor=1.0)
    with pytest.raises(ScenarioError, match="solver"):
        ScvxSettings(solver="mosek")
    with pytest.raises(ScenarioError, match="rho0 <= rho1"):
        ScvxSettings(rho1=0.9, rho2=0.5)
    with pytest.raises(ScenarioError, match="site_latitude_deg"):
        ScvxMission(site_latitude_deg=95.0)
    with pytest.raises(ScenarioError, match="objective"):
        EntryProblemSettings(objective="fuel")


@pytest.fixture(scope="module")
def sphynx_case():
    vehicle, planet, atmosphere, mission = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere(), ScvxMission()
    return vehicle, planet, atmosphere, mission, glide_guess(vehicle, planet, atmosphere, mission)


def test_mission_converts_the_paper001_table1_interface_and_site(sphynx_case):
    vehicle, planet, atmosphere, mission, _ = sphynx_case
    x0 = mission.entry_state(planet)
    h_geo, lat_geo = planet.geodetic(planet.radius(x0[0]), x0[2])
    assert h_geo == pytest.approx(120e3, abs=1e-3) and math.degrees(lat_geo) == pytest.approx(30.0, abs=1e-9)
    lon, lat = mission.site(planet)
    assert math.degrees(lat) == pytest.approx(36.7895, abs=1e-3)  # geocentric, 20 km south of 36.974
    assert planet.great_circle_distance(x0[1], x0[2], lon, lat) == pytest.approx(8076e3, rel=0.01)  # notes: 8076 km
    assert heading_regulariser_sign(x0, lat) == 1.0  # site north of the entry point


def test_mission_from_geocentric_inverts_entry_state_and_site(sphynx_case):
    """``ScvxMission.from_geocentric`` (the closed loop's and a re-plan's entry) is the exact
    inverse of ``entry_state`` and ``site`` on the oblate Earth."""
    _, planet, _, mission, _ = sphynx_case
    x0 = mission.entry_state(planet)
    again = ScvxMission.from_geocentric(planet, x0, *mission.site(planet))
    assert again.entry_state(planet) == pytest.approx(x0, abs=1e-9)
    assert again.site(planet) == pytest.approx(mission.site(planet), abs=1e-12)
    assert again.entry_altitude_m == pytest.approx(120e3, abs=1e-6)
    assert again.site_latitude_deg == pytest.approx(36.974, abs=1e-9)


@pytest.mark.parametrize("formulation, objective", [("lossless", "heat_load"), ("paper_lossless", "heat_load"),
                                                   ("hybrid", "max_heat_flux"),
                                                   ("direct_bank", "max_flight_path_rate"), ("direct", "control_effort"),
                                                   ("direct", "max_load"), ("direct", "miss")])
def test_entry_jacobians_equal_central_differences(sphynx_case, formulation, objective):
    """AutoDiff Jacobians of the defects, inequalities (path, epigraph, events) and objective of
    the project's one set of equations against central differences, on a small mesh at the glide
    guess, for each formulation and the epigraph objectives."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    form = PAPER_LOSSLESS if formulation == "paper_lossless" else {"formulation": formulation}
    problem = EntryProblem(vehicle, planet, atmosphere, mission,
                           EntryProblemSettings(segments=3, nodes_per_segment=3, heading_weight=0.02,
                                                objective=objective, **form), guess.final_time)
    z = initial_decision(problem, guess)
    lin = problem.linearise(z)
    C, G = lin.defect_jacobian.toarray(), lin.inequality_jacobian.toarray()
    eps = 1e-6
    for i in range(problem.n_z):
        dz = np.zeros(problem.n_z)
        dz[i] = eps
        up, down = problem.evaluate(z + dz), problem.evaluate(z - dz)
        assert C[:, i] == pytest.approx((up.defects - down.defects) / (2 * eps), abs=1e-5 * (1 + np.abs(C[:, i]).max()))
        assert G[:, i] == pytest.approx((up.inequalities - down.inequalities) / (2 * eps), abs=1e-5 * (1 + np.abs(G[:, i]).max()))
        assert lin.objective_gradient[i] == pytest.approx((up.objective - down.objective) / (2 * eps), abs=1e-6)


def test_a_vehicle_limiting_the_normal_load_the_dynamic_pressure_and_a_mach_window(sphynx_case):
    """A vehicle whose only load limit is the normal load and that limits the dynamic pressure
    (HORUS-2B's kind): the plan bounds (L cos(alpha) + D sin(alpha)) / g0 and rho V^2 / 2 at the
    nodes (paper 000 eqs. 34-35); a DRS Mach window's lower edge is an event row M_min a - V;
    a vertical speed's upper bound is another (not in paper 001); the rows' Jacobians equal
    central differences. Without a dynamic-pressure limit its rows are -1 with no gradient."""
    from drake_entry.models.constraints import PathLimits, normal_load_factor
    from drake_entry.models.dynamics import aero_accelerations, air_data

    vehicle, planet, atmosphere, mission, guess = sphynx_case
    normal = dc.replace(vehicle, limits=PathLimits(heat_flux_max=vehicle.limits.heat_flux_max, normal_load_max=2.8,
                                                   dynamic_pressure_max=20e3))
    window = dc.replace(mission, final_mach_min=0.4, final_vertical_speed_max_m_s=-20.0)
    problem = EntryProblem(normal, planet, atmosphere, window,
                           EntryProblemSettings(segments=3, nodes_per_segment=3, formulation="direct",
                                                objective="max_load"), guess.final_time)
    assert problem.load_kind == "normal" and problem.load_max == 2.8
    z = initial_decision(problem, guess)
    X, U, _ = problem.unpack(z)
    x, u = X[4], U[4]
    rho, a = air_data(x[:6], planet, atmosphere)
    _, L, D = aero_accelerations(x[:6], x[7], rho, a, normal)
    assert problem.node_outputs(x, u)[problem.out_n] == pytest.approx(normal_load_factor(L, D, x[7], planet.g0),
                                                                       rel=1e-12)
    ev = problem.evaluate(z)
    xf = X[-1]
    a_f = problem.node_outputs(xf, U[-1])[problem.out_a]
    event = ev.inequalities[problem.n_path + problem.n_epigraph + 4]
    assert event == pytest.approx((0.4 * a_f - xf[3]) / 100.0, rel=1e-12)
    assert "DRS Mach lower bound" in problem.describe_inequality(problem.n_path + problem.n_epigraph + 4)
    assert ev.inequalities[problem.n_path + problem.n_epigraph + 5] == pytest.approx(
        (xf[3] * math.sin(xf[4]) + 20.0) / 100.0, rel=1e-12)
    assert "DRS vertical speed upper bound" in problem.describe_inequality(problem.n_path + problem.n_epigraph + 5)
    assert problem.describe_inequality(1).startswith("normal load at")
    assert problem.describe_inequality(2 + 5 * 3).startswith("dynamic pressure at node 4")
    p_max = problem.node_limits[2]
    for k in (1, 4, len(X) - 1):
        rho_k, _ = air_data(X[k, :6], planet, atmosphere)
        assert ev.inequalities[(k - 1) * 5 + 2] == pytest.approx(0.5 * rho_k * X[k, 3] ** 2 / p_max[k - 1] - 1.0,
                                                                 rel=1e-12)
    assert p_max[-1] == pytest.approx(20e3 * (1.0 - problem.settings.path_margin))
    unlimited = EntryProblem(vehicle, planet, atmosphere, window, problem.settings, guess.final_time)
    assert not np.isfinite(vehicle.limits.dynamic_pressure_max)
    rows = np.arange(unlimited.n_nodes - 1) * 5 + 2
    assert np.all(unlimited.evaluate(z).inequalities[rows] == -1.0)
    assert not unlimited.linearise(z).inequality_jacobian.toarray()[rows].any()
    lin = problem.linearise(z)
    G = lin.inequality_jacobian.toarray()
    eps = 1e-6
    for i in range(problem.n_z):
        dz = np.zeros(problem.n_z)
        dz[i] = eps
        up, down = problem.evaluate(z + dz), problem.evaluate(z - dz)
        assert G[:, i] == pytest.approx((up.inequalities - down.inequalities) / (2 * eps),
                                        abs=1e-5 * (1 + np.abs(G[:, i]).max()))


def test_initial_decision_respects_the_rate_limits_and_sets_the_epigraph_to_the_objective(sphynx_case):
    """The direct formulation's start: bank and alpha within their bounds and rate limits (their
    rates the controls), the epigraph variable equal to the max it bounds."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    problem = EntryProblem(vehicle, planet, atmosphere, mission,
                           EntryProblemSettings(formulation="direct", objective="max_load"), guess.final_time)
    z = initial_decision(problem, guess)
    assert np.all(z >= problem.lower - 1e-12) and np.all(z <= problem.upper + 1e-12)
    X, U, tf = problem.unpack(z)
    assert problem.state_names[6:] == ("bank", "alpha")
    assert np.abs(U[:, 0]).max() <= vehicle.bank_rate_limit + 1e-12
    assert np.abs(U[:, 1]).max() <= math.radians(mission.alpha_rate_limit_deg_s) + 1e-12
    loads = [problem.node_outputs(x, u)[problem.out_n] for x, u in zip(X, U)]
    assert z[-1] * problem.aux_scale == pytest.approx(max(loads), rel=1e-12)
    assert problem.evaluate(z).objective == pytest.approx(max(loads) / 3.0, rel=1e-12)


def test_initial_decision_follows_a_guess_s_own_alpha(sphynx_case):
    """A re-plan's guess carries the previous plan's alpha: the direct start flies it (within
    the alpha bounds and rate limit), not the mission's alpha(V) schedule it replaced."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    problem = EntryProblem(vehicle, planet, atmosphere, mission,
                           EntryProblemSettings(formulation="direct", objective="heat_load"), guess.final_time)
    lo, hi = np.radians(mission.alpha_bounds_deg)
    own = lo + 0.25 * (hi - lo) * (1.0 + np.cos(guess.time / guess.final_time * math.pi))  # slow: within the rate limit
    X, _, _ = problem.unpack(initial_decision(problem, dc.replace(guess, alpha=own)))
    t = problem.mesh.s * guess.final_time
    assert X[1:, 7] == pytest.approx(np.interp(t, guess.time, own)[1:], abs=1e-9)
    scheduled = np.array([problem.alpha(float(V)) for V in X[:, 3]])
    X0, _, _ = problem.unpack(initial_decision(problem, guess))
    assert X0[1:, 7] == pytest.approx(scheduled[1:], abs=1e-9)
    assert np.abs(X[1:, 7] - scheduled[1:]).max() > math.radians(1.0)


def test_settings_name_the_formulation_an_objective_needs():
    with pytest.raises(ScenarioError, match="formulation"):
        EntryProblemSettings(formulation="polar")
    with pytest.raises(ScenarioError, match="needs a formulation with rate controls"):
        EntryProblemSettings(formulation="lossless", objective="control_effort")
    with pytest.raises(ScenarioError, match="alpha_bounds_deg"):
        ScvxMission(alpha_bounds_deg=(30.0, 20.0))


def test_glide_guess_reaches_the_drs_altitude_near_the_site(sphynx_case):
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    xf = guess.states[-1]
    assert guess.reached_drs_altitude
    assert planet.atmospheric_altitude(xf[0], xf[2]) == pytest.approx(11.5e3, abs=1.0)
    assert 1000.0 < guess.final_time < 2500.0
    assert guess.miss < 500e3  # the law's best; the SCvx buffers absorb the rest


@pytest.fixture(scope="module")
def nominal_plan(sphynx_case):
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    return plan_entry(vehicle, planet, atmosphere, mission, guess=guess, verifier=fly_controls)


@pytest.fixture(scope="module")
def lossless_plan(sphynx_case):
    """The lossless bank with its defaults: it plans its DRS altitude 1200 m inside the window
    (flown through the actuators it ends about 950 m above the plan's)."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    return plan_entry(vehicle, planet, atmosphere, mission, guess=guess,
                      problem_settings=EntryProblemSettings(formulation="lossless"), verifier=fly_controls)


@pytest.fixture(scope="module")
def paper_lossless_plan(sphynx_case):
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    return plan_entry(vehicle, planet, atmosphere, mission, guess=guess,
                      problem_settings=EntryProblemSettings(**PAPER_LOSSLESS), verifier=fly_controls)


def test_nominal_plan_converges_and_its_controls_fly_to_the_site(sphynx_case, nominal_plan):
    """Paper 001 nominal (Table 1 interface, Azores site), direct bank and alpha (the form of its
    Tables 2 and 4-7), heat-load objective: converges with defects <= 1e-6 inside every limit, and
    its bank and alpha flown by the Drake Simulator through the closed loop's actuators end within
    5 km of the plan (0.97 km measured), within 15 km of the site, inside the DRS box, every path
    limit held; the planner's own model-layer flight (the same actuator law) agrees within 100 m.
    Heat load 477 MJ/m^2 measured (the paper's 540.4 with its own aero table, Table 3; both about
    8 % below their lossless plans)."""
    vehicle, planet, atmosphere, mission, _ = sphynx_case
    plan = nominal_plan
    assert plan.success, plan.message
    assert plan.formulation == "direct" and plan.lossless_gap == pytest.approx(0.0, abs=1e-12)
    assert plan.max_defect <= 1e-6 and plan.max_violation <= 1e-6
    assert plan.iterations <= 60
    assert 460.0 < plan.objective < 500.0  # MJ/m^2: regression pin of our model (paper: 540.4 with its aero)
    assert plan.peaks["heat_flux_W_m2"] <= 670e3 * (1 + 1e-6) and plan.peaks["total_load_g"] <= 3.0 + 1e-6
    # its margins hold between the nodes too (at 3dec588: 671.0 kW/m^2 and gamma 0.508 deg there)
    assert plan.between_nodes["heat_flux"] == 0.0 and plan.between_nodes["flight_path_rad"] == 0.0
    assert plan.metrics["max_bank_rate_deg_s"] <= 5.0 * 1.02  # eq. 36 (the polynomials between the nodes: 2 %)
    assert plan.metrics["max_alpha_rate_deg_s"] <= mission.alpha_rate_limit_deg_s * 1.02
    assert np.all(np.radians(mission.alpha_bounds_deg[0]) - 1e-9 <= plan.alpha)
    assert plan.miss_m <= 10e3 + 1.0
    assert plan.propagated_error_m < 5e3
    flight = plan.flown
    assert flight.ok, (flight.from_plan_m, flight.drs, flight.violations_text())
    assert flight.from_plan_m == plan.propagated_error_m and not flight.failure
    assert flight.trajectory.time[-1] == pytest.approx(plan.final_time, abs=1e-9)
    assert flight.from_site_m < 15e3
    assert all(c.held and c.margin >= 0.0 for c in flight.checks)
    names = {c.limit.name for c in flight.checks}
    assert {"heat_flux", "total_load", "bank", "flight_path"} <= names
    # the plan's state at t/2 on its own polynomials equals the node values where they coincide
    mid = plan.evaluate(plan.time[len(plan.time) // 2])
    assert mid["V"][0] == pytest.approx(plan.states[len(plan.time) // 2, 3], rel=1e-12)
    assert mid["bank"][0] == pytest.approx(plan.bank[len(plan.time) // 2], abs=1e-12)


def test_the_verifiers_fixed_steps_fly_the_plan_as_a_tight_error_controlled_flight(nominal_plan):
    """The plan verifier flies through the sampled actuators with fixed RK5 steps of half the
    guidance period; the same diagram with error-controlled RK5 at accuracy 1e-10 ends within
    5 m of it (0.3 m measured against 1e-9), and both end where the verdict says."""
    plan = nominal_plan
    tight = fly_controls(plan_controls(plan, plan.flight), accuracy=1e-10)
    assert not tight.failure and tight.time[-1] == pytest.approx(plan.final_time, abs=1e-9)
    xf, xg = tight.states[-1], plan.flown.states[-1]
    gap = math.hypot(plan.problem.planet.great_circle_distance(xf[1], xf[2], xg[1], xg[2]), xf[0] - xg[0])
    assert gap < 5.0, gap
    assert abs(xf[3] - xg[3]) < 0.05  # m/s


def test_the_verifier_flies_a_plans_actuator_response_as_the_actuator_systems(nominal_plan):
    """The verifier flies a plan's commands as their actuators' response computed before the
    flight (no Python call per stage); through the sampled actuator systems themselves the
    same flight takes the same steps and ends within 1e-6 m and 1e-9 m/s of it, the bank
    flown within 1e-12 rad at every logged sample."""
    plan = nominal_plan
    controls = plan_controls(plan, plan.flight)
    fast, systems = fly_controls(controls), fly_controls(controls, actuator_systems=True)
    assert not fast.failure and not systems.failure
    assert len(fast.trajectory.steps.time) == len(systems.trajectory.steps.time)
    xf, xs = fast.states[-1], systems.states[-1]
    planet = plan.problem.planet
    assert math.hypot(planet.great_circle_distance(xf[1], xf[2], xs[1], xs[2]), xf[0] - xs[0]) < 1e-6
    assert abs(xf[3] - xs[3]) < 1e-9
    assert np.max(np.abs(fast.trajectory.bank - systems.trajectory.bank)) < 1e-12
    assert np.max(np.abs(fast.trajectory.alpha - systems.trajectory.alpha)) < 1e-12


@pytest.mark.slow
def test_nominal_heat_load_matches_the_nlp_path(sphynx_case, nominal_plan):
    """Paper 001 Table 3 against the NLP path: the same direct minimum-heat-load problem (``as_ocp.mission_problem``:
    same models, limits and DRS box) through ``nlp.solve`` with Hermite-Simpson collocation + SNOPT at 100
    samples from the same glide guess (the NLP of Drake's DirectCollocation, vectorised:
    24 s against 9 minutes through DirectCollocation): the SCvx heat load within 1 % of it (measured 477.60 vs
    475.02 MJ/m^2, +0.54 %). The NLP answer is checked as an answer: its DRS box met at the final
    node, heat flux within the limit, its controls flown by the Drake Simulator 0.07 km from its
    terminal point."""
    from drake_entry.guidance.scvx.as_ocp import nlp_form
    from drake_entry.planning import nlp

    vehicle, planet, atmosphere, mission, guess = sphynx_case
    plan = nominal_plan
    problem, start = nlp_form(plan)
    assert plan.guess is guess and problem.final_time_bounds == pytest.approx(
        (0.3 * guess.final_time, 3.0 * guess.final_time), rel=1e-12)  # the SCvx problem's bounds
    assert start[1][0, :6] == pytest.approx(mission.entry_state(planet), rel=1e-12)  # the OCP's layout
    result = nlp.solve(problem, transcription="hermite_simpson", solver="snopt", nodes=100, guess=start,
                       tolerance=1e-6, verifier=fly_controls)
    assert result.success, result.message
    assert plan.objective == pytest.approx(result.objective / 1e6, rel=0.01)
    for c, value in zip(problem.terminal, problem.terminal_values(result.states[-1], result.controls[-1])):
        assert c.min - 1e-6 * c.scale <= value <= c.max + 1e-6 * c.scale, c.name
    q = [problem.conditions(x, u).heat_flux for x, u in zip(result.states, result.controls)]
    assert max(q) <= vehicle.limits.heat_flux_max * (1 + 1e-6)
    assert nlp.propagate(problem, result, fly_controls).terminal_error["position_m"] < 1e3


def test_nominal_lossless_plan_converges_in_35_iterations_and_its_real_bank_flies(sphynx_case, lossless_plan):
    """Paper 001 Table 3, lossless bank: the nominal lossless heat-load plan (u = (cos, sin) of the bank, eqs.
    37-45, with the floor |u| >= 0.99 and the bank-rate chords) converges from the glide guess
    in <= 35 iterations (measured 27: the projection of nearly feasible points and the
    convergence test at feasible points cut the tail of 37) with defects <= 1e-6,
    reports its gap (<= 0.01), and its real
    bank atan2(u2, u1) flown by the Drake Simulator through the closed loop's actuators ends <= 5 km
    from the plan (measured 1.9 km), <= 15 km from the site, inside the DRS box (its default
    1200 m altitude margin: planned 11.80 km, flown 12.75 km), every path limit held."""
    vehicle, planet, atmosphere, mission, _ = sphynx_case
    plan = lossless_plan
    assert plan.success, plan.message
    assert plan.iterations <= 35
    assert plan.max_defect <= 1e-6 and plan.max_violation <= 1e-6
    assert plan.lossless_gap <= 0.01 + 1e-6 and plan.lossless_gap_all <= 0.01 + 1e-6
    assert 500.0 < plan.objective < 540.0  # MJ/m^2: regression pin of our model (the ratio test below is the paper check)
    turns = plan.problem.bank_turns(plan.controls)
    assert np.all(turns <= plan.problem.bank_turn_limits(plan.final_time) * (1 + 1e-6) + 1e-6)
    flight = plan.flown
    assert flight.ok and flight.drs_ok, (flight.from_plan_m, flight.drs, flight.violations_text())
    assert flight.from_plan_m <= 5e3 and flight.from_site_m <= 15e3
    assert 10e3 <= flight.drs["altitude_m"] <= 13e3


def test_paper_lossless_plan_reports_its_gap_and_is_refused_when_its_bank_does_not_fly(sphynx_case,
                                                                                    paper_lossless_plan):
    """The paper's lossless relaxation (Table 3 'Lossless Bank': no floor on |u|, no rate limit,
    no margins, the heading regulariser) converges near the study's 520 MJ/m^2 with |u| < 1 at
    the skip and the final dive; its real bank flown by the Drake Simulator through the closed
    loop's actuators misses: more than 5 km from the plan (12 to 17 km measured on different
    machines) and above the DRS window, so the plan is refused, its message says why and points
    to the direct polish."""
    vehicle, planet, atmosphere, _, _ = sphynx_case
    plan = paper_lossless_plan
    assert plan.message.startswith("converged in")
    assert plan.max_defect <= 1e-6 and plan.max_violation <= 1e-6
    assert 500.0 < plan.objective < 540.0  # MJ/m^2: regression pin of our model (paper: 573.5 with its aero)
    assert 0.01 < plan.lossless_gap < 0.5  # 0.1-0.3 measured, by trust-region path
    flight = plan.flown
    assert flight.from_plan_m > 5e3 and not flight.ok
    assert not plan.success
    assert "converged but its controls flown end" in plan.message and "'direct'" in plan.message


def test_planning_alpha_lowers_the_heat_load_as_paper001_table3_reports(nominal_plan, paper_lossless_plan):
    """Paper 001 Table 3: with the angle of attack in the optimisation the minimum heat load
    falls from 573.455 (lossless bank) to 540.382 MJ/m^2 (direct AOA and bank), 5.8 % (its
    Sec. V text). Ours, with the labelled representative aerodynamics (the paper's table is not
    public), must show the same effect within a factor of two: 3 to 12 % (8.4 % measured:
    477 vs 521 MJ/m^2). The absolute bands of the other tests are regression pins of our model."""
    reduction = 1.0 - nominal_plan.objective / paper_lossless_plan.objective
    assert 1.0 - 540.382 / 573.455 == pytest.approx(0.0577, abs=1e-4)
    assert 0.03 < reduction < 0.12, reduction


def test_default_lossless_margin_is_what_flies_it_into_the_drs_window(sphynx_case):
    """The lossless plan with the rate formulations' 200 m DRS margin plans 12.8 km and flies
    above the 10-13 km window (eq. 64) through the actuators: refused, naming the flown altitude."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    plan = plan_entry(vehicle, planet, atmosphere, dc.replace(mission, final_altitude_margin_m=200.0), guess=guess,
                      problem_settings=EntryProblemSettings(formulation="lossless"), verifier=fly_controls)
    assert plan.drs["altitude_m"] == pytest.approx(12.8e3, abs=1.0)
    assert plan.flown.drs["altitude_m"] > 13e3 and not plan.flown.drs_ok
    assert not plan.success and "outside the DRS box (geodetic altitude 1" in plan.message


def test_direct_polish_of_the_lossless_plan_flies(sphynx_case, paper_lossless_plan):
    """``plan_entry(initial=lossless plan)`` in the direct formulation: the bank becomes a state
    (rate-limited from atan2(u2, u1)) and alpha is freed; the polished plan flies within 5 km
    and lowers the heat load (alpha planned)."""
    vehicle, planet, atmosphere, mission, _ = sphynx_case
    polished = plan_entry(vehicle, planet, atmosphere, mission, initial=paper_lossless_plan,
                          problem_settings=EntryProblemSettings(formulation="direct"), verifier=fly_controls)
    assert polished.success, polished.message
    assert polished.guess is None
    assert polished.propagated_error_m < 5e3
    assert polished.objective < paper_lossless_plan.objective


def test_warm_start_from_a_plan_on_a_finer_mesh_keeps_its_heat_load(sphynx_case, nominal_plan):
    """``plan_entry(initial=plan)`` interpolates a converged plan onto another mesh and
    re-converges near the same optimum (within 1 %), and its controls flown through the
    actuators still meet the DRS box and the limits."""
    vehicle, planet, atmosphere, mission, _ = sphynx_case
    warm = plan_entry(vehicle, planet, atmosphere, mission, initial=nominal_plan,
                      problem_settings=EntryProblemSettings(segments=40, nodes_per_segment=4), verifier=fly_controls)
    assert warm.message.startswith("converged"), warm.message
    assert warm.guess is None and warm.problem.n_nodes == 121
    assert warm.max_defect <= 1e-6 and warm.max_violation <= 1e-6
    assert warm.objective == pytest.approx(nominal_plan.objective, rel=0.01)
    assert warm.success, warm.message
    assert warm.flown.drs_ok and warm.flown.within_limits and warm.propagated_error_m <= 5e3


def test_min_max_load_objective_is_the_epigraph_of_the_peak_load(sphynx_case, lossless_plan):
    """Table 2's 'Min Maximum g-load' through the epigraph variable (mu >= n_k at every node):
    the objective is the plan's peak load and lies below the heat-load plan's peak (Table 2: 1.111 g
    with its aero; measured here 1.17 g), in the paper's relaxation (with the |u| floor and the
    rate chords it does not converge in 60: the peak alone shapes the plan). Its relaxed bank
    (gap 0.48) does not fly: through the actuators it ends 25.7 km from the plan, above the DRS
    window, so the plan is refused and points to the direct polish."""
    vehicle, planet, atmosphere, mission, guess = sphynx_case
    plan = plan_entry(vehicle, planet, atmosphere, mission, guess=guess,
                      problem_settings=EntryProblemSettings(objective="max_load", **PAPER_LOSSLESS), verifier=fly_controls)
    assert plan.message.startswith("converged in"), plan.message
    assert plan.lossless_gap > 0.1 and plan.propagated_error_m > 5e3
    assert not plan.success and "polish it with the 'direct' formulation" in plan.message
    assert plan.objective == pytest.approx(plan.metrics["max_load_g"], rel=1e-6)
    assert plan.objective < 0.6 * lossless_plan.metrics["max_load_g"]
    assert plan.between_nodes["load"] == 0.0 or plan.between_nodes["load"] < 0.02
