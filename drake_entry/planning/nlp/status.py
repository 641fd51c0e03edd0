"""Solver verdicts in words. Only a solver's own "optimal" counts as converged: Drake maps
SNOPT info 3 ("requested accuracy could not be achieved") to kSolutionFound, and that is
not converged here. The meanings are the SNOPT 7 user guide's (section 8.6, INFO codes) and
Ipopt's SolverReturn (Drake's ``IpoptSolverDetails.ConvertStatusToString``)."""
from __future__ import annotations

__all__ = ["SNOPT_INFO", "SNOPT_CONVERGED", "SNOPT_RESTARTABLE", "IPOPT_RESTARTABLE_WORDS", "verdict", "restartable"]

SNOPT_INFO = {
    1: "optimality conditions satisfied", 2: "feasible point found", 3: "requested accuracy could not be achieved",
    5: "elastic objective minimized", 6: "elastic infeasibilities minimized",
    11: "infeasible linear constraints", 12: "infeasible linear equalities",
    13: "nonlinear infeasibilities minimized", 14: "linear infeasibilities minimized",
    15: "infeasible linear constraints in QP subproblem", 16: "infeasible nonelastic constraints",
    21: "unbounded objective", 22: "constraint violation limit reached",
    31: "iteration limit reached", 32: "major iteration limit reached", 33: "the superbasics limit is too small",
    34: "time limit reached",
    41: "current point cannot be improved", 42: "singular basis", 43: "cannot satisfy the general constraints",
    44: "ill-conditioned null-space basis", 45: "unable to compute acceptable LU factors",
    51: "incorrect objective derivatives", 52: "incorrect constraint derivatives",
    56: "irregular or badly scaled problem functions",
    61: "undefined function at the first feasible point", 62: "undefined function at the initial point",
    63: "unable to proceed into undefined region",
    71: "terminated during function evaluation", 72: "terminated during constraint evaluation",
    73: "terminated during objective evaluation", 74: "terminated from monitor routine",
    81: "work arrays must have at least 500 elements", 82: "not enough character storage",
    83: "not enough integer storage", 84: "not enough real storage",
    91: "invalid input argument", 92: "basis file dimensions do not match this problem",
}
SNOPT_CONVERGED = (1,)
#: stops near an optimum that one warm restart from the returned point usually finishes
#: (SNOPT 3 and 41; Ipopt's acceptable point and tiny step): MARV refined from 40 to 60 LGL
#: nodes stops at info 3 after 21 s with J = 17.6556 and the restart ends at info 1 in 0.4 s
SNOPT_RESTARTABLE = (3, 41)
IPOPT_RESTARTABLE_WORDS = ("acceptable", "tiny step")


def verdict(result, solver: str) -> tuple[bool, str]:
    """(converged, the solver's verdict in words) of a Drake MathematicalProgramResult."""
    try:
        details = result.get_solver_details()
        if solver == "snopt":
            info = int(details.info)
            return info in SNOPT_CONVERGED, f"SNOPT: {SNOPT_INFO.get(info, 'unlisted exit')} (info {info})"
        words = details.ConvertStatusToString()
        return int(details.status) == 0, f"Ipopt: {words} (status {int(details.status)})"
    except Exception:  # noqa: BLE001 - no details: fall back on Drake's verdict
        return result.is_success(), f"{solver}: {result.get_solution_result().name}"


def restartable(result, solver: str) -> bool:
    """Did the solver stop near an optimum without meeting its tolerances (SNOPT_RESTARTABLE,
    IPOPT_RESTARTABLE_WORDS), so that a warm restart from the returned point is worth it?"""
    try:
        details = result.get_solver_details()
        if solver == "snopt":
            return int(details.info) in SNOPT_RESTARTABLE
        return any(w in details.ConvertStatusToString().lower() for w in IPOPT_RESTARTABLE_WORDS)
    except Exception:  # noqa: BLE001
        return False
