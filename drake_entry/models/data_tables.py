"""The project's CSV tables (aerodynamic tables, atmosphere profiles): rows of cells, with
blank lines and ``#`` comment lines left out."""
from __future__ import annotations

import csv

__all__ = ["read_csv_rows"]


def read_csv_rows(path_or_file) -> list[list[str]]:
    """The rows of a CSV file (a path or an open text file) as lists of cells (strings)."""
    if hasattr(path_or_file, "read"):
        lines = path_or_file.read().splitlines()
    else:
        with open(path_or_file) as f:
            lines = f.read().splitlines()
    return list(csv.reader(line for line in lines if line.strip() and not line.lstrip().startswith("#")))
