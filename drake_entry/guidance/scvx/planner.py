"""Plan an entry with SCvx (paper 001): glide guess -> EntryProblem -> solve_scvx -> ScvxPlan,
with the answer re-checked between the nodes before it is called a success."""
from __future__ import annotations

import dataclasses as dc
import math
import time

import numpy as np

from drake_entry.guidance.scvx.decision import decision_from_trajectory, initial_decision
from drake_entry.guidance.scvx.engine import max_defect, max_violation, solve_scvx
from drake_entry.guidance.scvx.entry import EntryProblem
from drake_entry.guidance.scvx.feedback import feedback_maker
from drake_entry.guidance.scvx.guess import GlideGuess, glide_guess
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.settings import EntryProblemSettings, FlightCheck, ScvxSettings
from drake_entry.models.acceleration_ratios import sensed_vehicle
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.dynamics import (
    STATE_NAMES,
    flight_conditions,
)
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle
from drake_entry.models.verdict import PathLimit, breaches_text, check_limits, vehicle_path_limits
from drake_entry.planning.result import PlanResult
from drake_entry.planning.verification import (
    Actuation,
    EntryControls,
    FlownControls,
    Tracking,
    Verifier,
    require_verifier,
)

__all__ = ["GAP_LIFT_FRACTION", "BETWEEN_NODE_TOLERANCE", "POINTS_PER_SEGMENT", "PROPAGATION_TOLERANCE_M",
           "OBJECTIVE_METRIC", "ScvxPlan", "plan_metrics",
           "plan_controls", "PlanFlight", "flown_check", "drs_point", "plan_path_limits", "terminal_distance",
           "plan_entry", "equivalent_heading", "replan_from"]

#: the lossless gap is judged where the lift can act: L >= this fraction of g0
GAP_LIFT_FRACTION = 0.05
#: between-node re-check: relative tolerance on heat flux, load and dynamic pressure, absolute
#: on gamma [rad]
BETWEEN_NODE_TOLERANCE = (0.02, 0.02, 0.02, math.radians(0.2))
#: evaluation points per mesh segment for the between-node check and the rate metrics
POINTS_PER_SEGMENT = 8
#: the plan's controls flown must end within this of its terminal point [m]
PROPAGATION_TOLERANCE_M = 5e3

#: ``ScvxPlan.metrics`` keys of each objective (paper 001 Table 2)
OBJECTIVE_METRIC = {"heat_load": "heat_load_MJ_m2", "control_effort": "control_effort_deg",
                    "max_control_rate": "max_control_rate_deg_s", "max_flight_path_rate": "max_flight_path_rate_deg_s",
                    "max_heat_flux": "max_heat_flux_kW_m2", "max_load": "max_load_g", "time": "final_time_s",
                    "miss": "miss_km"}


@dc.dataclass(kw_only=True)
class ScvxPlan(PlanResult):
    """An SCvx entry plan (a PlanResult over time; ``objective`` in the unit of
    ``settings.OBJECTIVES``: MJ/m^2, deg, deg/s, kW/m^2, g, s or km).

    Attributes:
      formulation: the EntryProblemSettings formulation ('lossless', 'hybrid', 'direct_bank', 'direct').
      time: node times [s]; states: (n, n_x) SI, columns ``problem.state_names`` (h, lon, lat, V,
        gamma, psi, then bank and alpha where they are states); controls: (n, n_u) at the nodes
        ((u1, u2) of the lossless bank, then the rates [rad/s]); final_time: t_f [s].
      bank, alpha: the bank and angle of attack [rad] at the nodes (atan2(u2, u1) and alpha(V)
        where they are not states).
      heat_load: integral of q dt [J/m^2] (without the regulariser).
      lossless_gap: max(1 - |u|) over nodes where L >= 5 % g0; lossless_gap_all: over all nodes
        (0 when the bank is a state: the flown bank is the planned one).
      max_defect, max_violation: largest scaled dynamics defect and constraint violation.
      between_nodes: worst relative excess of heat flux, load and dynamic pressure and of gamma
        [rad] over their limits on the segment polynomials between the nodes (8 points per
        segment).
      miss_m: planned DRS point to the site [m]; drs: planned DRS altitude (geodetic) [m], Mach,
        vertical speed [m/s].
      metrics: the paper's Table 2, 3 and 6 quantities (``plan_metrics``).
      flight: the FlightCheck it was flown with; flown: the PlanFlight (``flown_check``: the
        flown DRS point and box, the path-limit checks); verifier: what flew it (re-plans
        use the same).
      guess: the glide guess it started from; history: the engine's IterationRecords.
      feedback_laws: the tracking laws made about it (``scvx.feedback.plan_feedback``).
    """

    formulation: str
    time: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    final_time: float
    bank: np.ndarray
    alpha: np.ndarray
    heat_load: float
    lossless_gap: float
    lossless_gap_all: float
    max_defect: float
    max_violation: float
    between_nodes: dict
    miss_m: float
    drs: dict
    metrics: dict
    guess: GlideGuess | None = None
    flight: FlightCheck | None = None
    flown: PlanFlight | None = dc.field(default=None, repr=False)
    verifier: Verifier | None = dc.field(default=None, repr=False)
    history: list = dc.field(default_factory=list, repr=False)
    problem: EntryProblem | None = dc.field(default=None, repr=False)
    #: its feedback laws by (kind, weight), made once (drake_entry.guidance.scvx.feedback)
    feedback_laws: dict = dc.field(default_factory=dict, repr=False)

    @property
    def propagated_error_m(self) -> float:
        """The plan's real bank and alpha flown by the verifier (the Drake Simulator) from its
        entry state through the closed loop's actuators (``plan_controls``) end this far from its
        terminal point [m] (great circle and altitude; inf when the flight stopped early, nan
        before it flew); ``success`` needs it <= PROPAGATION_TOLERANCE_M."""
        return self.flown.from_plan_m if self.flown is not None else math.nan

    @property
    def peaks(self) -> dict:
        """Max heat flux [W/m^2] and total load [g] at the nodes."""
        return {"heat_flux_W_m2": self.metrics["max_heat_flux_kW_m2"] * 1e3, "total_load_g": self.metrics["max_load_g"]}

    def evaluate(self, at) -> dict:
        """The plan at times ``at`` [s] on its own segment polynomials: the states by name
        (h, lon, lat, V, gamma, psi), bank and alpha [rad], and the controls ('u1', 'u2' for the
        lossless bank, 'bank_rate', 'alpha_rate' [rad/s] for the rate formulations)."""
        t = np.clip(np.atleast_1d(np.asarray(at, float)), 0.0, self.final_time)
        p = self.problem
        P = p.mesh.interpolation(t / self.final_time)
        X, U = P @ self.states, P @ self.controls
        out = {name: X[:, i] for i, name in enumerate(p.state_names)}
        bank_alpha = [p.bank_and_alpha(x, u) for x, u in zip(X, U)]
        out["bank"] = np.array([math.atan2(s, c) for c, s, _ in bank_alpha])
        out["alpha"] = np.array([float(a) for _, _, a in bank_alpha])
        if p.formulation.bank == "lossless":
            out.update(u1=U[:, 0], u2=U[:, 1])
        names = {p.i_sigma: "bank_rate", p.i_alpha: "alpha_rate"}
        for control, state in p.rate_controls:
            out[names[state]] = U[:, control]
        return out

    def control_samples(self, samples_per_segment: int = 32):
        """The controls to fly, sampled on the plan's polynomials: times [s] (``samples_per_segment``
        per mesh segment), the bank unwrapped [rad], and the planned alpha [rad] (None where alpha
        follows the mission's alpha(V) law, to be evaluated at the flown speed)."""
        tt = np.linspace(0.0, self.final_time, samples_per_segment * self.problem.mesh.n_segments + 1)
        ref = self.evaluate(tt)
        return tt, np.unwrap(ref["bank"]), (ref["alpha"] if self.problem.i_alpha is not None else None)


def _dense(problem: EntryProblem, X, U):
    """Points between the nodes (POINTS_PER_SEGMENT per segment, and the ends): s, states, controls."""
    mesh = problem.mesh
    inner = (np.arange(mesh.n_segments)[:, None] + (np.arange(POINTS_PER_SEGMENT)[None, :] + 0.5)
             / POINTS_PER_SEGMENT).ravel() / mesh.n_segments
    s = np.concatenate([[0.0], inner, [1.0]])
    P = mesh.interpolation(s)
    return s, P @ X, P @ U


def _between_nodes(problem: EntryProblem, X, U) -> dict:
    """Worst excess of heat flux, load, dynamic pressure (relative; 0 where the vehicle states
    no dynamic-pressure limit) and gamma (rad) over their limits between the nodes."""
    _, Xd, Ud = _dense(problem, X, U)
    outputs = np.array([problem.node_outputs(x, u) for x, u in zip(Xd, Ud)])
    lim = problem.vehicle.limits
    g_lo, g_hi = np.radians(problem.mission.flight_path_bounds_deg)
    return {"heat_flux": float(max(outputs[:, problem.out_q].max() / lim.heat_flux_max - 1.0, 0.0)),
            "load": float(max(outputs[:, problem.out_n].max() / problem.load_max - 1.0, 0.0)),
            "dynamic_pressure": float(max(outputs[:, problem.out_p].max() / lim.dynamic_pressure_max - 1.0, 0.0)),
            "flight_path_rad": float(max((g_lo - Xd[:, 4]).max(), (Xd[:, 4] - g_hi).max(), 0.0))}


def plan_metrics(problem: EntryProblem, X, U, tf: float) -> dict:
    """Paper 001's Table 2/3/6 quantities of a plan: heat load [MJ/m^2] (node quadrature),
    final time [s], max heat flux [kW/m^2], max total load [g], max |gamma_dot| [deg/s] and max
    dynamic pressure [kPa] at the nodes; integrated and max |sigma_dot|, |alpha_dot| and |(sigma_dot, alpha_dot)| [deg, deg/s]
    on the segment polynomials (the bank and alpha histories differentiated, whatever the
    formulation); the planned miss [km]."""
    nodes, _ = problem._nodes(X, U, gradients=False)
    s, Xd, Ud = _dense(problem, X, U)
    t = s * tf
    bank_alpha = [problem.bank_and_alpha(x, u) for x, u in zip(Xd, Ud)]
    sigma = np.unwrap([math.atan2(sn, c) for c, sn, _ in bank_alpha])
    alpha = np.array([float(a) for _, _, a in bank_alpha])
    sigma_dot, alpha_dot = np.gradient(sigma, t), np.gradient(alpha, t)
    norm = np.hypot(sigma_dot, alpha_dot)
    deg = math.degrees
    return {"heat_load_MJ_m2": float(tf * (problem.mesh.weights @ nodes[:, problem.out_q]) / 1e6),
            "final_time_s": tf,
            "max_heat_flux_kW_m2": float(nodes[:, problem.out_q].max() / 1e3),
            "max_load_g": float(nodes[:, problem.out_n].max()),
            "max_flight_path_rate_deg_s": deg(float(np.abs(nodes[:, 4]).max())),
            "max_dynamic_pressure_kPa": float(nodes[:, problem.out_p].max() / 1e3),
            "bank_effort_deg": deg(float(np.trapezoid(np.abs(sigma_dot), t))),
            "max_bank_rate_deg_s": deg(float(np.abs(sigma_dot).max())),
            "alpha_effort_deg": deg(float(np.trapezoid(np.abs(alpha_dot), t))),
            "max_alpha_rate_deg_s": deg(float(np.abs(alpha_dot).max())),
            "control_effort_deg": deg(float(np.trapezoid(norm, t))),
            "max_control_rate_deg_s": deg(float(norm.max())),
            "miss_km": problem.site_miss(X[-1]) / 1e3}


def plan_controls(plan: ScvxPlan, flight: FlightCheck | None, samples_per_segment: int = 32) -> EntryControls:
    """The plan's bank and alpha (planned, or the mission's alpha(V) law at the flown speed) as
    the verifier flies them: from its entry state to its t_f, through the closed loop's bank and
    alpha actuators as ``flight`` says (the vehicle's bank limits, the mission's alpha bounds and
    rate limit) with the closed loop's feedback between re-plans where it has one, or directly
    when ``flight`` is None or has no period."""
    p, v, m = plan.problem, plan.problem.vehicle, plan.problem.mission
    tt, bank, alpha = plan.control_samples(samples_per_segment)
    actuation = None
    if flight is not None and flight.period_s is not None:
        lo, hi = np.radians(m.alpha_bounds_deg)
        actuation = Actuation(period_s=flight.period_s, lead_s=flight.lead_s, bank_limit=v.bank_limit,
                              bank_rate_limit=v.bank_rate_limit, bank_accel_limit=v.bank_accel_limit,
                              alpha_bounds=(float(lo), float(hi)), alpha_rate_limit=math.radians(m.alpha_rate_limit_deg_s),
                              alpha_accel_limit=math.radians(flight.alpha_acceleration_deg_s2),
                              initial_bank=float(plan.bank[0]), initial_alpha=float(plan.alpha[0]))
    maker = None if flight is None or flight.period_s is None else feedback_maker(flight.feedback,
                                                                               flight.feedback_state_weight)
    tracking = None if maker is None else Tracking(plan, maker, flight.feedback_offset_limits)
    return EntryControls(p.vehicle, p.planet, p.atmosphere, plan.states[0, :6].astype(float), plan.final_time,
                         tt, bank, alpha, p.alpha, actuation, tracking)


@dc.dataclass
class PlanFlight:
    """A plan's controls flown by the verifier, and the verdict on that flight.

    Attributes:
      from_plan_m: flown minus planned position at t_f [m] (great circle and altitude, root
        sum square); inf when the flight stopped early.
      from_site_m: flown DRS point to the site [m].
      drs: flown geodetic altitude [m], Mach and vertical speed [m/s] at t_f; drs_ok: inside the
        DRS box (eqs. 64-68: the altitude window, Mach, vertical speed, the site within
        site_radius_m + PROPAGATION_TOLERANCE_M).
      peaks: flown max heat flux [W/m^2] and total load [g] (log samples and integrator steps).
      checks: the path limits (``plan_path_limits``) on the flight; within_limits: all held.
      failure: why the flight stopped before t_f ('' when it reached it).
      trajectory: the flown drake_entry.models.trajectory.Trajectory (with its integrator steps).
    """

    from_plan_m: float
    from_site_m: float
    drs: dict
    drs_ok: bool
    peaks: dict
    checks: list
    within_limits: bool
    failure: str = ""
    trajectory: object = dc.field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """Reached t_f within PROPAGATION_TOLERANCE_M of the plan, inside the DRS box, every path limit held."""
        return (not self.failure and self.from_plan_m <= PROPAGATION_TOLERANCE_M and self.drs_ok
                and self.within_limits)

    @property
    def time(self) -> np.ndarray:
        """Logged times of the flight [s]."""
        return self.trajectory.time

    @property
    def states(self) -> np.ndarray:
        """Logged states (n, 6) of the flight [h, lon, lat, V, gamma, psi] (SI, rad)."""
        return self.trajectory.state

    def violations_text(self) -> str:
        return breaches_text(self.checks)


def flown_check(plan: ScvxPlan, flown: FlownControls) -> PlanFlight:
    """The verdict on a flight of the plan's controls: its terminal point to the plan's, the
    flown DRS point and box, and the path limits at every log sample and integrator step."""
    p, m = plan.problem, plan.problem.mission
    tr = flown.trajectory
    checks = check_limits(tr.flown_time(), tr.flown, plan_path_limits(plan))
    peaks = {"heat_flux_W_m2": float(tr.flown("heat_flux").max()), "total_load_g": float(tr.flown("total_load").max())}
    xf = tr.state[-1]
    drs, inside = drs_point(m, p.planet, xf, float(tr.column("mach")[-1]), m.site_radius_m + PROPAGATION_TOLERANCE_M)
    from_site = drs.pop("site_miss_m")
    from_plan = math.inf if flown.failure else terminal_distance(p.planet, xf, plan.states[-1])
    return PlanFlight(from_plan, float(from_site), drs, bool(inside and not flown.failure), peaks, checks,
                      all(c.held for c in checks), flown.failure, tr)


def drs_point(mission: ScvxMission, planet: Earth, xf, mach: float, site_tolerance_m: float) -> tuple[dict, bool]:
    """The flown DRS point of a final state ``xf`` at Mach ``mach``: (geodetic altitude [m],
    Mach, vertical speed [m/s], site miss [m]) and whether it is inside the DRS box (eqs. 64-68:
    the altitude window, Mach up to final_mach_max plus the mission's flown_mach_margin, vertical
    speed, the site within ``site_tolerance_m``; a vertical speed's upper bound is the plan's
    design aim, not a box criterion)."""
    drs = {"altitude_m": float(planet.atmospheric_altitude(xf[0], xf[2])), "mach": float(mach),
           "vertical_speed_m_s": float(xf[3] * math.sin(xf[4])),
           "site_miss_m": float(planet.great_circle_distance(xf[1], xf[2], *mission.site(planet)))}
    inside = (mission.final_altitude_m[0] <= drs["altitude_m"] <= mission.final_altitude_m[1]
              and drs["mach"] <= mission.final_mach_max + mission.flown_mach_margin
              and drs["vertical_speed_m_s"] >= mission.final_vertical_speed_min_m_s
              and drs["site_miss_m"] <= site_tolerance_m)
    return drs, bool(inside)


def plan_path_limits(plan: ScvxPlan) -> list[PathLimit]:
    """The path limits a flown plan must hold: the vehicle's heat flux, total load (and q where
    finite) and bank limit, and the mission's flight-path bounds (eq. 70)."""
    p = plan.problem
    return vehicle_path_limits(p.vehicle.limits, p.vehicle.bank_limit) + [p.mission.flight_path_limit()]


def terminal_distance(planet: Earth, x, x_plan) -> float:
    """Distance [m] between two terminal points: great circle and altitude, root sum square."""
    return float(math.hypot(planet.great_circle_distance(x[1], x[2], x_plan[1], x_plan[2]), x[0] - x_plan[0]))


def plan_entry(vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission, *,
               problem_settings: EntryProblemSettings | None = None, settings: ScvxSettings | None = None,
               guess: GlideGuess | None = None, initial=None, progress=None,
               flight: FlightCheck = FlightCheck(), verifier: Verifier | None = None) -> ScvxPlan:
    """Plan the mission: the glide guess (unless given), SCvx, the between-node check, then the
    verdict of its controls flown by ``verifier`` (the Drake Simulator,
    drake_entry.diagrams.verification.fly_controls; ``flown_check``): ``success`` only when it
    converged, its controls flown through the closed loop's actuators (``flight``) end within
    PROPAGATION_TOLERANCE_M of its terminal point, inside the DRS box, and every path limit held.

    Args:
      initial: a previous ScvxPlan to start from instead of the guess (a warm start, or a
        polish in another formulation, e.g. a 'lossless' plan refined as 'direct'; its mesh may
        differ, it is interpolated).
      progress: ``progress(k, IterationRecord)`` after every iteration.
      flight: how the controls are flown for the verdict (FlightCheck; re-plans keep it).
      verifier: flies the controls (drake_entry.planning.verification; re-plans keep it).
    """
    fly = require_verifier(verifier, "plan_entry")
    t0 = time.perf_counter()
    ps = problem_settings or EntryProblemSettings()
    if initial is None and guess is None:
        guess = glide_guess(vehicle, planet, atmosphere, mission)
    tf0 = initial.final_time if initial is not None else guess.final_time
    problem = EntryProblem(vehicle, planet, atmosphere, mission, ps, tf0)
    if initial is not None:
        ref = initial.evaluate(problem.mesh.s * tf0)
        lossless = np.stack([ref["u1"], ref["u2"]], axis=1) if "u1" in ref else None
        z0 = decision_from_trajectory(problem, np.stack([ref[k] for k in STATE_NAMES], axis=1), ref["bank"],
                                      ref["alpha"], tf0, lossless)
    else:
        z0 = initial_decision(problem, guess)
    build = time.perf_counter() - t0
    outcome = solve_scvx(problem, z0, settings, progress=progress)
    X, U, tf = problem.unpack(outcome.z)
    bank_alpha = [problem.bank_and_alpha(x, u) for x, u in zip(X, U)]
    bank = np.array([math.atan2(s, c) for c, s, _ in bank_alpha])
    alpha = np.array([float(a) for _, _, a in bank_alpha])
    norm_u = np.array([math.hypot(c, s) for c, s, _ in bank_alpha])
    lift = np.array([flight_conditions(x[:6], 0.0, a, vehicle, planet, atmosphere).lift for x, a in zip(X, alpha)])
    acting = lift >= GAP_LIFT_FRACTION * planet.g0
    gap = float(np.max(1.0 - norm_u[acting], initial=0.0))
    metrics = plan_metrics(problem, X, U, tf)
    between = _between_nodes(problem, X, U)
    xf = X[-1]
    final = problem.node_outputs(xf, U[-1])
    ev = outcome.evaluation
    tol_q, tol_n, tol_p, tol_g = BETWEEN_NODE_TOLERANCE
    checked = (between["heat_flux"] <= tol_q and between["load"] <= tol_n and between["dynamic_pressure"] <= tol_p
               and between["flight_path_rad"] <= tol_g)
    message = outcome.message
    if outcome.converged and not checked:
        message += (f"; converged but violated between the nodes (heat flux +{between['heat_flux']:.1%}, "
                    f"{problem.load_kind} load +{between['load']:.1%}, dynamic pressure "
                    f"+{between['dynamic_pressure']:.1%}, gamma {math.degrees(between['flight_path_rad']):.2f} deg): "
                    f"refine the mesh")
    plan = ScvxPlan(
        success=False, message=message, iterations=outcome.iterations, build_time=build,
        objective=metrics[OBJECTIVE_METRIC[ps.objective]], formulation=ps.formulation,
        time=problem.mesh.s * tf, states=X, controls=U, final_time=tf, bank=bank, alpha=alpha,
        heat_load=metrics["heat_load_MJ_m2"] * 1e6, lossless_gap=gap,
        lossless_gap_all=float(np.max(1.0 - norm_u)), max_defect=max_defect(ev),
        max_violation=max_violation(ev), between_nodes=between, miss_m=problem.site_miss(xf),
        drs={"altitude_m": float(final[problem.out_h]), "mach": float(xf[3] / final[problem.out_a]),
             "vertical_speed_m_s": float(xf[3] * math.sin(xf[4]))},
        metrics=metrics, guess=guess, history=outcome.history, problem=problem)
    plan.flight, plan.verifier = flight, fly
    plan.flown = flown = flown_check(plan, fly(plan_controls(plan, flight)))
    if flown.failure:
        why = f"its controls flown stop before t_f: {flown.failure}"
    else:
        d = flown.drs
        problems = []
        if plan.propagated_error_m > PROPAGATION_TOLERANCE_M:
            problems.append(f"end {plan.propagated_error_m / 1e3:.1f} km from its terminal point "
                            f"(> {PROPAGATION_TOLERANCE_M / 1e3:g} km; "
                            + (f"lossless gap {gap:.2f}: polish it with the 'direct' formulation)" if gap > 1e-2
                               else "refine the mesh)"))
        if not flown.drs_ok:
            problems.append(f"end outside the DRS box (geodetic altitude {d['altitude_m'] / 1e3:.2f} km of "
                            f"{mission.final_altitude_m[0] / 1e3:g}-{mission.final_altitude_m[1] / 1e3:g} km, "
                            f"Mach {d['mach']:.2f}, vertical speed {d['vertical_speed_m_s']:.1f} m/s, "
                            f"{flown.from_site_m / 1e3:.1f} km from the site)")
        if not flown.within_limits:
            problems.append("breach " + flown.violations_text())
        why = "its controls flown " + " and ".join(problems)
    if outcome.converged and not flown.ok:
        plan.message += f"; converged but {why}"
    plan.success = outcome.converged and checked and flown.ok
    plan.solve_time = time.perf_counter() - t0 - build
    return plan


#: ScvxMission fields a re-plan takes from the state flown (the rest stay the mission's)
_ENTRY_FIELDS = ("entry_altitude_m", "entry_longitude_deg", "entry_latitude_deg", "entry_speed_m_s",
                 "entry_flight_path_deg", "entry_heading_deg", "site_longitude_deg", "site_latitude_deg",
                 "entry_bank_deg", "entry_alpha_deg")


def equivalent_heading(psi: float, bounds) -> float:
    """``psi`` [rad] or the same direction a whole turn away, whichever lies in ``bounds`` [rad]
    (a glide's heading drifts past a bound measured from the entry heading; as a direction it
    may still be inside); ``psi`` itself when none does."""
    for turn in (0.0, -2.0 * math.pi, 2.0 * math.pi):
        if bounds[0] <= psi + turn <= bounds[1]:
            return float(psi + turn)
    return float(psi)


def replan_from(previous: ScvxPlan, x, elapsed: float, bank: float, alpha: float, scales=None, *,
                settings: ScvxSettings | None = None) -> ScvxPlan:
    """Re-plan ``previous``'s mission from state ``x`` [h, lon, lat, V, gamma, psi] reached
    ``elapsed`` [s] into it, holding the bank and alpha being flown [rad] where they are
    states (the rate formulations): the same site, DRS box, limits, formulation and mesh,
    warm-started from the rest of the previous plan (its states and bank from ``elapsed`` to
    its t_f, the state at ``elapsed`` replaced by ``x``; the remaining time its t_f guess). A state outside the mission's bounds (e.g. gamma above
    0.5 deg in a dispersed skip) is clipped into them for the new entry point, and a heading past
    its bounds taken a whole turn away when that is inside (``equivalent_heading``). With ``scales`` =
    (k_L, k_D), the lift and drag ratios the flight has shown, the plan predicts (and is verified)
    with the nominal coefficients times them (models.acceleration_ratios.sensed_vehicle)."""
    p = previous.problem
    m = p.mission
    x = np.array(x, float)
    x[4] = np.clip(x[4], *np.radians(m.flight_path_bounds_deg))
    x[5] = equivalent_heading(x[5], np.radians(m.heading_bounds_deg))
    fields = {k: v for k, v in dc.asdict(m).items() if k not in _ENTRY_FIELDS}
    f = p.formulation
    if f.bank == "rate":
        fields["entry_bank_deg"] = float(np.clip(math.degrees(bank), -180.0, 180.0))
    if f.alpha == "rate":
        fields["entry_alpha_deg"] = float(np.clip(math.degrees(alpha), *m.alpha_bounds_deg))
    mission = ScvxMission.from_geocentric(p.planet, x, p.site_lon, p.site_lat, **fields)
    rest = np.linspace(min(elapsed, previous.final_time), previous.final_time, 200)
    ref = previous.evaluate(rest)
    states = np.stack([ref[k] for k in STATE_NAMES], axis=1)
    states[0] = x
    guess = GlideGuess(rest - rest[0], states, ref["bank"], math.nan, math.nan, True, alpha=ref["alpha"])
    if guess.final_time <= 0.0:
        raise ValueError(f"the previous plan has no time left at {elapsed:.1f} s (t_f {previous.final_time:.1f} s)")
    vehicle = p.vehicle if scales is None else sensed_vehicle(p.vehicle, scales)
    return plan_entry(vehicle, p.planet, p.atmosphere, mission, problem_settings=p.settings,
                      settings=settings, guess=guess, flight=previous.flight or FlightCheck(),
                      verifier=previous.verifier)
