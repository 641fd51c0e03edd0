"""Mesh refinement: raise the node count until the between-node error meets the
tolerance, each mesh warm-started from the previous solution.

The error estimate of a mesh is verify.interval_errors: on every interval the integral of
f along the transcription's own interpolants against the change of the states, relative
in GPOPS-II's form (Patterson & Rao 2014, eq. 39). The next node count follows each
transcription's convergence:

- LGL, one global polynomial (p-refinement): the error falls exponentially in N for a
  smooth solution, so with two meshes the next N extrapolates log(error) linearly in N to
  half the tolerance; with one mesh it is 1.5 N.
- DirectCollocation (Hermite-Simpson, cubic states): the integrated residual of an interval
  falls as h^5; the next N assumes the slower h^4 (a margin against a rate not yet reached)
  and aims at half the tolerance.

Each step grows N by at least 25 % (a smaller step rarely changes the error class) and at
most 2x (LGL) / 3x (Hermite-Simpson), capped at ``max_nodes``.
"""
from __future__ import annotations

import dataclasses as dc
import math

import numpy as np

from drake_entry.errors import DrakeEntryError
from drake_entry.planning.nlp.verify import interval_errors

__all__ = ["MAX_NODES", "TARGET_SHARE", "MeshStep", "mesh_error", "next_nodes"]

#: default node caps: one LGL polynomial of 150 nodes already resolves minutes-long entry
#: flights to 1e-4; Hermite-Simpson needs more samples for the same error
MAX_NODES = {"lgl": 150, "dircol": 400, "hermite_simpson": 400}
TARGET_SHARE = 0.5  # aim each new mesh at this share of the tolerance


@dc.dataclass(frozen=True)
class MeshStep:
    """One mesh of a refined solve: node count, its largest between-node error (relative;
    inf when the models were undefined between the nodes, nan when not converged), the
    solver's verdict and its wall time [s]."""

    nodes: int
    error: float
    converged: bool
    solve_time: float

    def __iter__(self):  # (nodes, error, converged, solve_time), e.g. for list(step)
        return iter(dc.astuple(self))


def mesh_error(problem, result) -> float:
    """Largest between-node error of ``result`` (verify.interval_errors), inf where the
    models are undefined between the nodes."""
    try:
        err, _ = interval_errors(problem, result)
    except DrakeEntryError:
        return math.inf
    return float(np.nan_to_num(err, nan=np.inf).max())


def next_nodes(transcription: str, history: list, target: float, max_nodes: int) -> int:
    """The next mesh's node count from the refinement ``history`` (MeshStep list) and the
    error ``target`` (module docstring)."""
    n, err = history[-1].nodes, history[-1].error
    goal = TARGET_SHARE * target
    if transcription == "lgl":
        grow_max, want = 2.0, 1.5 * n
        if len(history) >= 2 and math.isfinite(err) and 0 < err < history[-2].error < math.inf and err > goal:
            slope = (math.log(history[-2].error) - math.log(err)) / (n - history[-2].nodes)
            want = n + math.log(err / goal) / slope
    else:
        grow_max, want = 3.0, 1.5 * n
        if math.isfinite(err) and err > goal:
            want = n * (err / goal) ** 0.25
    step = min(max(want, 1.25 * n), grow_max * n)
    return int(min(math.ceil(step), max_nodes))
