"""Paper 004's study on a mission: Table 1 (swarm statistics over seeds), the optimum per case
(Case 1 and Case 2 at Mach_shift 20, 16, 10), the scipy baselines and the two-parameter
search, as ``benchmarks/run.py paper004`` prints them beside the paper's.

``PAPER`` holds the figures paper 004 prints, for side-by-side tables (Case 1 unless named).
"""
from __future__ import annotations

import dataclasses as dc
import time

import numpy as np

from drake_entry.guidance.swarm_bank.evaluator import Evaluation, SwarmProblem, evaluate
from drake_entry.guidance.swarm_bank.optimizers import minimise
from drake_entry.guidance.swarm_bank.search import BASELINES, Objective, SearchResult, search, swarm_searches

__all__ = ["PAPER", "CASES", "SwarmStatistics", "swarm_statistics", "case_problem", "CaseOptimum", "case_optima",
           "baselines", "two_parameter"]

#: paper 004's printed figures (Table 1: Case 1, 5 runs; Sec. 5 per case)
PAPER = {
    "sigma0_deg": {"case 1": 58.89, "mach_shift 20": 59.684, "mach_shift 16": 65.08, "mach_shift 10": 67.563},
    "altitude_error_m": {"case 1": 350.0, "mach_shift 20": 180.0, "mach_shift 16": 610.0, "mach_shift 10": 4570.0},
    "peak_heat_MW_m2": {"case 1": 3.83, "mach_shift 20": 6.06, "mach_shift 16": 6.29},
    "table1": {"pio": {"iterations": (11.8, 4.15), "J": (0.3783, 4.16e-4)},
               "pso": {"iterations": (12.6, 5.94), "J": (0.4530, 0.0415)}},
}

#: the cases of paper 004 Sec. 5: name -> (alpha law, Mach_shift)
CASES = {"case 1": ("load", 20.0), "mach_shift 20": ("heat", 20.0), "mach_shift 16": ("heat", 16.0),
         "mach_shift 10": ("heat", 10.0)}


@dc.dataclass
class SwarmStatistics:
    """One swarm method over seeds (Table 1 form): per-seed results and their statistics.
    iterations: to converge (the first iteration within 1e-3 of the run's final best J)."""

    method: str
    results: list
    wall_s: float

    def _stat(self, values) -> tuple[float, float]:
        v = np.asarray(values, float)
        return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0

    @property
    def sigma0(self):
        return self._stat([r.x[0] for r in self.results])

    @property
    def J(self):
        return self._stat([r.J for r in self.results])

    @property
    def iterations(self):
        return self._stat([r.iterations_to_converge for r in self.results])

    @property
    def trajectories(self) -> int:
        return int(sum(r.evaluations for r in self.results))


def swarm_statistics(problem: SwarmProblem, method: str, seeds, *, bounds=((0.0, 89.0),), **settings) -> SwarmStatistics:
    """Run ``method`` (SWARMS) once per seed, all seeds' populations flown together
    (optimizers.minimise), and return their statistics."""
    t0 = time.perf_counter()
    f = Objective(problem)
    results = minimise(f, swarm_searches(method, [tuple(b) for b in bounds], list(seeds), **settings))
    return SwarmStatistics(method, results, time.perf_counter() - t0)


def case_problem(problem: SwarmProblem, case: str) -> SwarmProblem:
    law, shift = CASES[case]
    return dc.replace(problem, case=law, mach_shift=shift)


@dc.dataclass
class CaseOptimum:
    """A case's optimum: the search, and the trajectory at its sigma_0 (one member, recorded)."""

    case: str
    search: SearchResult
    evaluation: Evaluation


def case_optima(problem: SwarmProblem, method: str = "pio", cases=tuple(CASES), **settings) -> list[CaseOptimum]:
    """The optimum sigma_0 of each case by ``method`` and its recorded trajectory."""
    out = []
    for case in cases:
        p = case_problem(problem, case)
        r = search(p, method, **settings)
        out.append(CaseOptimum(case, r, evaluate(p, np.radians(r.x[:1]), sigma_f=np.radians(r.x[1:2]) if len(r.x) > 1
                                                 else None, record=True)))
    return out


def baselines(problem: SwarmProblem, methods=BASELINES + ("pio",), *, seed: int = 0) -> list[SearchResult]:
    """Each search once on ``problem`` (sigma_0 only), with its trajectory count."""
    return [search(problem, m, seed=seed) for m in methods]


def two_parameter(problem: SwarmProblem, methods=("pio", "differential_evolution"), *, seed: int = 0,
                  sigma_f_bounds=(0.0, 85.0)) -> list[SearchResult]:
    """Searches over (sigma_0, sigma_f): a second variable removes the altitude floor of J."""
    return [search(problem, m, [(0.0, 89.0), sigma_f_bounds], seed=seed) for m in methods]

