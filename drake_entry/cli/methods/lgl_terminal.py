"""``drake-entry plan`` for paper 002's terminal guidance: the pre-flight LGL solution of the
scenario's problem, verified (between the nodes, its controls propagated) and flown through the
closed loop's actuators into the acceptance box; printed, plotted (paper 002 Figs. 1-10 with the
Drake propagation) and written to ``plan.json``. CLI layer (it flies diagrams)."""
from __future__ import annotations

import math

from drake_entry.cli.common import write_plan_report
from drake_entry.models.verdict import box_text

__all__ = ["plan_report"]


def plan_report(scenario, out_dir: str) -> int:
    """Exit 0 when the plan is a success (solver converged, verified, and its bank and alpha,
    flown through the actuators, end inside the acceptance box with every path limit held); 1
    otherwise."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.guidance.lgl_terminal.method import METHOD
    from drake_entry.planning.nlp.plots import nlp_solution_plots

    plan = METHOD.make_planner(scenario, fly_controls)
    r = plan.result
    print(f"{scenario.name}: {r.nodes} LGL nodes, {r.solver}, J = {r.objective:.4f}, t_f = {r.final_time:.1f} s, "
          f"{r.total_time:.1f} s")
    print(f"NLP: {r.message}")
    summary = {"scenario": scenario.name, "success": bool(plan.success), "message": plan.message,
               "objective": float(r.objective), "final_time_s": r.final_time, "nodes": r.nodes,
               "solve_wall_s": r.total_time, "verification": r.verification.as_dict() if r.verification else None}
    paths = []
    if plan.flight is not None:
        f = plan.flight
        tr = f.trajectory
        xf = tr.state[-1]
        summary["actuator_flight"] = {
            "failure": f.failure, "box": f.box, "ok": f.ok,
            "final_state": {"altitude_m": float(xf[0]), "longitude_deg": math.degrees(xf[1]),
                            "latitude_deg": math.degrees(xf[2]), "velocity_m_s": float(xf[3]),
                            "flight_path_deg": math.degrees(xf[4]), "alpha_deg": math.degrees(tr.alpha[-1])},
            "path_limits": [{"name": c.limit.name, "peak": c.peak, "margin": c.margin, "held": c.held}
                            for c in f.checks]}
        print(f"flown through the actuators to t_f: {f.text()}")
        print("  " + "; ".join(f"{k} {b['error'] / _unit(k):+.4g}" + ("" if b["inside"] else f" ({box_text(k, b)})")
                               for k, b in f.box.items()))
        print("  path limits: " + "; ".join(f"{c.limit.name} margin {100 * c.margin:+.1f} %" for c in f.checks))
    if r.verification is not None and r.verification.flight is not None:
        paths = nlp_solution_plots(r.problem, r, out_dir, propagated=r.verification.flight,
                                   title=f"{scenario.name}: pre-flight LGL plan")
    return write_plan_report(out_dir, summary, paths, plan.success, f"the plan is not a success: {plan.message}")


def _unit(name: str) -> float:
    """Display divisor of a box error (SI to the printed unit: m, m/s, deg)."""
    return math.pi / 180.0 if name in ("flight_path", "alpha") else 1.0
