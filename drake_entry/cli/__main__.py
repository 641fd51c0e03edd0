"""``python -m drake_entry.cli``: the drake-entry command."""
import sys

from drake_entry.cli import main

__all__ = []

sys.exit(main())
