"""Paper 000 method: corridor, SOCP in I = 1/D, extraction, tracking and reversals."""
import dataclasses as dc
import math

import numpy as np
import pytest

from drake_entry.guidance.drag_energy.drag_dynamics import drag_acceleration
from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner, plan
from drake_entry.scenario import load_scenario


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("horus2b")


@pytest.fixture(scope="module")
def planner(scenario):
    return DragEnergyPlanner.from_scenario(scenario)


@pytest.fixture(scope="module")
def engagement_state():
    """Pre-guidance end of the nominal flight (measured: t = 300 s, e = 0.042)."""
    return np.array([77438.3, math.radians(-90.93), math.radians(-16.93), 7332.0, math.radians(-0.0158),
                     math.radians(73.5)])


def _state_on_bound(planner, i, name):
    """(h, V, alpha) where constraint ``name`` reaches its limit at corridor energy i."""
    c = planner.corridor
    E, alpha = c.energy[i], c.alpha[i]
    from drake_entry.guidance.drag_energy.planner import altitude_speed_from_drag

    h, V = altitude_speed_from_drag(E, c.upper[name][i], alpha, planner.vehicle, planner.planet, planner.atmosphere)
    return h, V, alpha


def test_corridor_upper_bound_equals_the_heat_flux_limit_where_heat_flux_binds(planner):
    c = planner.corridor
    act = c.active()
    i = next(k for k in range(len(act)) if act[k] == "heat_flux" and c.energy[k] > -4.0e7)
    h, V, _ = _state_on_bound(planner, i, "heat_flux")
    rho = planner.atmosphere.density(h)
    assert planner.vehicle.heat_flux(rho, V) == pytest.approx(530e3, rel=1e-4)


def test_corridor_active_constraints_and_narrowest_point_match_the_prototype_study(planner, scenario):
    """docs/methods/drag-energy.md: heat flux binds for e < 0.57, load factor to 0.85, then q;
    narrowest D_max/D_min about 1.17 near e = 0.93 (with its own alpha ramp)."""
    c = planner.corridor
    E0, Ef = scenario.entry_energy(), planner.E_final
    e = (E0 - c.energy) / (E0 - Ef)
    act = np.array(c.active())
    assert set(act[(e > 0.05) & (e < 0.5)]) == {"heat_flux"}
    assert set(act[(e > 0.62) & (e < 0.84)]) == {"normal_load"}
    assert "dynamic_pressure" in set(act[e > 0.95])
    ratio = (c.D_max / (1 - c.margin)) / (c.D_min / (1 + c.margin))
    k = np.argmin(np.where(e > 0.05, ratio, np.inf))
    assert 1.05 < ratio[k] < 1.3 and 0.85 < e[k] < 1.0
    assert c.empty_at.size == 0


def test_equilibrium_glide_lower_bound_holds_lift_equal_to_gravity_minus_centrifugal(planner):
    c = planner.corridor
    i = len(c.energy) // 2
    from drake_entry.guidance.drag_energy.planner import altitude_speed_from_drag

    h, V = altitude_speed_from_drag(c.energy[i], c.D_eq_glide[i], c.alpha[i], planner.vehicle, planner.planet,
                                    planner.atmosphere)
    r = planner.planet.radius(h)
    rho, _, a = planner.atmosphere.properties(h)
    cl, _ = planner.vehicle.aero.coefficients(c.alpha[i], V / a)
    L = 0.5 * rho * V * V * planner.vehicle.area_over_mass * cl
    assert L == pytest.approx(planner.planet.mu / r**2 - V * V / r, rel=1e-5)


@pytest.fixture(scope="module")
def reference(planner, engagement_state):
    ref = planner.plan_from_state(engagement_state)
    assert ref.success, ref.message
    return ref


def test_socp_solution_satisfies_range_bounds_and_initial_conditions(reference):
    p = reference.problem
    assert reference.range_flown() == pytest.approx(p.range_to_go, rel=1e-6)  # eq. 83
    lo, hi = p.corridor.bounds(reference.energy)
    assert np.all(reference.D <= hi * (1 + 1e-6)) and np.all(reference.D >= lo * (1 - 1e-6))  # eq. 86
    D, Dp, _ = reference.profile(p.E0)
    assert D[0] == pytest.approx(p.D0, rel=1e-7)  # eq. 84
    assert Dp[0] == pytest.approx(p.D0_prime, rel=1e-4, abs=1e-12)
    assert reference.D[-1] == pytest.approx(p.Df, rel=1e-6)  # eq. 85


def test_clarabel_is_optimal_against_an_independent_scs_solution(reference):
    """SCS (first-order) on the conditioned SOCP at SCS_OPTIONS passes the planner's own check,
    and its answer is never cheaper than Clarabel's interior-point optimum (cost
    s' + s'' = ||D1 I|| + ||D2 I||, eq. 92) and within 1 % of it (0.25 % measured at 40 nodes)."""
    p = dc.replace(reference.problem, solver="scs", range_iterations=1, kappa_guess=reference.kappa_at)
    scs = plan(p)
    assert scs.success, scs.message
    op = reference.lgl

    def cost(ref):
        return np.linalg.norm(op.D1_tau @ (ref.I * p.D0)) + np.linalg.norm(op.D2_tau @ (ref.I * p.D0))

    lo, hi = p.corridor.bounds(scs.energy)
    assert np.all(scs.D <= hi * (1 + 1e-3)) and np.all(scs.D >= lo * (1 - 1e-3))  # the planner's check
    assert scs.range_flown() == pytest.approx(p.range_to_go, rel=1e-5)
    assert cost(reference) <= cost(scs) * (1 + 1e-6)
    assert cost(scs) <= cost(reference) * 1.01
    assert scs.objective == pytest.approx(cost(scs) / p.D0, rel=1e-9)  # the reported eq. 92 value


def test_extraction_reproduces_energy_drag_and_drag_slope(reference, planner):
    p = reference.problem
    x = reference.extraction
    for k in range(0, p.n_nodes, 7):
        E = reference.energy[k]
        assert planner.planet.specific_energy(x.h[k], x.V[k]) == pytest.approx(E, rel=1e-9)  # eq. 93
        assert drag_acceleration(x.h[k], x.V[k], p.alpha(E), planner.vehicle, planner.atmosphere) == pytest.approx(
            reference.D[k], rel=1e-6)
    assert not x.saturated.any()
    assert x.h[-1] == pytest.approx(26.5e3, abs=5.0)  # terminal drag pinned at 26.5 km, Mach 2.5


def test_infeasible_range_is_diagnosed_not_raised(planner, engagement_state):
    short = planner.plan_from_state(engagement_state, range_to_go=2000e3)
    assert not short.success
    assert "upper bound binds" in short.message and short.binding[0]["bound"] == "D_max"
    long = planner.plan_from_state(engagement_state, range_to_go=9000e3)
    assert not long.success and "lower bound binds" in long.message


@pytest.mark.parametrize("margin, limit, first_e", [(0.15, "dynamic_pressure", 0.957), (0.3, "heat_flux", 0.129)])
def test_an_empty_corridor_names_the_limit_that_closes_it_and_where(scenario, engagement_state, margin, limit,
                                                                     first_e):
    """HORUS-2B with a wide corridor margin: the diagnosis names the upper limit that closes the
    corridor first (15 %: q near the end; 30 %: the heat flux from e = 0.13) and the energy, with
    both drags, and that limit is the corridor's own smallest upper bound there."""
    wide = dc.replace(scenario, guidance=dc.replace(scenario.guidance, corridor_margin=margin))
    planner = DragEnergyPlanner.from_scenario(wide)
    ref = planner.plan_from_state(engagement_state)
    assert not ref.success
    d = ref.binding[0]
    assert d["bound"] == "corridor" and d["limit"] == limit and d["where_e"] == pytest.approx(first_e, abs=2e-3)
    assert f"the {limit.replace('_', ' ')} limit caps the drag at" in ref.message and "MJ/kg" in ref.message
    c = planner.corridor
    E = c.energy[np.searchsorted(c.energy, c.energy[c.D_min > c.D_max].max())]
    caps = {name: float(np.interp(E, c.energy, c.upper[name])) for name in c.upper}
    assert min(caps, key=caps.get) in ("heat_flux", "normal_load", "dynamic_pressure")


def test_nominal_terminal_point_violates_q_as_the_notes_say(planner, engagement_state, scenario):
    """A fixed terminal drag at 25 km, Mach 2.5 is above D_max (q limit; notes)."""
    h, V = 25e3, 2.5 * float(planner.atmosphere.speed_of_sound(25e3))
    E = planner.planet.specific_energy(h, V)
    Df = drag_acceleration(h, V, planner.alpha(E), planner.vehicle, planner.atmosphere)
    ref = planner.plan_from_state(engagement_state, Df=Df)
    assert not ref.success and "terminal drag" in ref.message and "above D_max" in ref.message


def test_dense_grid_violation_shrinks_with_nodes(planner, engagement_state):
    v = [planner.plan_from_state(engagement_state, n_nodes=n).corridor_violation()["above_max"] for n in (20, 60)]
    assert v[1] < v[0]


def test_bank_reversal_turns_back_at_the_corridor_edge():
    from drake_entry.systems.bank_reversal import BankReversalLogic

    logic = BankReversalLogic(target_lon=0.0, target_lat=0.0, corridor_deg=(5.0, 15.0),
                              corridor_velocity=(1000.0, 6000.0))
    # due east of the target, heading north: the target bears 270 deg, heading error +90 deg
    x = np.array([50e3, math.radians(1.0), 0.0, 3500.0, 0.0, 0.0])
    assert logic.heading_error(x) == pytest.approx(math.radians(90.0), abs=1e-6)
    assert logic.limit(3500.0) == pytest.approx(math.radians(10.0))
    assert logic.new_sign(x, +1.0) == -1.0  # turn left, towards the target
    x[5] = math.radians(265.0)  # 5 deg error: inside the 10 deg corridor, keep the sign
    assert logic.new_sign(x, +1.0) == +1.0 and logic.new_sign(x, -1.0) == -1.0


def test_drag_tracking_recovers_from_a_perturbed_entry(scenario, planner):
    """Controller stability: 250 m and 15 m/s off the entry interface, the loop still tracks its
    reference within 4 % after engagement and reaches E_f within 3 km of the runway."""
    from drake_entry.diagrams.closed_loop import fly

    x0 = scenario.initial_state() + np.array([250.0, 0, 0, -15.0, math.radians(0.01), 0])
    res = fly(scenario, planner, initial_state=x0)
    assert res.success, res.message
    tr = res.trajectory
    ref = tr.extra["reference"]
    on = (ref[:, 3] > 0.5) & (tr.time > res.guidance.details.engaged_at + 60.0)
    assert np.max(np.abs(tr.column("drag")[on] / ref[on, 0] - 1.0)) < 0.04
    assert res.errors["distance_m"] < 3e3
    assert abs(res.errors["altitude_m"]) < 500.0
    assert tr.column("heat_flux").max() <= 530e3 and tr.column("normal_load").max() <= 2.5


def test_drag_tracking_sign_convention_requires_negative_zeta(planner):
    from drake_entry.systems.drag_energy_tracking import DragTrackingController

    with pytest.raises(ValueError, match="zeta must be < 0"):
        DragTrackingController(planner, zeta=0.7, omega=1e-6)


def test_drag_inversion_from_a_neighbour_guess_equals_the_bracketed_root(planner):
    """Eq. 93 inverted by secant steps from a guess gives Brent's root (to 1e-3 m) and the drag."""
    from drake_entry.guidance.drag_energy.drag_dynamics import drag_acceleration
    from drake_entry.guidance.drag_energy.planner import altitude_speed_from_drag

    c = planner.corridor
    for i in (10, 150, 280):
        D = 0.5 * (c.D_min[i] + c.D_max[i])
        args = (c.energy[i], D, c.alpha[i], planner.vehicle, planner.planet, planner.atmosphere)
        h_b, V_b = altitude_speed_from_drag(*args)
        h_s, V_s = altitude_speed_from_drag(*args, h_guess=h_b + 3000.0)
        assert abs(h_s - h_b) < 1e-3 and abs(V_s - V_b) < 1e-6
        assert drag_acceleration(h_s, V_s, c.alpha[i], planner.vehicle, planner.atmosphere) == pytest.approx(D, rel=1e-8)


def _corridor_shares(ref):
    """(lambda, ramp) at the nodes: I's distance from the I of D_max as a share of the corridor's
    width in I, and the centring ramp (0 at the ends, 1 from a tenth of the span in)."""
    p, op = ref.problem, ref.lgl
    lo, hi = p.corridor.bounds(op.x)
    lam = (ref.I - 1.0 / hi) / (1.0 / lo - 1.0 / hi)
    e = (op.x - op.x[0]) / (op.x[-1] - op.x[0])
    return lam, np.clip(np.minimum(e, 1.0 - e) / 0.1, 0.0, 1.0)


def test_corridor_centring_keeps_every_node_its_share_from_both_bounds(planner, engagement_state):
    """With the centring weight the profile keeps the share m of the corridor's width (in 1/D)
    from both bounds at every node (ramped at the fixed ends), m grows with the weight and lies
    above the paper's smoothest profile's least share, the range and the end conditions
    (eqs. 83-85) still hold, and eq. 92's smoothness is paid for it (never below the paper's)."""
    paper = planner.plan_from_state(engagement_state)
    shares = {}
    for weight in (100.0, 1000.0):
        ref = planner.plan_from_state(engagement_state, centring=weight)
        assert ref.success, ref.message
        lam, ramp = _corridor_shares(ref)
        m = shares[weight] = ref.corridor_share
        assert np.all(lam >= m * ramp - 1e-7) and np.all(1.0 - lam >= m * ramp - 1e-7)
        assert ref.range_flown() == pytest.approx(ref.problem.range_to_go, rel=1e-6)
        assert 1.0 / ref.I[0] == pytest.approx(paper.problem.D0, rel=1e-7) and ref.D[-1] == pytest.approx(
            paper.problem.Df, rel=1e-6)
        assert ref.objective >= paper.objective * (1 - 1e-6)
    lam0, ramp0 = _corridor_shares(paper)
    least_paper = float(np.min(np.minimum(lam0, 1.0 - lam0)[ramp0 == 1.0]))
    assert least_paper < shares[100.0] < shares[1000.0] < 0.5
    assert math.isnan(paper.corridor_share)


def test_a_re_plan_from_the_reference_starts_at_its_drag_and_slope_not_the_flown_one(planner, engagement_state):
    """replan_start: a re-plan from a state 1 km lower than planned starts (eq. 84) at the
    previous reference's drag and slope at that energy with "reference", at the flown drag with
    "flown" (paper 000's, as the first plan)."""
    import copy

    first = planner.plan_from_state(engagement_state)
    later = engagement_state.copy()
    later[0] -= 1000.0
    E = planner.energy(later)
    D_ref, Dp_ref, _ = first.profile(E)
    flown = planner.plan_from_state(later, previous=first)
    assert flown.success and 1.0 / flown.I[0] == pytest.approx(planner.drag_state(later).D, rel=1e-7)
    assert abs(planner.drag_state(later).D / D_ref[0] - 1.0) > 0.01  # the two starts differ
    from_reference = copy.copy(planner)
    from_reference.replan_start = "reference"
    ref = from_reference.plan_from_state(later, previous=first)
    assert ref.success, ref.message
    D, Dp, _ = ref.profile(E)
    assert D[0] == pytest.approx(D_ref[0], rel=1e-7) and Dp[0] == pytest.approx(Dp_ref[0], rel=1e-4)
    assert from_reference.plan_from_state(later).I[0] == pytest.approx(flown.I[0])  # no previous: the flown drag


def test_a_range_offset_moves_the_planned_range_and_the_plan_flies_it(planner, engagement_state):
    """range_offset_m: the plan from the engagement state flies the great-circle range to go plus
    the offset (its own integral of the range, eq. 83, equals it), never below a
    tenth of the distance left."""
    import copy

    distance = float(planner.planet.great_circle_distance(engagement_state[1], engagement_state[2], *planner.target))
    short = copy.copy(planner)
    short.range_offset = -20e3
    assert short.range_to_go(engagement_state) == pytest.approx(distance - 20e3, abs=1e-6)
    base, shortened = planner.plan_from_state(engagement_state), short.plan_from_state(engagement_state)
    assert base.success and shortened.success, shortened.message
    flown = [p.range_flown() for p in (base, shortened)]  # the range, eq. 83, over the plan's nodes
    assert flown[0] == pytest.approx(distance, rel=1e-4) and flown[1] == pytest.approx(distance - 20e3, rel=1e-4)
    assert base.problem.range_to_go - shortened.problem.range_to_go == pytest.approx(20e3, rel=1e-9)
    short.range_offset = -10.0 * distance
    assert short.range_to_go(engagement_state) == pytest.approx(0.1 * distance)


@pytest.mark.parametrize("field, value, message", [
    ("guidance.replan_start", "'now'", r"guidance.replan_start 'now' is unknown; allowed: flown, reference"),
    ("guidance.corridor_centring", "-1", r"guidance.corridor_centring"),
    ("guidance.range_offset_m", "-2e6", r"guidance.range_offset_m"),
])
def test_drag_energy_refuses_an_unknown_re_plan_start_and_a_negative_centring(field, value, message):
    from drake_entry.errors import ScenarioError
    from drake_entry.scenario import apply_overrides

    with pytest.raises(ScenarioError, match=message):
        apply_overrides(load_scenario("horus2b"), {field: value})


def test_replan_where_clarabel_stalls_without_refinement_still_succeeds(planner):
    """A re-plan from a dispersed flight (tests/data) on which Clarabel with iterative
    refinement off (the planner's fast setting) stops with InsufficientProgress: the planner
    solves again with Clarabel's defaults and returns a verified plan."""
    import json
    from pathlib import Path

    case = json.loads((Path(__file__).parent / "data" / "replan_clarabel_stall.json").read_text())
    E, kappa = np.array(case["previous_energy"]), np.array(case["previous_kappa"])
    ref = planner.plan_from_state(np.array(case["state"]), sensed_drag=case["sensed_drag"], range_iterations=1,
                                  kappa_guess=lambda e: np.interp(e, E[::-1], kappa[::-1]))
    assert ref.success, ref.message
    assert ref.range_flown() == pytest.approx(planner.range_to_go(np.array(case["state"])), rel=1e-5)
    assert 1.0 / ref.I[0] == pytest.approx(case["sensed_drag"], rel=1e-6)


def test_a_re_plan_in_the_sensed_air_moves_each_limit_s_drag_bound_as_its_physics_does(planner, engagement_state):
    """DragEnergyPlanner.sensed: with lift and drag sensed at k_L, k_D times the model's, the
    drag HORUS-2B's normal-load limit allows is n_max g / (k_L/k_D L/D cos(alpha) + sin(alpha))
    (the drag of the sensed vehicle at that altitude), the q bound moves with k_D / k_rho (k_rho = sqrt(k_L k_D),
    the sensed density ratio: the limit is on the true q), the terminal drag is the sensed
    vehicle's at the terminal state (inside the corridor), the nominal ratios change nothing,
    and one set of ratios is computed once."""
    from drake_entry.guidance.drag_energy.corridor import compute_corridor

    assert planner.sensed((1.0, 1.0004)) == {}
    k_l, k_d = 1.06, 1.03
    over = planner.sensed((k_l, k_d))
    assert planner.sensed((1.0601, 1.0299))["corridor"] is over["corridor"]  # rounded to 1e-3: the same
    nominal, sensed = planner.corridor, over["corridor"]
    free = compute_corridor(nominal.energy, planner.alpha, planner.vehicle, planner.planet, planner.atmosphere)
    i = len(nominal.energy) // 2
    alpha = nominal.alpha[i]
    h, V = _state_on_bound(planner, i, "normal_load")[:2]
    cl, cd = planner.vehicle.aero.coefficients(alpha, V / planner.atmosphere.air_data(h)[1])
    ld = cl / cd
    ratio = (ld * math.cos(alpha) + math.sin(alpha)) / (k_l / k_d * ld * math.cos(alpha) + math.sin(alpha))
    assert free.upper["normal_load"][i] == pytest.approx(nominal.upper["normal_load"][i])
    assert sensed.upper["normal_load"][i] / nominal.upper["normal_load"][i] == pytest.approx(ratio, rel=2e-3)
    k_rho = math.sqrt(k_l * k_d)
    assert sensed.upper["dynamic_pressure"][i] / nominal.upper["dynamic_pressure"][i] == pytest.approx(
        k_d / k_rho, rel=2e-3)
    h_f, V_f = planner.terminal_state
    D_f = drag_acceleration(h_f, V_f, planner.alpha(planner.E_final), over["vehicle"], planner.atmosphere)
    lo, hi = sensed.bounds(np.array([planner.E_final]))
    assert over["Df"] == pytest.approx(min(max(D_f, lo[0]), hi[0])) and lo[0] <= over["Df"] <= hi[0]
    assert D_f == pytest.approx(k_d * planner.terminal_drag, rel=1e-9)
    ref = planner.plan_from_state(engagement_state, **over)
    assert ref.success, ref.message
    assert np.all(ref.D <= np.interp(ref.energy, sensed.energy, sensed.D_max) * (1 + 1e-6))


def _capsule_drag_energy(reach_margin=None):
    """The capsule's drag-energy scenario as example 27 flies it (the settings its derivation found)."""
    import importlib.util
    import os

    path = os.path.join(os.path.dirname(__file__), os.pardir, "examples", "27_drag_energy_within_reach.py")
    spec = importlib.util.spec_from_file_location("example_27", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.scenario(reach_margin)


def test_a_plan_within_reach_asks_only_for_drag_the_bank_can_give():
    """A low-L/D capsule at its drag-energy engagement (the nominal flight's loft, t = 337 s,
    66.3 km, 6794 m/s): paper 000's smoothest profile asks, from e = 0.1 on, for D'' that full
    lift down cannot give (u_FF -6.6 L/D) and at the end for D' steeper than a vertical
    descent. Within reach (margin 0.3 of L/D), every node up to e = 0.95 asks for u_FF in
    [-0.7, 0.7] L/D (to the linearisation's 1e-3) with the range, the initial drag and the
    terminal drag (eqs. 83-85) still met; the end game, pinned to the terminal drag, stays out
    of reach at two nodes (measured: e = 0.98 and 1, -1.7 and -1.8 L/D, the last at -62 deg),
    and the plan's message names them."""
    from drake_entry.guidance.drag_energy.planner import reach_excess

    planner = DragEnergyPlanner.from_scenario(_capsule_drag_energy())
    x = np.array([66284.47, math.radians(-109.70405), math.radians(20.09349), 6793.794, math.radians(-0.157948),
                  math.radians(66.14031)])
    paper = planner.plan_from_state(x)
    assert paper.success, paper.message
    within = dc.replace(paper.problem, reach_margin=0.3)
    assert reach_excess(within, paper.extraction) == math.inf  # a node past vertical
    e = (within.E0 - paper.energy) / (within.E0 - within.Ef)
    ratio = paper.extraction.u_ff / paper.extraction.lift_to_drag
    assert ratio[e < 0.95].min() < -5.0  # five times more than full lift down
    ref = plan(within)
    assert ref.success, ref.message
    ratio = ref.extraction.u_ff / ref.extraction.lift_to_drag
    assert np.all(np.abs(ratio[e < 0.95]) <= 0.7 + 1e-3), ratio
    out = np.flatnonzero(np.abs(ratio) > 0.7 + 1e-3)
    assert len(out) == 2 and e[out].min() > 0.95, (e[out], ratio[out])
    assert ref.message.count("u_FF") == 2 and "the drag's reach not met at e = 0.9" in ref.message
    assert ref.range_flown() == pytest.approx(within.range_to_go, rel=1e-5)
    assert ref.D[0] == pytest.approx(within.D0, rel=1e-6) and ref.D[-1] == pytest.approx(within.Df, rel=1e-6)
    assert ref.objective > paper.objective  # reach is paid for in eq. 92's smoothness


@pytest.mark.parametrize("margin", [-0.1, 0.5])
def test_a_reach_margin_outside_its_range_is_refused(margin, planner, engagement_state):
    from drake_entry.errors import ScenarioError

    with pytest.raises(ScenarioError, match=r"reach_margin must be in \[0, 0.45\]"):
        plan(planner.problem(engagement_state, reach_margin=margin))


def test_the_reach_verdict_and_the_nodes_it_names_agree():
    """reach_excess (the iterations' stop) and the message naming the nodes out of reach use one
    tolerance: a node a hair steeper than REACH_GAMMA_DEG, or a hair past its u range, is within
    reach and named nowhere; one past the tolerance makes the plan out of reach and is named."""
    from types import SimpleNamespace

    from drake_entry.guidance.drag_energy.planner import (
        REACH_GAMMA_DEG,
        REACH_TOLERANCE,
        _out_of_reach,
        _u_range,
        reach_excess,
    )

    p = SimpleNamespace(reach_margin=0.2, sigma_max=math.radians(80.0), E0=0.0, Ef=-1.0)
    op = SimpleNamespace(x=np.array([0.0, -0.5, -1.0]))
    ld = np.full(3, 0.3)
    lo, hi = _u_range(p, ld)
    assert hi == pytest.approx(0.3 * 0.8) and lo == pytest.approx(0.3 * (math.cos(math.radians(80.0)) + 0.2))
    limit = math.radians(REACH_GAMMA_DEG)
    within = SimpleNamespace(lift_to_drag=ld, u_ff=np.array([0.15, hi[1] + 0.5 * REACH_TOLERANCE * 0.3, lo[2]]),
                             gamma=np.array([-0.1, -0.2, -limit - 0.5 * REACH_TOLERANCE]))
    assert 0.0 < reach_excess(p, within) <= REACH_TOLERANCE
    assert _out_of_reach(p, op, within) == "the drag's reach not met at "  # no node named
    past_u = SimpleNamespace(lift_to_drag=ld, u_ff=np.array([0.15, hi[1] + 0.1 * 0.3, lo[2]]), gamma=within.gamma)
    assert reach_excess(p, past_u) == pytest.approx(0.1)
    assert _out_of_reach(p, op, past_u) == "the drag's reach not met at e = 0.500 (u_FF +0.9 L/D, gamma -11.5 deg)"
    steep = SimpleNamespace(lift_to_drag=ld, u_ff=np.array([0.15, 0.15, lo[2]]),
                            gamma=np.array([-0.1, -0.2, -limit - 2.0 * REACH_TOLERANCE]))
    assert reach_excess(p, steep) == math.inf
    assert _out_of_reach(p, op, steep) == "the drag's reach not met at e = 1.000 (u_FF +0.374 L/D, gamma -60.1 deg)"
