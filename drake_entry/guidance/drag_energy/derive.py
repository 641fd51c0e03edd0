"""The drag-energy guidance's settings from a mission (drake_entry.guidance.derivation): the
terminal interface in the mission's box, the mission's alpha schedule in normalised energy, its
reversal corridor; the interface's altitude and the corridor margin searched (paper 000's
corridor closes where the vehicle's limits meet: the altitude that keeps it open is the
mission's)."""

from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    Choice,
    Derivation,
    SearchStep,
    alpha_rewritten,
    interface_altitudes,
    require_alpha_window,
    reversal_corridor,
    terminal_interface,
)
from drake_entry.guidance.drag_energy.spec import DragEnergy
from drake_entry.scenario import ScheduleSpec

__all__ = ["derive", "MARGIN_CANDIDATES", "REPLAN_PERIOD_S"]
#: corridor margins tried (paper 000 keeps the profile inside the limits by a margin)
MARGIN_CANDIDATES = (0.05, 0.03, 0.08, 0.02)
#: re-plan from the navigation state every this [s] (paper 000 plans once; re-planning is what
#: dispersed entries need: HORUS-2B's single plan ends 24.3 +- 4.3 km from the runway)
REPLAN_PERIOD_S = 20.0


def derive(scenario) -> Derivation:
    """DragEnergy settings for ``scenario``'s mission stating no
    block of this method (derivation_for returns a stated one as it is)."""
    require_alpha_window(scenario)
    interface = terminal_interface(scenario)
    mach = interface.mach
    heading, velocity, corridor = reversal_corridor(scenario)
    breakpoints, values, alpha_how = alpha_rewritten(scenario, interface, "normalized_energy")
    own = scenario.alpha
    alpha = (None if own.variable in ("energy", "normalized_energy")
             else ScheduleSpec("normalized_energy", breakpoints, values, own.smooth))
    altitudes = interface_altitudes(scenario, interface)
    spec = DragEnergy(terminal_altitude_km=altitudes[0], terminal_mach=round(mach, 4),
                      corridor_margin=MARGIN_CANDIDATES[0], replan_period_s=REPLAN_PERIOD_S, replan_until_e=0.99,
                      bandwidth_rad_s=0.1, reversal_heading_deg=heading, reversal_velocity_m_s=velocity)
    choices = [
        Choice("guidance.terminal_mach", round(mach, 4), "the centre of the mission's acceptance box"
               + ("" if interface.mach_given else f" ({interface.speed_m_s:g} m/s as a Mach number)")),
        Choice("alpha", "as the mission's" if alpha is None else
               ", ".join(f"{v:g} deg at e = {b:.3f}" for b, v in zip(breakpoints, values)),
               alpha_how if alpha is not None else "the planner flies alpha(E): the mission's schedule is in energy"),
        corridor,
        Choice("guidance.replan_period_s, replan_until_e", f"{REPLAN_PERIOD_S:g} s, 0.99",
               "re-planned from the navigation state (paper 000 plans once; a single HORUS-2B plan ends "
               "24.3 +- 4.3 km from the runway)"),
        Choice("guidance.bandwidth_rad_s", 0.1, "the tracking law's constant time-domain bandwidth (omega = "
               "0.1 / (D V)): the same response at every speed, for any vehicle's drag"),
    ]
    search = [SearchStep.over("guidance.terminal_altitude_km", altitudes, ALTITUDE_WHY),
              SearchStep.over("guidance.corridor_margin", MARGIN_CANDIDATES,
                         "room between the profile and the limits for the dispersions")]
    return Derivation(spec, choices, search, alpha=alpha)
