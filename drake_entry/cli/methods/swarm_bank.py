"""``drake-entry plan`` for paper 004's guidance: search sigma_0, fly it in the Drake closed
loop, compare the flight with the planned trajectory, and plot both (paper 004 Figs. 5-13
form). CLI layer (it flies diagrams)."""
from __future__ import annotations

import sys

__all__ = ["plan_report"]


def plan_report(scenario, out_dir: str) -> int:
    """Plan, fly once (nominal), print the comparison and write the figures; exit code 0 when
    the plan is verified and the flight agrees with it (2 km along-track, 20 m altitude)."""
    from drake_entry.diagrams.closed_loop import fly
    from drake_entry.figures import trajectory_plots
    from drake_entry.guidance.swarm_bank.evaluator import HISTORY_COLUMNS, range_error
    from drake_entry.guidance.swarm_bank.plots import swarm_case_plots

    res = fly(scenario)
    plan = res.guidance.details
    print(plan.message)
    if plan.search is not None:
        s = plan.search
        print(f"search {s.method}: {s.trajectories} trajectories in {s.calls} populations, {s.wall_s:.1f} s")
    ev = plan.evaluation
    x = res.trajectory.state[-1]
    ds, cross = range_error(plan.problem, x[1], x[2])
    d_along, d_alt = float(ds[0] - ev.range_error_m[0]), float(x[0] - plan.problem.h_f - ev.altitude_error_m[0])
    print(f"Drake closed loop: {res.message}")
    print(f"  flown minus planned at TAEM: along-track {d_along:+.1f} m, cross-track "
          f"{float(cross[0] - ev.crossrange_m[0]):+.1f} m, altitude {d_alt:+.2f} m, speed "
          f"{float(x[3] - plan.problem.V_f - ev.velocity_error_m_s[0]):+.3f} m/s")
    agrees = abs(d_along) <= 2e3 and abs(d_alt) <= 20.0
    paths = swarm_case_plots({"planned": ev.history[0]}, HISTORY_COLUMNS, out_dir, limits=plan.problem.vehicle.limits,
                             flown={"flown": res.trajectory}, title=f"{scenario.name}: sigma_0 = {plan.sigma0_deg:.3f} deg")
    target = (scenario.target.longitude_deg, scenario.target.latitude_deg)
    paths += trajectory_plots(res.trajectory, out_dir, limits=plan.problem.vehicle.limits, target=target,
                              title=f"{scenario.name}: Drake closed loop")
    print(f"wrote {len(paths)} plots to {out_dir}")
    if not plan.success:
        print(f"drake-entry: the plan is not verified: {plan.message}", file=sys.stderr)
    if not agrees:
        print("drake-entry: the Drake flight departs from the plan by more than 2 km / 20 m", file=sys.stderr)
    return 0 if plan.success and agrees else 1
