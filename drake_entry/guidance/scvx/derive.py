"""SCvx's settings from a mission (drake_entry.guidance.derivation). Today: only a mission that
states its !Scvx block flies it (derivation_for); any other mission is refused with the figure
that stops it (the planner's load limit, the terminal window). Posing paper 001's DRS problem
from any mission's interface is future work."""
import math

from drake_entry.guidance.derivation import CannotFly, Derivation, terminal_interface

__all__ = ["derive"]


def derive(scenario) -> Derivation:
    """Scvx settings for ``scenario``'s mission; CannotFly (with its figures) for another method's mission."""
    lim = scenario.make_vehicle().limits
    interface = terminal_interface(scenario)
    reasons = []
    if not math.isfinite(lim.total_load_max):
        reasons.append(f"its planner constrains the total aerodynamic load (paper 001 eq. 11) and the vehicle limits "
                       f"only the normal load ({lim.normal_load_max:g} g)")
    if not math.isfinite(lim.heat_flux_max):
        reasons.append("its planner constrains the heat flux (eq. 9) and the vehicle gives no heat-flux limit")
    reasons.append(f"the SCvx problem is posed for paper 001's DRS window (a stop altitude, Mach <= 1, a site "
                   f"radius); this mission ends at {interface.altitude_km:g} km"
                   + (f", Mach {interface.mach:g}" if interface.mach is not None else
                      f", {interface.speed_m_s:g} m/s")
                   + ", and posing SCvx on a TAEM interface from the mission is not written")
    raise CannotFly("; ".join(reasons))
