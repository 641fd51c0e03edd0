"""Guidance methods, registered in one place.

``REGISTRY`` maps each method's scenario spec (a dataclass; YAML tag ``!ClassName``) to
the module that holds its ``GuidanceMethod`` as ``METHOD``. The spec modules are pure data
and imported here; method modules (which import Drake systems) are imported on first use.
Add a method: a new package beside ``drag_energy``, its spec import and one entry below
(docs/architecture.md).
"""
from __future__ import annotations

import importlib
from typing import Union

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.spec import Ampi
from drake_entry.guidance.bank_profile.spec import BankProfile
from drake_entry.guidance.drag_energy.spec import DragEnergy
from drake_entry.guidance.fnpeg.spec import Fnpeg
from drake_entry.guidance.lgl_terminal.spec import LglTerminal
from drake_entry.guidance.scvx.spec import Scvx
from drake_entry.guidance.swarm_bank.spec import SwarmBank

__all__ = ["REGISTRY", "GuidanceSpec", "known_tags", "folder_of", "method_for"]

REGISTRY = {
    DragEnergy: "drake_entry.guidance.drag_energy.method",
    BankProfile: "drake_entry.guidance.bank_profile.method",
    SwarmBank: "drake_entry.guidance.swarm_bank.method",
    Scvx: "drake_entry.guidance.scvx.method",
    Ampi: "drake_entry.guidance.ampi.method",
    LglTerminal: "drake_entry.guidance.lgl_terminal.method",
    Fnpeg: "drake_entry.guidance.fnpeg.method",
}

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
