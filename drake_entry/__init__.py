"""drake_entry: atmospheric-entry guidance design and analysis on Drake.

The repository keeps ``systems/`` and ``diagrams/`` at its top level; pyproject's
``package-dir`` installs them as ``drake_entry.systems`` and ``drake_entry.diagrams`` (a wheel,
or an editable install for development: ``pip install -e .``), so scripts import them one way
everywhere. That mapping is the only place the names are encoded.
"""

__all__ = ["campaign", "claims", "cli", "comparison", "errors", "figures", "guidance", "models", "planning",
           "scenario", "schema_doc", "tables", "typed_yaml"]

__version__ = "0.1.0"
