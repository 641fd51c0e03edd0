"""Paper 001's direct problem posed for the NLP path: the same mission as an
``OptimalControlProblem`` (planning/ocp.py) that ``planning.nlp.solve`` transcribes with LGL or
Drake's DirectCollocation and solves with Ipopt or SNOPT — the independent check of an SCvx
plan's optimality (the two heat loads agree within 1 %: docs/methods/scvx.md).

Same models and limits as the SCvx entry problem in its direct formulation (eqs. 34-36,
54-55): states [h, lon, lat, V, gamma, psi, alpha, sigma], controls their rates within the
mission's and vehicle's rate limits, alpha and bank within their bounds, heat flux and total
load at most the vehicle's limits and gamma within eq. 70's bounds along the path, and at the
final node the DRS box: geodetic altitude window narrowed by the margin (eq. 64), Mach (eq. 64),
vertical speed (eq. 65) and the site cone measured as the SCvx planner measures it (eq. 69).
"""
from __future__ import annotations

import math

import numpy as np

from drake_entry.errors import ScenarioError
from drake_entry.guidance.scvx.decision import initial_decision
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.models.atmosphere import Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import Vehicle
from drake_entry.planning.ocp import ObjectiveTerm, OptimalControlProblem, PathConstraint

__all__ = ["NLP_OBJECTIVES", "mission_problem", "nlp_guess", "nlp_form"]

#: OptimalControlProblem objective kind of each SCvx objective the NLP path can pose
NLP_OBJECTIVES = {"heat_load": "heat_load", "time": "final_time"}


def mission_problem(vehicle: Vehicle, planet: Earth, atmosphere: Atmosphere, mission: ScvxMission, *,
                    final_time: tuple, objective: str = "heat_load") -> OptimalControlProblem:
    """The SCvx direct problem of ``mission`` as an OptimalControlProblem; ``final_time`` the
    (min, max) bounds of the free final time [s]."""
    if objective not in NLP_OBJECTIVES:
        raise ScenarioError(f"mission_problem objective = '{objective}' has no NLP form here; allowed: "
                            f"{', '.join(NLP_OBJECTIVES)}")
    deg = math.radians
    x0 = mission.entry_state(planet)
    site_lon, site_lat = mission.site(planet)
    cos_site = math.cos(site_lat)
    R = planet.reference_radius
    limits = vehicle.limits
    h_lo, h_hi = mission.drs_altitude_window("rate")

    def geodetic_altitude(x, u, env):
        return planet.atmospheric_altitude(x[0], x[2])

    def vertical_speed(x, u, env):
        return x[3] * np.sin(x[4])

    def site_miss_squared(x, u, env):  # (miss / R)^2 as EntryProblem.site_miss measures it
        return (cos_site * (x[1] - site_lon)) ** 2 + (x[2] - site_lat) ** 2

    return OptimalControlProblem(
        vehicle=vehicle, planet=planet, atmosphere=atmosphere,
        initial={name: float(v) for name, v in zip(("h", "lon", "lat", "V", "gamma", "psi"), x0)},
        final={}, final_time=tuple(float(t) for t in final_time),
        objective=[ObjectiveTerm(NLP_OBJECTIVES[objective])], controls="rates",
        state_bounds={"gamma": tuple(deg(b) for b in mission.flight_path_bounds_deg),
                      "psi": tuple(deg(b) for b in mission.heading_bounds_deg),
                      "alpha": tuple(deg(b) for b in mission.alpha_bounds_deg),
                      "sigma": (-vehicle.bank_limit, vehicle.bank_limit)},
        control_bounds={"u_alpha": (-deg(mission.alpha_rate_limit_deg_s), deg(mission.alpha_rate_limit_deg_s)),
                        "u_sigma": (-vehicle.bank_rate_limit, vehicle.bank_rate_limit)},
        path=[PathConstraint("heat_flux", max=limits.heat_flux_max),
              PathConstraint("total_load", max=limits.total_load_max) if math.isfinite(limits.total_load_max)
              else PathConstraint("normal_load", max=limits.normal_load_max)],
        terminal=[PathConstraint(geodetic_altitude, h_lo, h_hi, scale=1e3, name="DRS geodetic altitude"),
                  PathConstraint("mach", min=mission.final_mach_min if mission.final_mach_min > 0 else -math.inf,
                                 max=mission.final_mach_max,
                                 name="DRS Mach"),
                  PathConstraint(vertical_speed, min=mission.final_vertical_speed_min_m_s, scale=100.0,
                                 name="DRS vertical speed"),
                  PathConstraint(site_miss_squared, max=(mission.site_radius_m / R) ** 2, name="DRS site cone")],
        name=f"{mission.name} (NLP form)")


def nlp_guess(problem, z) -> tuple:
    """(t [s], states, controls) of the SCvx direct problem's decision z (a plan's, or
    ``decision.initial_decision`` of its glide guess) in the OptimalControlProblem's order
    ([h, lon, lat, V, gamma, psi, alpha, sigma], [u_alpha, u_sigma])."""
    if problem.i_sigma is None or problem.i_alpha is None:
        raise ScenarioError(f"nlp_guess needs the bank and alpha as states (the 'direct' formulation), "
                         f"got '{problem.settings.formulation}'")
    X, U, tf = problem.unpack(z)
    rate = {state: control for control, state in problem.rate_controls}
    states = np.column_stack([X[:, :6], X[:, problem.i_alpha], X[:, problem.i_sigma]])
    controls = np.column_stack([U[:, rate[problem.i_alpha]], U[:, rate[problem.i_sigma]]])
    return problem.mesh.s * tf, states, controls


def nlp_form(plan) -> tuple:
    """(OptimalControlProblem, guess) of an SCvx direct plan for ``nlp.solve``: its mission and
    models with its problem's final-time bounds, started from the glide guess the plan started
    from (``plan.guess``), so the two methods solve the same problem from the same point."""

    p = plan.problem
    if plan.guess is None:
        raise ScenarioError("nlp_form needs a plan started from a glide guess (plan.guess is None: "
                            "it was warm-started from another plan)")
    i = p.i_tf
    problem = mission_problem(p.vehicle, p.planet, p.atmosphere, p.mission,
                              final_time=(p.lower[i] * p.scale[i], p.upper[i] * p.scale[i]))
    return problem, nlp_guess(p, initial_decision(p, plan.guess))
