"""The LGL terminal guidance's settings from a mission (drake_entry.guidance.derivation).

Paper 002 solves its own impact problem; on another mission the guidance solves the problem
that mission poses (``problem: mission``, guidance.lgl_terminal.mission.mission_problem): from
the entry state to the centre of the acceptance box over the target, at the box's speed (its
flight-path angle and alpha where the box gives them), alpha within the mission's alpha
schedule's range, inside the vehicle's limits. The terminal altitude is searched inside the
box on the nominal flight and a few dispersed draws."""

from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    FINAL_DESCENT_DEG,
    FORCE_SIGMAS,
    Q_SPEED_FRACTION,
    Choice,
    Derivation,
    SearchStep,
    alpha_actuator,
    interface_speeds,
    mission_alpha,
    terminal_interface,
)
from drake_entry.guidance.lgl_terminal.mission import MISSION
from drake_entry.guidance.lgl_terminal.spec import LglTerminal
from drake_entry.models.dispersions import force_ratio_high

__all__ = ["derive", "ALPHA_WIDEN_DEG", "ALPHA_RATE_DEG_S", "NODES", "SEGMENTS"]

#: a constant mission alpha is flown within this much either side [deg] (alpha is a state of
#: the problem and needs a range)
ALPHA_WIDEN_DEG = 1.0
#: alpha's rate bound [deg/s] (paper 002 eq. 17 bounds 10 deg/s for a slender MaRV; a glider's
#: schedule moves alpha by tens of degrees over minutes)
ALPHA_RATE_DEG_S = 2.0
#: the pre-flight solve's LGL nodes on a mission (paper 002 flies 125 on its 714-s problem; HORUS-2B's
#: 1300-s glide on 40 is converged but inaccurate: 0.013 between the nodes, 62 km when propagated),
#: in SEGMENTS segments: HORUS-2B's pre-flight solve at 80 nodes on one polynomial took 62 s, 8.2e-4
#: between the nodes, 615 m propagated; at 81 in 4 segments 29 s, 1.8e-4, 84 m, and a dispersed
#: closed loop (draw 0 of seed 2026) 88 s of wall time against 163 (re-solves 2.4 s median against 6.1)
NODES, SEGMENTS = 81, 4
def derive(scenario) -> Derivation:
    """LglTerminal settings for ``scenario``'s mission stating no block of this method."""
    interface = terminal_interface(scenario)
    alpha, source = mission_alpha(scenario)
    lo, hi = min(alpha.values_deg), max(alpha.values_deg)
    constant = lo == hi
    if constant:
        lo, hi = lo - ALPHA_WIDEN_DEG, hi + ALPHA_WIDEN_DEG
    gamma = scenario.terminal.flight_path_deg
    force_high = force_ratio_high(scenario.dispersions, FORCE_SIGMAS)
    candidates = [{"guidance.terminal_altitude_km": h, "guidance.terminal_velocity_m_s": V}
                  for h, V in interface_speeds(scenario, interface, LglTerminal.path_margin, load_alpha_deg=lo,
                                               force_high=force_high)]
    first = candidates[0]
    rate_limit, alpha_accel, actuator = alpha_actuator(
        scenario, ("the alpha actuator's rate", "guidance.alpha_accel_limit_deg_s2"),
        (ALPHA_RATE_DEG_S, LglTerminal.alpha_accel_limit_deg_s2), "the derivation's rate bound and the spec's acceleration")
    alpha_rate = min(ALPHA_RATE_DEG_S, rate_limit)
    spec = LglTerminal(problem=MISSION, terminal_altitude_km=first["guidance.terminal_altitude_km"],
                       terminal_velocity_m_s=first["guidance.terminal_velocity_m_s"], final_flight_path_deg=gamma,
                       final_descent_deg=FINAL_DESCENT_DEG if gamma is None else None,
                       alpha_bounds_deg=[lo, hi], alpha_rate_deg_s=alpha_rate, nodes=NODES,
                       segments=SEGMENTS, alpha_accel_limit_deg_s2=alpha_accel)
    choices = [Choice("guidance.problem", MISSION, "the problem the mission poses: its entry state, target, box and "
                      "vehicle limits (paper 002's eq. 11 objective)"),
               Choice("guidance.terminal_altitude_km, terminal_velocity_m_s",
                      f"{spec.terminal_altitude_km:g} km, {spec.terminal_velocity_m_s:.1f} m/s",
                      f"{interface.speed_words} ({interface.speed_m_s:.1f} m/s), or {Q_SPEED_FRACTION:g} of the "
                      f"speed where the planned dynamic-pressure bound is met at the altitude when lower, or the "
                      f"speed where forces {force_high:.3g} x the nominal ({FORCE_SIGMAS:g} sigma of the mission's "
                      f"force dispersions) meet the planned load bound at alpha {lo:g} deg when lower still (a "
                      f"re-solve predicts with the forces sensed, and its last node is fixed)"),
               Choice("guidance.alpha_bounds_deg", f"[{lo:g}, {hi:g}]", f"the range of {source} alpha schedule"
                      + (f", widened {ALPHA_WIDEN_DEG:g} deg each side" if constant else "")),
               Choice("guidance.final_flight_path_deg", "free" if gamma is None else f"{gamma:g}",
                      "the box's flight-path angle" if gamma is not None else "the box checks none"),
               Choice("guidance.final_descent_deg", "none" if gamma is not None else f"{FINAL_DESCENT_DEG:g}",
                      "the box's angle is planned" if gamma is not None else
                      "the plan ends descending at least this steeply: the flight stops where it first crosses the "
                      "terminal altitude (paper 004's CAV-H levelling off there was crossed up to 75 km short)"),
               actuator,
               Choice("guidance.nodes, segments, alpha_rate_deg_s", f"{NODES}, {SEGMENTS}, {alpha_rate:g}",
                      "the derivation's (4 LGL segments: each solve about twice as fast, verified closer; the planned "
                      f"alpha rate {ALPHA_RATE_DEG_S:g} deg/s, or the actuator's when slower)")]
    search = [SearchStep("guidance.terminal_altitude_km", tuple(candidates), ALTITUDE_WHY)]
    return Derivation(spec, choices, search)
