"""Paper 003 (Sagliano, Mooij & Theil 2017): adaptive multivariate pseudospectral interpolation.

Modules: ``spec`` (the ``!Ampi`` scenario block), ``grid`` (the eq. 4-5 parameter grid and its
continuation order), ``database`` (storage at LD LGL nodes, eqs. 11-12 LD-HD expansion,
neighbour consistency), ``synthesis`` (Algorithm 1 subspace selection, Algorithm 2
tensor-product interpolation, the nearest entry for NTT), ``reference`` (the on-board reference
maker and its TVLQR law) and ``method`` (the closed-loop wiring). The database is solved by the
campaign engine (``guidance/ampi/database_study.py``), which runs the NLP planner on every case.
"""

__all__ = ["accuracy_study", "database", "database_study", "grid", "method", "reference", "spec", "synthesis"]
