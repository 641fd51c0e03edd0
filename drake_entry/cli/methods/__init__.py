"""The commands of the guidance methods, one module per method folder (named as the folder in
``drake_entry/guidance/``): ``plan_report(scenario, out_dir) -> exit code`` for ``drake-entry plan``
and any further ``COMMANDS``."""

__all__ = ["ampi", "drag_energy", "lgl_terminal", "scvx", "swarm_bank"]
