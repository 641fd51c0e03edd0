"""What a method needs built before its first plan, built once per mission before any worker
starts (a method's ``GuidanceMethod.preparation``: e.g. AMPI's database for the mission, minutes
of solves on this machine's cores, then cached). The campaign, comparison and CLI call
``prepare`` before they plan; a script that builds a closed loop itself calls it too."""
from __future__ import annotations

import importlib

from drake_entry.guidance import method_for

__all__ = ["prepare"]


def prepare(scenario, *, progress: bool = True) -> str | None:
    """Build what ``scenario``'s guidance method needs before it plans (nothing for most
    methods); returns the preparation's one-line summary, or None when there was none."""
    name = method_for(scenario.guidance).preparation
    if not name:
        return None
    module, _, function = name.partition(":")
    return getattr(importlib.import_module(module), function)(scenario, progress=progress)
