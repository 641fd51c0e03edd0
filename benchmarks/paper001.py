"""Benchmark: paper 001's SCvx nominal plan (SPHYNX, Table 1 mission, minimum heat load) by
discretisation, with the plan flown by the Drake Simulator, side by side with the paper's mean
plan time and iterations (75.5 s, 21.8 iterations: aborts, Sec. VI) and the issue-13 goals
(<= 5 s per plan at 100 nodes, <= 15 s at the flyable accuracy, <= 5 km flown from the plan)."""
from __future__ import annotations

import time

PAPER_TIME_S, PAPER_ITERATIONS = 75.5, 21.8


def paper001_benchmark(meshes=((99, 2), (33, 4), (50, 4), (66, 4))) -> list:
    """Plan and fly the nominal on each (segments, nodes per segment) mesh; (99, 2) is the
    paper's trapezoid at 100 nodes."""
    from drake_entry.atmosphere import US76Atmosphere
    from drake_entry.diagrams.plan_flight import fly_plan
    from drake_entry.planet import Earth
    from drake_entry.planning.scvx.entry import EntryProblemSettings
    from drake_entry.planning.scvx.guess import glide_guess
    from drake_entry.planning.scvx.mission import ScvxMission
    from drake_entry.planning.scvx.planner import plan_entry
    from drake_entry.vehicles import load_vehicle

    vehicle, planet, atmosphere, mission = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere(), ScvxMission()
    t0 = time.perf_counter()
    guess = glide_guess(vehicle, planet, atmosphere, mission)
    guess_s = time.perf_counter() - t0
    print(f"paper 001 nominal, minimum heat load; glide guess {guess_s:.2f} s (miss {guess.miss / 1e3:.0f} km), "
          f"included in 'plan s'; paper: {PAPER_TIME_S} s, {PAPER_ITERATIONS} iterations (abort means)")
    print(f"{'mesh':>10s} {'nodes':>5s} {'plan s':>7s} {'/paper':>7s} {'iters':>5s} {'/paper':>7s} {'ms/iter':>8s} "
          f"{'Q MJ/m2':>8s} {'t_f s':>6s} {'gap':>6s} {'flown-plan km':>13s} {'flown-site km':>13s} {'DRS':>4s} ok")
    rows = []
    for segments, per in meshes:
        t1 = time.perf_counter()
        plan = plan_entry(vehicle, planet, atmosphere, mission, guess=guess,
                          problem_settings=EntryProblemSettings(segments=segments, nodes_per_segment=per))
        wall = time.perf_counter() - t1 + guess_s
        flight = fly_plan(plan, vehicle, planet, atmosphere)
        n = plan.problem.n_nodes
        label = "trapezoid" if per == 2 else f"{segments}x{per}"
        print(f"{label:>10s} {n:5d} {wall:7.2f} {wall / PAPER_TIME_S:7.3f} {plan.iterations:5d} "
              f"{plan.iterations / PAPER_ITERATIONS:7.2f} {1e3 * plan.solve_time / plan.iterations:8.0f} "
              f"{plan.objective:8.1f} {plan.final_time:6.0f} {plan.lossless_gap:6.3f} {flight.from_plan_m / 1e3:13.2f} "
              f"{flight.from_site_m / 1e3:13.2f} {'yes' if flight.drs_ok else 'no':>4s} {plan.success}")
        rows.append({"mesh": label, "nodes": n, "plan_s": wall, "iterations": plan.iterations,
                     "heat_load_MJ_m2": plan.objective, "from_plan_km": flight.from_plan_m / 1e3,
                     "from_site_km": flight.from_site_m / 1e3, "success": plan.success})
    return rows
