"""Benchmark: both SOCP planners with Clarabel and SCS, side by side.

1. The drag-energy SOCP (paper 000 eqs. 82-92) by node count: build and solve times,
   iterations, the planner's own check and SCS's objective against Clarabel's.
2. The SCvx nominal plan (paper 001, direct minimum heat load, 33 x 4 Lobatto): plan time,
   iterations, heat load and the plan flown by the Drake Simulator, each solver with its
   tolerances (``ScvxSettings.for_solver``).
3. The closed-loop drag-energy campaign (horus2b) re-planning with each solver: the same
   samples, cost per sample and distance to the target."""
from __future__ import annotations

import numpy as np


def socp_benchmark(*, repeats: int = 5, nodes=(20, 40, 80, 160), scenario_name: str = "horus2b") -> dict:
    """Build and solve times of the drag-energy SOCP (paper 000 eqs. 82-92) with Clarabel and
    SCS at several node counts, from the nominal engagement state, one kappa iteration
    (the pure convex problem), and the corridor excursion of the Clarabel profile on a
    dense energy grid (between nodes)."""
    import dataclasses as dc
    import logging
    import math

    from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner, plan, solve_socp
    from drake_entry.planning.pseudospectral import LGL
    from drake_entry.scenario import load_scenario

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
    print(f"{'nodes':>5s} {'solver':>9s} {'build ms':>9s} {'solve ms':>9s} {'total ms':>9s} {'/Clarabel':>9s} "
          f"{'iters':>6s} {'status':>10s} {'excursion':>10s} {'J/Clarabel':>10s}")
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
            out[(n, solver, "objective")] = best.objective  # eq. 92 at the solution's I
            ratio = total / out[(n, "clarabel")]
            j_ratio = best.objective / out[(n, "clarabel", "objective")]
            print(f"{n:5d} {solver:>9s} {1e3 * best.build_time:9.2f} {1e3 * best.solve_time:9.2f} {total:9.2f} "
                  f"{ratio:9.1f} {best.iterations:6d} {status:>10s} {exc:>10s} {j_ratio:10.4f}")
    if (40, "clarabel") in out:
        print(f"goal: build + solve < 10 ms at 40 nodes with Clarabel: {out[(40, 'clarabel')]:.2f} ms")
    return out


def scvx_solver_benchmark() -> dict:
    """The SCvx nominal plan (paper 001 Table 1 mission, direct minimum heat load, 100 nodes)
    with Clarabel and with SCS, each flown by the Drake Simulator."""
    import logging
    import time

    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.scvx.mission import ScvxMission
    from drake_entry.guidance.scvx.planner import plan_entry
    from drake_entry.guidance.scvx.settings import ScvxSettings
    from drake_entry.models.atmosphere import US76Atmosphere
    from drake_entry.models.planet import Earth
    from drake_entry.models.vehicles import load_vehicle

    logging.getLogger("drake").setLevel(logging.WARNING)
    vehicle, planet, atmosphere, mission = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere(), ScvxMission()
    print("\nSCvx nominal plan (paper 001), direct minimum heat load, 33 x 4 Lobatto, each solver with its "
          "tolerances (ScvxSettings.for_solver)")
    print(f"{'solver':>9s} {'plan s':>7s} {'/Clarabel':>9s} {'iters':>5s} {'solver its':>10s} {'Q MJ/m2':>8s} "
          f"{'Q/Clarabel':>10s} {'max defect':>10s} {'flown-plan km':>13s} {'flown-site km':>13s} ok")
    out = {}
    for solver in ("clarabel", "scs"):
        t0 = time.perf_counter()
        plan = plan_entry(vehicle, planet, atmosphere, mission, settings=ScvxSettings.for_solver(solver),
                          verifier=fly_controls)
        wall = time.perf_counter() - t0
        flight = plan.flown
        out[solver] = {"plan_s": wall, "iterations": plan.iterations, "heat_load_MJ_m2": plan.objective,
                       "success": plan.success, "from_plan_km": flight.from_plan_m / 1e3}
        base = out["clarabel"]
        its = sum(r.solver_iterations for r in plan.history)
        print(f"{solver:>9s} {wall:7.1f} {wall / base['plan_s']:9.1f} {plan.iterations:5d} {its:10d} "
              f"{plan.objective:8.2f} {plan.objective / base['heat_load_MJ_m2']:10.4f} "
              f"{plan.max_defect:10.1e} {flight.from_plan_m / 1e3:13.2f} {flight.from_site_m / 1e3:13.2f} "
              f"{plan.success}")
    return out


def campaign_solver_benchmark(*, runs: int = 20, seed: int = 2018) -> dict:
    """The closed-loop horus2b campaign re-planning with Clarabel and with SCS: the same
    ``runs`` samples on one worker."""
    import tempfile
    import time

    from drake_entry.campaign.montecarlo import run_campaign
    from drake_entry.campaign.report import rows_as_columns, summary_statistics
    from drake_entry.campaign.store import read_rows

    print(f"\nclosed-loop horus2b campaign, the same {runs} samples (seed {seed}), one worker, "
          f"re-planning with each solver")
    print(f"{'solver':>9s} {'s/sample':>9s} {'/Clarabel':>9s} {'in box':>7s} {'distance m mean':>15s} "
          f"{'p95':>7s} {'worst margin %':>14s}")
    out = {}
    for solver in ("clarabel", "scs"):
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            run_campaign("horus2b", runs=runs, out_dir=d, seed=seed, workers=1, backend="serial",
                         overrides={"guidance.solver": solver}, progress=False, trajectory_step_s=0)
            wall = (time.perf_counter() - t0) / runs
            stats = summary_statistics(rows_as_columns(list(read_rows(d)[0].values())))
        distance = stats["errors"]["err_distance_m"]
        worst = min(m["worst"] for m in stats["margins"].values())
        out[solver] = {"s_per_sample": wall, "successful": stats["successful"], "distance_m": distance["mean"]}
        print(f"{solver:>9s} {wall:9.2f} {wall / out['clarabel']['s_per_sample']:9.2f} "
              f"{stats['successful']:4d}/{runs:<2d} {distance['mean']:15.0f} {distance['p95']:7.0f} "
              f"{100 * worst:14.2f}")
    return out
