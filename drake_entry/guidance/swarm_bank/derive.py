"""Paper 004's settings from a mission (drake_entry.guidance.derivation): the TAEM interface at the
mission's box centre, alpha from the load factor (Case 1, eq. 31) between the mission's alpha
extremes, its reversal corridor, sigma_0 searched before flight and re-solved on board; sigma_f
searched."""

from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    Choice,
    Derivation,
    SearchStep,
    interface_altitudes,
    mission_alpha,
    reversal_corridor,
    terminal_interface,
)
from drake_entry.guidance.swarm_bank.spec import SwarmBank

__all__ = ["derive", "BANK_END_CANDIDATES_DEG", "REPLAN_PERIOD_S"]

#: sigma_f tried, in order [deg] (paper 004: 60)
BANK_END_CANDIDATES_DEG = (60.0, 45.0, 30.0, 75.0)
#: sigma_0 re-solved on board every this [s] (paper 004's plan-once sigma_0 meets its own
#: mission's dispersions in 1 of 20 runs, re-solved every 100 s in 20 of 20)
REPLAN_PERIOD_S = 100.0


def derive(scenario) -> Derivation:
    """SwarmBank settings for ``scenario``'s mission stating no
    block of this method (derivation_for returns a stated one as it is)."""
    interface = terminal_interface(scenario)
    heading, velocity, corridor = reversal_corridor(scenario)
    alpha, source = mission_alpha(scenario)
    alphas = [float(a) for a in alpha.values_deg]
    lo, hi = min(alphas), max(alphas)
    if hi - lo < 1.0:  # a constant alpha: the load law still needs room to move
        lo, hi = lo - 1.0, hi + 1.0
    bank_limit = min(89.0, scenario.make_vehicle().bank_limit_deg)
    candidates = tuple(b for b in BANK_END_CANDIDATES_DEG if b <= bank_limit)
    spec = SwarmBank(terminal_altitude_km=interface.altitude_km, terminal_velocity_m_s=round(interface.speed_m_s, 3),
                     bank_end_deg=candidates[0], bank_start_bounds_deg=[0.0, bank_limit], alpha_law="load",
                     alpha_min_deg=lo, alpha_max_deg=hi, replan_period_s=REPLAN_PERIOD_S,
                     reversal_heading_deg=heading, reversal_velocity_m_s=velocity)
    choices = [
        Choice("guidance.terminal_altitude_km, terminal_velocity_m_s",
               f"{interface.altitude_km:g} km, {interface.speed_m_s:.1f} m/s",
               "eq. 32's TAEM interface at the centre of the mission's acceptance box"),
        Choice("guidance.alpha_law, alpha_min_deg, alpha_max_deg", f"load, {lo:g}-{hi:g} deg",
               f"Case 1 (eq. 31) between the extremes of {source} alpha schedule (widened to 2 deg when constant)"),
        Choice("guidance.bank_start_bounds_deg", f"0-{bank_limit:g} deg", "the vehicle's bank limit"),
        Choice("guidance.replan_period_s", REPLAN_PERIOD_S,
               "sigma_0 re-solved on board (plan-once PIO meets paper 004's own dispersions in 1 of 20 runs)"),
        corridor,
    ]
    search = [SearchStep.over("guidance.terminal_altitude_km", interface_altitudes(scenario, interface), ALTITUDE_WHY),
              SearchStep.over("guidance.bank_end_deg", candidates,
                              "eq. 17's sigma_f: the lift left for the range at the end")]
    return Derivation(spec, choices, search)
