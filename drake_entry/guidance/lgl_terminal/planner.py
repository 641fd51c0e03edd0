"""Plans of paper 002's terminal guidance: an LGL solution of the scenario's problem, verified as
the closed loop flies it.

    plan = plan_terminal(scenario, verifier)            # before flight (the spec's nodes)
    again = replan(plan, x_nav, elapsed, bank, alpha)   # in flight: the horizon that remains

A plan is a success only when (1) the NLP solution is verified (drake_entry.planning.nlp.verify:
the dynamics between the nodes and its controls flown on the problem's own dynamics) and (2) its
bank and angle of attack, flown by the Drake Simulator through the closed loop's actuators (the
guidance period, the command lead, the vehicle's bank limits, the problem's alpha bounds and
rate bound), end inside the scenario's acceptance box at the plan's t_f and hold every path
limit of the closed loop's verdict (``PlanFlight``).
"""
from __future__ import annotations

import dataclasses as dc
import functools
import math

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.models.acceleration_ratios import sensed_limit_factors, sensed_vehicle
from drake_entry.models.verdict import box_text, breaches_text, check_limits
from drake_entry.planning.neighbouring_optimal import neighbouring_optimal, without_odd_even_mode
from drake_entry.planning.pseudospectral import segment_compatible
from drake_entry.planning.tracking import CommandFeedback, TrackingWeights, tvlqr
from drake_entry.planning.verification import Actuation, EntryControls, Tracking, require_verifier

__all__ = ["SAMPLES_PER_S", "PlanFlight", "LglPlan", "feedback_weights", "feedback_maker", "actuation", "fly_plan",
           "interface_crossing", "sensed_path", "measured_path", "MEASURED_MARGIN_FRACTION",
           "judged", "plan_terminal", "replan_nodes", "final_windows", "replan"]

#: command samples per second of a plan (linear interpolation between them by the guidance)
SAMPLES_PER_S = 4.0
#: a re-solve whose measured state passes a planned path bound plans it this fraction of the way
#: from the planned bound to the vehicle's limit (measured_path). At 1 (the limit itself) the
#: plans left no room for the actuators: 3, 2 and 2 re-solves of paper 004's CAV-H draws 12 and
#: 30 and HORUS-2B's draw 3 (seed 2026) were refused for 0.01-0.6 % over a limit flown through
#: them; at 0.5 none was, the flights ending 37, 24 and 37 m from the target
MEASURED_MARGIN_FRACTION = 0.5


@dc.dataclass
class PlanFlight:
    """A plan's bank and alpha flown through the closed loop's actuators, and the verdict.

    Attributes:
      box: the scenario's acceptance box where the closed loop would stop: the flight's first
        descent through the terminal altitude, else the plan's t_f; checks: the closed loop's path
        limits on the flight (every log sample and integrator step); failure: why it stopped
        early; interface_early_s: how long [s] before the plan's t_f the flight met the terminal
        altitude (0 when it met it at t_f or not before).
    """

    box: dict
    checks: list
    failure: str = ""
    trajectory: object = dc.field(default=None, repr=False)
    interface_early_s: float = 0.0

    @property
    def ok(self) -> bool:
        return not self.failure and all(b["inside"] for b in self.box.values()) and all(c.held for c in self.checks)

    def text(self) -> str:
        if self.failure:
            return f"flown through the actuators it stopped early: {self.failure}"
        parts = [f"{k} {box_text(k, b)}" for k, b in self.box.items() if not b["inside"]]
        if parts and self.interface_early_s > 0:
            parts.insert(0, f"it meets the terminal altitude {self.interface_early_s:.1f} s before the plan's end, "
                            f"where the closed loop stops")
        if not all(c.held for c in self.checks):
            parts.append(f"path limits breached: {breaches_text(self.checks)}")
        return ("flown through the actuators: " + "; ".join(parts)) if parts else \
            "flown through the actuators: inside the acceptance box, every path limit held"


@dc.dataclass
class LglPlan:
    """One LGL solution as the guidance flies it.

    Attributes:
      result: the NlpResult (its clock: t = 0 where this plan begins).
      flight: the PlanFlight; success: result.success and flight.ok; message: both in words.
      scenario, verifier: what re-plans need.
      feedback_errors: why a feedback law of this solution could not be made (``feedback``).
    """

    result: object
    flight: PlanFlight | None
    success: bool
    message: str
    scenario: object = dc.field(repr=False, default=None)
    verifier: object = dc.field(repr=False, default=None)
    feedback_errors: list = dc.field(default_factory=list)
    _feedback_laws: dict = dc.field(repr=False, default_factory=dict)

    @property
    def final_time(self) -> float:
        return self.result.final_time

    def control_samples(self):
        """(t [s], bank [rad], alpha [rad]) sampled at SAMPLES_PER_S from the solution's states
        (computed once: the actuator flight, the closed loop's wiring and the guidance read them)."""
        return self._samples

    def feedback(self, kind: str) -> CommandFeedback | None:
        """The feedback law about this solution, its bank and alpha offsets driven by their rate
        controls: kind "tvlqr" (planning.tracking, ``feedback_weights``) or "costate" (the
        neighbouring-optimal law of its costates, without their odd-even mode,
        planning.neighbouring_optimal, with the same terminal penalty). Computed once per kind; None when it cannot be made (the reason in
        ``feedback_errors``: the plan then flies without feedback)."""
        if kind not in self._feedback_laws:
            self._feedback_laws[kind] = None
            try:
                self._feedback_laws[kind] = self._make_feedback(kind)
            except ScenarioError as e:
                self.feedback_errors.append(f"{kind}: {e}")
        return self._feedback_laws[kind]

    def _make_feedback(self, kind: str) -> CommandFeedback:
        t = self.control_samples()[0]
        r = self.result
        problem, weights = r.problem, feedback_weights(self.scenario.guidance)
        X, U, samples = r.state_function()(t), r.control_function()(t), max(40, int(math.ceil(r.final_time / 5.0)))
        if kind == "costate":
            if r.costates is None:
                raise ScenarioError("the solution carries no costates (the solver returned no multipliers)")
            law = neighbouring_optimal(problem, t, X, U, r.costate_time, without_odd_even_mode(r.costates), weights,
                                       samples=samples)
        else:
            law = tvlqr(problem, t, X, U, weights, samples=samples)
        names, controls = list(problem.state_names), list(problem.control_names)
        return CommandFeedback(law, ((names.index("sigma"), controls.index("u_sigma")),
                                     (names.index("alpha"), controls.index("u_alpha"))))

    @functools.cached_property
    def _samples(self):
        tf = self.final_time
        t = np.linspace(0.0, tf, max(int(tf * SAMPLES_PER_S) + 1, 3))
        X = self.result.state_function()(t)
        names = list(self.result.problem.state_names)
        return t, X[:, names.index("sigma")], X[:, names.index("alpha")]


def feedback_weights(spec) -> TrackingWeights:
    """The LQR weights of the feedback between re-solves (planning.tracking,
    ``TrackingWeights.entry_commands``) at the spec's ``feedback_state_weight``."""
    return TrackingWeights.entry_commands(spec.feedback_state_weight)


def feedback_maker(kind: str):
    """What ReplanningGuidance calls on each plan it flies: the plan's feedback law of ``kind``
    ("tvlqr" or "costate"; ``LglPlan.feedback``), or None for kind "none"."""
    return None if kind == "none" else lambda plan: plan.feedback(kind)


def actuation(problem, spec, initial_bank: float, initial_alpha: float) -> Actuation:
    """The closed loop's actuators for a plan of ``problem``: the vehicle's bank limits, the
    problem's alpha bounds and alpha-rate bound (eq. 17), the spec's period, lead and alpha
    acceleration limit."""
    v = problem.vehicle
    lo, hi = problem.state_bounds["alpha"]
    rate = max(abs(r) for r in problem.control_bounds["u_alpha"])
    return Actuation(period_s=spec.period_s, lead_s=spec.command_lead_s, bank_limit=v.bank_limit,
                     bank_rate_limit=v.bank_rate_limit, bank_accel_limit=v.bank_accel_limit,
                     alpha_bounds=(float(lo), float(hi)), alpha_rate_limit=float(rate),
                     alpha_accel_limit=math.radians(spec.alpha_accel_limit_deg_s2),
                     initial_bank=float(initial_bank), initial_alpha=float(initial_alpha))


def fly_plan(plan: LglPlan, scenario, verifier) -> PlanFlight:
    """Fly the plan's bank and alpha from its first node through the closed loop's actuators, with
    the feedback the closed loop flies between re-solves (the spec's ``feedback``), and judge the
    flight as the closed loop's verdict would (acceptance box at t_f, path limits)."""
    r, spec = plan.result, scenario.guidance
    t, bank, alpha = plan.control_samples()
    x0 = r.states[0]
    maker = feedback_maker(spec.feedback)
    tracking = None if maker is None else Tracking(plan, maker, spec.feedback_offset_limits())
    controls = EntryControls(r.problem.vehicle, r.problem.planet, r.problem.atmosphere, x0[:6].astype(float),
                             r.final_time, t, bank, alpha, None, actuation(r.problem, spec, bank[0], alpha[0]),
                             tracking)
    flown = verifier(controls)
    tr = flown.trajectory
    planet = r.problem.planet
    stop_altitude = (planet.atmospheric_altitude(tr.state[:, 0], tr.state[:, 2])
                     if scenario.altitude_datum == "ellipsoid" else None)  # as the closed loop's stop reads it
    xf, mach, alpha, t_stop = interface_crossing(tr, spec.terminal_altitude_km * 1e3, stop_altitude)
    distance = planet.great_circle_distance(xf[1], xf[2], math.radians(scenario.target.longitude_deg),
                                            math.radians(scenario.target.latitude_deg))
    box = scenario.acceptance_box(planet, xf, mach=mach, distance_m=float(distance), alpha_rad=alpha)
    checks = check_limits(tr.flown_time(), tr.flown, scenario.path_limits(r.problem.vehicle))
    return PlanFlight(box, checks, flown.failure, tr, interface_early_s=max(0.0, float(tr.time[-1]) - t_stop))


def interface_crossing(tr, h_stop: float, altitude=None) -> tuple[np.ndarray, float, float, float]:
    """(state [6], Mach, alpha [rad], t [s]) where the flight ``tr`` first descends through
    ``h_stop`` [m], interpolated linearly between its samples, as the closed loop's termination
    monitor stops it there; its last sample when it never does before its end. ``altitude``:
    the altitude the stop reads at each sample [m] (geodetic), default the state altitude."""
    h, t = (tr.state[:, 0] if altitude is None else np.asarray(altitude, float)), tr.time
    below = np.nonzero(h[1:] <= h_stop)[0]
    if below.size == 0 or below[0] + 1 == len(t) - 1:
        return tr.state[-1], float(tr.column("mach")[-1]), float(tr.column("alpha")[-1]), float(t[-1])
    i = int(below[0]) + 1  # first sample at or below; i - 1 above (h[0] is the plan's start)
    w = 0.0 if h[i - 1] == h[i] else (h[i - 1] - h_stop) / (h[i - 1] - h[i])

    def at(values):
        return (1.0 - w) * np.asarray(values[i - 1], float) + w * np.asarray(values[i], float)

    return at(tr.state), float(at(tr.column("mach"))), float(at(tr.column("alpha"))), float(at(t))


def judged(result, scenario, verifier) -> LglPlan:
    """An LglPlan of an NlpResult: flown through the actuators only when the NLP solution is
    verified (an unverified one is not flown)."""
    plan = LglPlan(result, None, False, result.message, scenario, verifier)
    if not result.success:
        return plan
    plan.flight = fly_plan(plan, scenario, verifier)
    plan.success = plan.flight.ok
    plan.message = f"{result.message}; {plan.flight.text()}"
    return plan


def plan_terminal(scenario, verifier, *, progress="auto") -> LglPlan:
    """The pre-flight plan: the scenario's problem on the spec's nodes from the built-in propagated
    guess, verified (module docstring). A mission's problem is solved first without its
    interface floor; only when that plan's flight meets the terminal altitude before its end is
    it solved again with the floor, from that solution. From the propagated guess SNOPT meets the
    floor slowly even where it is never active: the capsule's plan (80 nodes) took 687 s with it
    and 109 s without it, paper 004's CAV-H 33 s and 21 s (each verified inside its box).

    When the spec's segments do not converge, the problem is solved again on one polynomial of
    the same nodes (paper 002's form), which the re-solves then keep: the capsule's plan at 18.25
    km in 4 segments of 81 nodes met SNOPT's iteration limit (3000, info 32); on one polynomial it
    converged and verified, and draws 0-2 of seed 2026 ended 1.2, 133 and 10 m from the target.

    With the spec's ``refine_mesh`` the mesh is refined (nlp.solve's ``refine``: more nodes in the
    same segments, each solve from the last) while the dynamics between the nodes miss their
    tolerance: SHEFEX-3's steep dive (-10 deg at 81 km, 4.7 km/s) on 81 nodes in 4 segments
    converged with 0.0023 between the nodes against 0.001 in the pull-out; refined to 125 nodes,
    0.00021, it is verified."""
    spec = scenario.guidance
    verifier = require_verifier(verifier, "the terminal guidance's plan")
    problem = spec.problem_for(scenario)
    settings = dict(nodes=spec.nodes, solver=spec.solver, tolerance=spec.tolerance,
                    max_iterations=spec.max_iterations, verifier=verifier, progress=progress, refine=spec.refine_mesh,
                    solver_options=spec.solver_options())
    plan = _staged(problem, scenario, verifier, dict(settings, segments=spec.segments))
    if spec.segments > 1 and not plan.result.converged:
        plan = _staged(problem, scenario, verifier, dict(settings, segments=1))
    return plan


def _staged(problem, scenario, verifier, settings: dict) -> LglPlan:
    """``problem`` solved without its interface floor, then with it when needed (plan_terminal)."""
    from drake_entry.guidance.lgl_terminal.mission import without_interface_floor
    from drake_entry.planning import nlp

    relaxed = without_interface_floor(problem)
    plan = judged(nlp.solve(relaxed, **settings), scenario, verifier)
    if relaxed is problem or plan.success or plan.flight is None or not plan.flight.interface_early_s > 0.0:
        return plan
    return judged(nlp.solve(problem, guess=plan.result, **settings), scenario, verifier)


def replan_nodes(spec, horizon_s: float) -> int:
    """Nodes of a re-solve: one per replan_node_spacing_s of the horizon, within replan_nodes,
    rounded up to a count the spec's segments share."""
    lo, hi = spec.replan_nodes
    return segment_compatible(int(np.clip(math.ceil(horizon_s / spec.replan_node_spacing_s) + 1, lo, hi)),
                              spec.segments)


def final_windows(problem, spec):
    """``problem`` with a fixed final speed and flight-path angle opened to windows of the spec's
    half-widths about them (a window already open stays as it is)."""
    final = dict(problem.final)
    for name, half in (("V", spec.replan_speed_window_m_s), ("gamma", math.radians(spec.replan_flight_path_window_deg))):
        v = final.get(name)
        if isinstance(v, (int, float)) and half > 0:
            final[name] = (float(v) - half, float(v) + half)
    return dc.replace(problem, final=final)


def sensed_path(path, scales) -> list:
    """The path constraints ``path`` with their q and heat-rate maxima held in the air the sensed
    ratios ``scales`` = (k_L, k_D) imply (models.acceleration_ratios.sensed_limit_factors): the
    problem computes both with the nominal density."""
    divisors = sensed_limit_factors(scales)
    return [dc.replace(c, max=c.max / divisors[c.quantity]) if isinstance(c.quantity, str) and c.quantity in divisors
            else c for c in path]


def measured_path(planned, limits, values) -> list:
    """The path constraints of a re-solve from a measured state: ``planned`` (with the spec's
    margin) as they are, except a bound the state already passes (``values``: the constraints'
    values there), which is planned MEASURED_MARGIN_FRACTION of the way from the planned bound to
    the vehicle's own (``limits``: the same constraints without the margin) or, past that too, at
    the value itself. The state at a re-solve's first node is fixed: a bound it passes cannot be
    met there, and SNOPT stops infeasible (HORUS-2B, draw 0 of seed 2026: 5 of 14 re-solves, each
    at the first node's heat rate, q or load)."""
    f = MEASURED_MARGIN_FRACTION
    out = []
    for c, lim, v in zip(planned, limits, values):
        lo, hi = c.min, c.max
        if math.isfinite(hi) and v > hi:
            hi = max(c.max + f * (lim.max - c.max), float(v))
        if math.isfinite(lo) and v < lo:
            lo = min(c.min + f * (lim.min - c.min), float(v))
        out.append(c if (lo, hi) == (c.min, c.max) else dc.replace(c, min=lo, max=hi))
    return out


def replan(previous: LglPlan, x, elapsed: float, bank: float, alpha: float, scales=None) -> LglPlan:
    """Re-solve from the navigation state ``x`` [h, lon, lat, V, gamma, psi] reached ``elapsed`` [s]
    into ``previous``, with the bank and alpha being commanded [rad] as the initial alpha and
    sigma states (clipped into their bounds), on the horizon that remains, warm-started from
    ``previous`` (shrinking_horizon.resolve_from), aiming at the final speed and flight-path
    angle within the spec's re-solve windows (``final_windows``), with the nominal lift and drag
    times ``scales`` = (k_L, k_D) when given (the sensed/modelled ratios) and the q and heat-rate
    bounds held in the air they imply (``sensed_path``), a bound the measured state already passes
    planned halfway to the vehicle's own (``measured_path``); judged, with the same models, as the
    pre-flight plan is. The path bounds are the pre-flight problem's each time (a re-solve's
    own, already held in the air of its time, are not carried on)."""
    from drake_entry.guidance.lgl_terminal.mission import inside_bounds, problem_for_scenario
    from drake_entry.planning.nlp.shrinking_horizon import resolve_from

    r, scenario = previous.result, previous.scenario
    spec = scenario.guidance
    names = list(r.problem.state_names)
    x_now = np.zeros(len(names))
    x_now[:6] = x
    lo, hi = r.problem.state_bounds["alpha"]
    x_now[names.index("alpha")] = float(np.clip(alpha, lo, hi))
    x_now[names.index("sigma")] = float(bank)
    problem = final_windows(r.problem, spec)
    limits = problem_for_scenario(spec, scenario, margin=False).path
    planned = [inside_bounds(c, spec.path_margin) for c in limits]  # as spec.problem_for plans them
    if scales is not None:
        planned, limits = sensed_path(planned, scales), sensed_path(limits, scales)
        problem = dc.replace(problem, vehicle=sensed_vehicle(scenario.make_vehicle(), scales))
    values = dc.replace(problem, path=planned).path_values(x_now, np.zeros(len(problem.control_names)))
    problem = dc.replace(problem, path=measured_path(planned, limits, values))
    again = resolve_from(r, x_now, elapsed, problem=problem, nodes=replan_nodes(spec, r.final_time - elapsed), solver=spec.solver,
                         tolerance=spec.replan_tolerance, max_iterations=spec.max_iterations,
                         solver_options=spec.solver_options(), verifier=previous.verifier, progress=False)
    return judged(again, scenario, previous.verifier)
