"""Where drake_entry keeps what it builds once per machine: compiled kernels, mission databases.

``$DRAKE_ENTRY_CACHE`` sets the root; otherwise ``$XDG_CACHE_HOME/drake_entry`` or
``~/.cache/drake_entry``. Each kind of artefact has its own folder below it."""
from __future__ import annotations

import os
from pathlib import Path

__all__ = ["cache_root", "cache_dir"]


def cache_root() -> Path:
    """The cache's root folder (module docstring); not created here."""
    explicit = os.environ.get("DRAKE_ENTRY_CACHE")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "drake_entry"


def cache_dir(kind: str) -> str:
    """The folder of one kind of artefact (e.g. 'ampi'), created when missing."""
    path = cache_root() / kind
    path.mkdir(parents=True, exist_ok=True)
    return str(path)
