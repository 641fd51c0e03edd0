"""The worked example's settings from a mission (drake_entry.guidance.derivation): the mission's
terminal interface, its reversal corridor; the two bank magnitudes searched on the nominal
flight."""

from drake_entry.guidance.bank_profile.spec import BankProfile
from drake_entry.guidance.derivation import (
    ALTITUDE_WHY,
    Choice,
    Derivation,
    SearchStep,
    interface_altitudes,
    require_alpha_window,
    reversal_corridor,
    terminal_interface,
)

__all__ = ["derive", "BANK_CANDIDATES_DEG"]

#: |sigma| at entry and at the interface tried, in order [deg]
BANK_CANDIDATES_DEG = (60.0, 45.0, 75.0, 30.0, 85.0, 15.0)


def derive(scenario) -> Derivation:
    """BankProfile settings for ``scenario``'s mission stating no
    block of this method (derivation_for returns a stated one as it is)."""
    require_alpha_window(scenario)
    interface = terminal_interface(scenario)
    mach = interface.mach
    heading, velocity, corridor = reversal_corridor(scenario)
    spec = BankProfile(terminal_altitude_km=interface.altitude_km, terminal_mach=round(mach, 4),
                       bank_start_deg=BANK_CANDIDATES_DEG[0], bank_end_deg=BANK_CANDIDATES_DEG[0],  # searched
                       reversal_heading_deg=heading, reversal_velocity_m_s=velocity)
    choices = [Choice("guidance.terminal_altitude_km, terminal_mach", f"{interface.altitude_km:g} km, Mach {mach:.3g}",
                      "the centre of the mission's acceptance box"),
               corridor]
    limit = scenario.make_vehicle().bank_limit_deg
    banks = tuple(b for b in BANK_CANDIDATES_DEG if b <= limit)
    search = [SearchStep.over("guidance.terminal_altitude_km", interface_altitudes(scenario, interface), ALTITUDE_WHY),
              SearchStep.over("guidance.bank_start_deg", banks, "no range feedback: the profile is the range"),
              SearchStep.over("guidance.bank_end_deg", banks, "no range feedback: the profile is the range")]
    return Derivation(spec, choices, search)
