"""Result tables: write column dictionaries as Parquet (default) or CSV."""
from __future__ import annotations

import os

import numpy as np

from drake_entry.errors import ScenarioError

__all__ = ["write_table", "read_table"]


def write_table(columns: dict, path: str) -> str:
    """Write {name: 1-D array} to ``path``; the suffix picks the format (.parquet or .csv)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if path.endswith(".parquet"):
        import pyarrow as pa
        import pyarrow.parquet as pq

        pq.write_table(pa.table({k: np.asarray(v) for k, v in columns.items()}), path)
    elif path.endswith(".csv"):
        names = list(columns)
        np.savetxt(path, np.column_stack([np.asarray(columns[n], float) for n in names]), delimiter=",",
                   header=",".join(names), comments="", fmt="%.10g")
    else:
        raise ScenarioError(f"output '{path}' must end in .parquet or .csv")
    return path


def read_table(path: str) -> dict:
    """Read a table written by ``write_table``."""
    if path.endswith(".parquet"):
        import pyarrow.parquet as pq

        t = pq.read_table(path)
        return {n: t.column(n).to_numpy() for n in t.column_names}
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {n: data[n] for n in data.dtype.names}
