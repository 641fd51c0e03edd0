"""AMPI's settings from a mission (drake_entry.guidance.derivation). Today: only a mission that
states its !Ampi block flies it (derivation_for); any other mission is refused with the figure
that stops it (the databases' vehicle and entry). Building a database for a mission on demand is
future work."""

from drake_entry.guidance.ampi.spec import packaged_databases
from drake_entry.guidance.derivation import CannotFly, Derivation

__all__ = ["derive"]


def derive(scenario) -> Derivation:
    """Ampi settings for ``scenario``'s mission; CannotFly for another method's mission."""
    e = scenario.entry
    raise CannotFly(f"AMPI interpolates references from a database of optimal trajectories of one vehicle and "
                    f"entry box (paper 003); the packaged databases ({', '.join(packaged_databases())}) are not of "
                    f"vehicle '{scenario.vehicle}' entering at {e.altitude_km:g} km, {e.velocity_m_s:g} m/s, "
                    f"{e.flight_path_deg:g} deg, and building one for a mission on demand is not written "
                    f"(`drake-entry ampi-database` builds one from a problem file)")
