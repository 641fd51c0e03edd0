"""The LGL terminal guidance's settings from a mission (drake_entry.guidance.derivation). Today: the
mission's own block when it flies it; any other mission is refused with the figure that stops it
(the problem file poses paper 002's impact). Posing the terminal problem from a mission's
interface is future work."""
import dataclasses as dc

from drake_entry.guidance.derivation import CannotFly, Choice, Derivation, own_guidance, terminal_interface
from drake_entry.guidance.lgl_terminal.spec import LglTerminal

__all__ = ["derive"]


def derive(scenario) -> Derivation:
    """LglTerminal settings for ``scenario``'s mission; CannotFly for another method's mission."""
    if isinstance(own_guidance(scenario), LglTerminal):
        return Derivation(dc.replace(scenario.guidance),
                          [Choice("guidance", "!LglTerminal", "the mission's own settings")])
    interface = terminal_interface(scenario)
    raise CannotFly(f"it solves a problem file (packaged: paper 002's MaRV impact at the ground, a final speed "
                    f"and alpha); this mission ends at {interface.altitude_km:g} km, {interface.speed_m_s:.0f} m/s "
                    f"over its target, and posing the terminal problem from a mission's interface is not written")
