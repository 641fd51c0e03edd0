"""The LGL terminal guidance's settings from a mission (drake_entry.guidance.derivation). Today:
the mission that states its !LglTerminal block flies it (derivation_for); any other mission is
refused with the figure that stops it (the problem file poses paper 002's impact). Posing the
terminal problem from a mission's interface is future work."""

from drake_entry.guidance.derivation import CannotFly, Derivation, terminal_interface

__all__ = ["derive"]


def derive(scenario) -> Derivation:
    """LglTerminal settings for ``scenario``'s mission; CannotFly for another method's mission."""
    interface = terminal_interface(scenario)
    raise CannotFly(f"it solves a problem file (packaged: paper 002's MaRV impact at the ground, a final speed "
                    f"and alpha); this mission ends at {interface.altitude_km:g} km, {interface.speed_m_s:.0f} m/s "
                    f"over its target, and posing the terminal problem from a mission's interface is not written")
