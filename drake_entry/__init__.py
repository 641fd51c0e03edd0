"""drake_entry: atmospheric-entry guidance design and analysis on Drake.

The repository keeps ``systems/`` and ``diagrams/`` at its top level; they install as
``drake_entry.systems`` and ``drake_entry.diagrams`` (pyproject ``package-dir``). In a
source checkout (tests, examples run from the repository) the same names are served from
those two directories, so scripts import them one way everywhere.
"""
import os as _os

__version__ = "0.1.0"

_root = _os.path.dirname(_os.path.dirname(_os.path.abspath(__file__)))
if not _os.path.isdir(_os.path.join(__path__[0], "systems")) and all(
        _os.path.isfile(_os.path.join(_root, d, "__init__.py")) for d in ("systems", "diagrams")):
    # source checkout: drake_entry.systems -> <root>/systems, drake_entry.diagrams -> <root>/diagrams
    import importlib.util as _util
    import sys as _sys

    for _name in ("systems", "diagrams"):
        _dir = _os.path.join(_root, _name)
        _spec = _util.spec_from_file_location(f"{__name__}.{_name}", _os.path.join(_dir, "__init__.py"),
                                              submodule_search_locations=[_dir])
        _module = _util.module_from_spec(_spec)
        _sys.modules[_spec.name] = _module
        _spec.loader.exec_module(_module)
        globals()[_name] = _module
