"""``drake-entry plan`` for paper 001's guidance: the pre-flight SCvx plan from the scenario's entry
state to its site, its bank and alpha flown by the Drake Simulator through the closed loop's
actuators, the comparison printed and plotted, and ``plan.json`` written. CLI layer."""
from __future__ import annotations

from drake_entry.cli.common import write_plan_report

__all__ = ["plan_report"]


def plan_report(scenario, out_dir: str) -> int:
    """Plan, fly the plan's controls, print, plot and write ``plan.json``; exit 0 when the plan
    is verified (converged, its flight within PROPAGATION_TOLERANCE_M of it, inside the DRS box,
    every path limit held), 1 otherwise."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.figures import trajectory_plots
    from drake_entry.guidance.scvx.method import METHOD
    from drake_entry.guidance.scvx.plots import plan_figure

    plan = METHOD.make_planner(scenario, verifier=fly_controls)
    m, flight = plan.metrics, plan.flown
    print(f"SCvx ({plan.formulation}, {plan.problem.mesh.n_nodes} nodes): {plan.message}")
    print(f"heat load {m['heat_load_MJ_m2']:.1f} MJ/m^2, t_f {plan.final_time:.0f} s, {plan.iterations} iterations, "
          f"{plan.build_time + plan.solve_time:.1f} s; max defect {plan.max_defect:.1e}; planned DRS point "
          f"{plan.miss_m / 1e3:.2f} km from the site")
    print(f"paper 001 Table 6 form: integrated |bank rate| {m['bank_effort_deg']:.0f} deg, max "
          f"{m['max_bank_rate_deg_s']:.2f} deg/s; integrated |alpha rate| {m['alpha_effort_deg']:.1f} deg, max "
          f"{m['max_alpha_rate_deg_s']:.3f} deg/s")
    summary = {"scenario": scenario.name, "success": bool(plan.success), "message": plan.message,
               "heat_load_MJ_m2": m["heat_load_MJ_m2"], "final_time_s": plan.final_time,
               "iterations": plan.iterations, "planning_s": plan.build_time + plan.solve_time,
               "max_defect": plan.max_defect, "planned_site_miss_m": plan.miss_m}
    paths = []
    if flight is not None:
        print(f"flown by Drake: {flight.from_plan_m / 1e3:.2f} km from the plan, {flight.from_site_m / 1e3:.2f} km "
              f"from the site; DRS altitude {flight.drs['altitude_m'] / 1e3:.2f} km, Mach {flight.drs['mach']:.2f}; "
              f"DRS box met: {flight.drs_ok}; path limits: {flight.violations_text() or 'all held'}")
        summary.update(flown_from_plan_m=flight.from_plan_m, flown_from_site_m=flight.from_site_m,
                       flown_drs={k: float(v) for k, v in flight.drs.items()}, flown_drs_box_met=bool(flight.drs_ok),
                       flown_within_limits=bool(flight.within_limits), flown_failure=flight.failure)
        mission = plan.problem.mission
        paths.append(plan_figure(plan, flight, mission.site(plan.problem.planet), out_dir,
                                 title=f"{scenario.name}: the SCvx plan and its controls flown by the Drake Simulator"))
        paths += trajectory_plots(flight.trajectory, out_dir, limits=plan.problem.vehicle.limits,
                                  target=(scenario.target.longitude_deg, scenario.target.latitude_deg),
                                  title=f"{scenario.name}: the plan's controls flown")
    return write_plan_report(out_dir, summary, paths, plan.success, f"the plan is not verified: {plan.message}")
