"""Paper 003 (Sagliano, Mooij & Theil 2017): a database of optimal trajectories over a grid
of entry-interface offsets, and adaptive multivariate pseudospectral interpolation (AMPI)
of it on line.

Modules: grid (the eq. 4-5 parameter grid, continuation order), database (storage at LD
LGL nodes, eqs. 11-12 LD-HD expansion, neighbour consistency), synthesis (Algorithm 1
subspace selection, Algorithm 2 tensor-product interpolation, the nearest entry for NTT).
The database is solved by the campaign engine (diagrams/ampi_database.py), which runs
the NLP planner on every case.
"""
from drake_entry.planning.ampi.database import Synthesis, TrajectoryDatabase, hd_matrix  # noqa: F401
from drake_entry.planning.ampi.grid import PARAMETERS, ParameterGrid  # noqa: F401
from drake_entry.planning.ampi.synthesis import interpolate, nearest_case, select_subspace  # noqa: F401
