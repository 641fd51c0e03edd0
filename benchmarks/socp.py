"""Benchmark: the drag-energy SOCP (paper 000) with Clarabel and SCS at several node counts."""
from __future__ import annotations

import numpy as np


def socp_benchmark(*, repeats: int = 5, nodes=(20, 40, 80, 160), scenario_name: str = "horus2b") -> dict:
    """Build and solve times of the drag-energy SOCP (paper 000 eqs. 82-92) with Clarabel and
    SCS at several node counts, from the nominal engagement state, one kappa iteration
    (the pure convex problem), and the corridor excursion of the Clarabel profile on a
    dense energy grid (between nodes)."""
    import dataclasses as dc
    import math

    from drake_entry.planning.drag_energy import DragEnergyPlanner, solve_socp, plan
    from drake_entry.pseudospectral import LGL
    from drake_entry.scenario import load_scenario

    import logging

    logging.getLogger("drake").setLevel(logging.WARNING)  # SCS's per-solve INFO lines
    scenario = load_scenario(scenario_name)
    planner = DragEnergyPlanner.from_scenario(scenario)
    # nominal engagement state (drake-entry plan horus2b: t = 300 s, e = 0.042)
    x = np.array([77438.3, math.radians(-90.93), math.radians(-16.93), 7332.0, math.radians(-0.0158),
                  math.radians(73.5)])
    base = planner.plan_from_state(x)
    out = {}
    print(f"drag-energy SOCP from the nominal engagement state, best of {repeats} (build = MathematicalProgram "
          f"construction, solve = solver call); excursion = max relative D above D_max between nodes")
    print(f"{'nodes':>5s} {'solver':>9s} {'build ms':>9s} {'solve ms':>9s} {'total ms':>9s} {'iters':>6s} "
          f"{'status':>10s} {'excursion':>10s}")
    for n in nodes:
        op = LGL(n, base.problem.E0, base.problem.Ef)
        lo, hi = base.problem.corridor.bounds(op.x)
        kappa = base.kappa_at(op.x)
        for solver in ("clarabel", "scs"):
            p = dc.replace(base.problem, n_nodes=n, solver=solver)
            best = None
            for _ in range(repeats):
                r = solve_socp(p, op, lo, hi, kappa)
                if best is None or r.build_time + r.solve_time < best.build_time + best.solve_time:
                    best = r
            exc = ""
            if best.success:
                full = plan(dc.replace(p, range_iterations=1, kappa_guess=base.kappa_at))
                exc = f"{100 * full.corridor_violation()['above_max']:.2f} %" if full.success else ""
            status = "ok" if best.success else "inaccurate"
            total = 1e3 * (best.build_time + best.solve_time)
            out[(n, solver)] = total
            print(f"{n:5d} {solver:>9s} {1e3 * best.build_time:9.2f} {1e3 * best.solve_time:9.2f} {total:9.2f} "
                  f"{best.iterations:6d} {status:>10s} {exc:>10s}")
    if (40, "clarabel") in out:
        print(f"goal: build + solve < 10 ms at 40 nodes with Clarabel: {out[(40, 'clarabel')]:.2f} ms")
    return out
