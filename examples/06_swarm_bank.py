"""Example 6: paper 004's guidance on CAV-H: search sigma_0 of eq. 17 with pigeon-inspired
optimisation (and, for comparison, a bracketed root search), fly the answer in the Drake
closed loop, and compare the flight with the planner's trajectory.

The planner's evaluator is a vectorised replica of the closed loop (same law, actuators and
reversal sampling), so the Drake flight ends where the plan does. The scenario
``cav_h_paper004`` carries a labelled substitute target (paper 004 prints none).

    python examples/06_swarm_bank.py [--quick] [--out out/examples/06]
"""
import os

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import fly
from drake_entry.figures import plt, save_figure
from drake_entry.guidance.swarm_bank.evaluator import range_error
from drake_entry.guidance.swarm_bank.search import problem_from_scenario, search
from drake_entry.scenario import load_scenario


def main(quick: bool = False, out_dir: str = "out/examples/06") -> dict:
    scenario = load_scenario("cav_h_paper004")
    problem = problem_from_scenario(scenario)

    # 1. searches for sigma_0 on J of eq. 32 (each flies whole populations of trajectories)
    methods = ("secant",) if quick else ("secant", "pio")
    found = {m: search(problem, m, seed=0) for m in methods}
    for m, r in found.items():
        print(f"{m:>7s}: sigma_0 = {r.x[0]:.3f} deg, J = {r.J:.4f}, {r.trajectories} trajectories, {r.wall_s:.1f} s")

    # 2. fly the best answer in the Drake closed loop (the method's planner re-verifies it)
    best = min(found.values(), key=lambda r: r.J)
    scenario.guidance.bank_start_deg = float(best.x[0])
    result = fly(scenario)
    plan = result.guidance.details  # the SwarmPlan: its evaluation holds the planned trajectory
    x = result.trajectory.state[-1]
    ds, cross = range_error(plan.problem, x[1], x[2])
    print(f"plan: {plan.message}")
    print(f"Drake closed loop: {result.message}")
    print(f"flown minus planned at TAEM: along-track {(ds[0] - plan.evaluation.range_error_m[0]):+.1f} m, "
          f"altitude {(x[0] - plan.problem.h_f - plan.evaluation.altitude_error_m[0]):+.2f} m")

    # 3. altitude and bank: plan against flight
    tr = result.trajectory
    planned = plan.evaluate(tr.time[tr.time <= plan.evaluation.time_s[0]])
    os.makedirs(out_dir, exist_ok=True)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    n = len(planned["time_s"])
    ax1.plot(tr.time, tr.state[:, 0] / 1e3, label="Drake closed loop")
    ax1.plot(planned["time_s"], planned["altitude_m"] / 1e3, "--", label="planner (replica)")
    ax1.set(xlabel="time [s]", ylabel="altitude [km]")
    ax1.legend()
    ax2.plot(tr.time, np.degrees(tr.bank), label="bank flown")
    ax2.plot(planned["time_s"], np.degrees(planned["bank_rad"][:n]), "--", label="bank planned")
    ax2.plot(tr.time, np.degrees(tr.alpha), label="alpha flown")
    ax2.set(xlabel="time [s]", ylabel="[deg]")
    ax2.legend()
    fig.suptitle(f"{scenario.name}: sigma_0 = {best.x[0]:.3f} deg by {best.method}")
    path = save_figure(fig, out_dir, "swarm_bank.png")
    print(f"wrote {path}")
    return {"searches": found, "flight": result}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 06: paper 004's bank profile")
    flight = r["flight"]
    plan = flight.guidance.details
    c.check("the plan reaches the TAEM energy inside the path limits", plan.success, plan.message)
    c.check("the Drake closed loop flies it to TAEM inside the box, every path limit held", flight.success,
            flight.message)
    x = flight.trajectory.state[-1]
    dh = x[0] - plan.problem.h_f - plan.evaluation.altitude_error_m[0]
    c.check("the Drake flight ends within 20 m of altitude of the planner's replica", abs(dh) < 20.0, f"{dh:+.2f} m")
    for method, found in r["searches"].items():
        c.check(f"{method} finds sigma_0 = 58.79 deg within 0.05 deg", abs(found.x[0] - 58.79) < 0.05,
                f"{found.x[0]:.3f} deg")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/06",
                                 quick="the bracketed search only (no PIO run)"))
