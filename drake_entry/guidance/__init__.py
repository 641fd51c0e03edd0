"""Guidance methods, registered in one place.

``METHODS`` lists each method once: its folder (``drake_entry/guidance/<folder>/``) and the
class name of its scenario spec (a dataclass in ``<folder>/spec.py``; YAML tag ``!ClassName``).
``REGISTRY`` maps each spec class to the module that holds its ``GuidanceMethod`` as ``METHOD``
(``<folder>/method.py``). The spec modules are pure data and imported here; method modules
(which import Drake systems) are imported on first use. Add a method: a new folder beside
``drag_energy`` and one line below (docs/architecture.md, "Adding a method").
"""
from __future__ import annotations

import importlib
from typing import Union

from drake_entry.errors import ScenarioError

__all__ = ["METHODS", "REGISTRY", "GuidanceSpec", "known_tags", "folder_of", "method_for"]

#: (folder, spec class) of every method; the first is the default of an untagged ``guidance:``
METHODS = (
    ("drag_energy", "DragEnergy"),  # paper 000
    ("bank_profile", "BankProfile"),  # the worked example of adding a method
    ("swarm_bank", "SwarmBank"),  # paper 004
    ("scvx", "Scvx"),  # paper 001
    ("ampi", "Ampi"),  # paper 003
    ("lgl_terminal", "LglTerminal"),  # paper 002 as guidance
    ("fnpeg", "Fnpeg"),  # Lu 2014, the field's baseline
)

#: {spec class: the module of its GuidanceMethod}
REGISTRY = {getattr(importlib.import_module(f"drake_entry.guidance.{folder}.spec"), spec):
            f"drake_entry.guidance.{folder}.method" for folder, spec in METHODS}

#: the scenario's ``guidance:`` field type (the first is the default when untagged)
GuidanceSpec = Union[tuple(REGISTRY)]


def known_tags() -> str:
    return ", ".join(f"!{spec.__name__}" for spec in REGISTRY)


def folder_of(spec_type) -> str:
    """The method folder (``drake_entry/guidance/<folder>/``) of a registered spec type."""
    return REGISTRY[spec_type].split(".")[2]


def method_for(spec):
    """The GuidanceMethod of a scenario's guidance spec."""
    module = REGISTRY.get(type(spec))
    if module is None:
        raise ScenarioError(f"guidance: {type(spec).__name__} is not a registered guidance method; "
                            f"known: {known_tags()}")
    return importlib.import_module(module).METHOD
