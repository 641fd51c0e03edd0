"""Feedback between re-plans for an SCvx plan: the time-varying LQR (planning.tracking) about
the plan, its dynamics linearised on the plan's mission posed as the direct-form
OptimalControlProblem (as_ocp: states [h, lon, lat, V, gamma, psi, alpha, sigma], controls
their rates). Not in paper 001, which re-plans only: on a 1500-s glide the open-loop plan drifts
from itself by 5-37 km through the actuators' lag alone (docs/methods/scvx.md), and the bank and
alpha offsets this law builds up between re-plans hold the flight on the plan.

Where alpha follows the mission's alpha(V) law (formulations 'direct_bank', 'lossless') the law
sees alpha as a state along the plan's alpha(V(t)), and its alpha offset is added to the law.
"""
from __future__ import annotations

import math

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.as_ocp import mission_problem
from drake_entry.planning.tracking import CommandFeedback, TrackingWeights, tvlqr

__all__ = ["LINEARISATION_SPACING_S", "plan_feedback", "feedback_maker"]

#: the plan's dynamics are linearised every this [s] (at least 40 times)
LINEARISATION_SPACING_S = 5.0


def plan_feedback(plan, state_weight: float) -> CommandFeedback:
    """The TVLQR law about ``plan`` (an ScvxPlan) with TrackingWeights.entry_commands at
    ``state_weight``; computed once per plan and weight (kept on the plan)."""
    key = ("tvlqr", float(state_weight))
    if key not in plan.feedback_laws:
        p = plan.problem
        problem = mission_problem(p.vehicle, p.planet, p.atmosphere, p.mission,
                                  final_time=(0.5 * plan.final_time, 1.5 * plan.final_time))
        t, bank, alpha = plan.control_samples()
        ref = plan.evaluate(t)
        if alpha is None:
            alpha = ref["alpha"]
        states = np.column_stack([*(ref[k] for k in ("h", "lon", "lat", "V", "gamma", "psi")), alpha, bank])
        controls = np.column_stack([np.gradient(alpha, t), np.gradient(bank, t)])
        names, control_names = list(problem.state_names), list(problem.control_names)
        if [names[6], names[7], control_names] != ["alpha", "sigma", ["u_alpha", "u_sigma"]]:
            raise ScenarioError(f"the SCvx mission's direct form has states {names} and controls {control_names}; "
                                f"the feedback needs [..., alpha, sigma] and [u_alpha, u_sigma]")
        law = tvlqr(problem, t, states, controls, TrackingWeights.entry_commands(state_weight),
                    samples=max(40, int(math.ceil(plan.final_time / LINEARISATION_SPACING_S))))
        plan.feedback_laws[key] = CommandFeedback(law, ((names.index("sigma"), control_names.index("u_sigma")),
                                                        (names.index("alpha"), control_names.index("u_alpha"))))
    return plan.feedback_laws[key]


def feedback_maker(kind: str, state_weight: float):
    """What ReplanningGuidance and the verifier call on each plan they fly: its TVLQR law
    (kind "tvlqr"), or None for kind "none"."""
    if kind == "none":
        return None
    if kind != "tvlqr":
        raise ScenarioError(f"SCvx feedback = '{kind}' is unknown; allowed: tvlqr, none")
    return lambda plan: plan_feedback(plan, state_weight)
