"""Example 19: guidance computing latency. Paper 000's drag-energy guidance on HORUS-2B re-plans
its drag profile on board every 20 s; a flight computer needs time to compute each plan. With
``guidance.replan_latency_s`` a plan computed from the estimate at t flies from t + latency (at
the first guidance update at or after it), the plan in use flying on meanwhile; the same field
works for every method that plans on board (SCvx, LGL terminal, the swarm bank re-solved on
board, FNPEG's corrector: systems/replan_scheduler.py).

The nominal HORUS-2B flight is flown with latencies of 0, 5 and 15 s (``--quick``: 0 and 5 s).
The figure shows the drag each flight tracks and the bank it flies; the claims check that
engagement (the first plan in use) comes exactly one latency later and that every flight
reaches its terminal interface.

    python examples/19_computing_latency.py [--quick] [--out out/examples/19]
"""
import dataclasses as dc

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
from drake_entry.figures import plt, save_figure
from drake_entry.scenario import load_scenario


def main(quick: bool = False, out_dir: str = "out/examples/19") -> dict:
    scenario = load_scenario("horus2b")
    setup = ClosedLoopSetup.from_scenario(scenario)  # the planner (corridor) built once
    flights = {}
    for latency in (0.0, 5.0) if quick else (0.0, 5.0, 15.0):
        variant = dc.replace(setup, scenario=dc.replace(scenario, guidance=dc.replace(
            scenario.guidance, replan_latency_s=latency)))
        r = fly(variant)
        flights[latency] = r
        g = r.guidance
        print(f"latency {latency:4.1f} s: {r.message or 'success'}; engaged at {g.fields['engaged_at_s']:.0f} s, "
              f"{g.plans} plans, miss {r.errors['distance_m'] / 1e3:.2f} km")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for latency, r in flights.items():
        tr = r.trajectory
        ax1.plot(tr.time, tr.column("drag"), lw=1, label=f"latency {latency:g} s")
        ax2.plot(tr.time, np.degrees(tr.column("bank")), lw=1, label=f"latency {latency:g} s")
    ax1.set(xlabel="time [s]", ylabel="sensed drag [m/s^2]", title="drag flown")
    ax2.set(xlabel="time [s]", ylabel="bank [deg]", title="bank flown (reversals signed)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    path = save_figure(fig, out_dir, "computing_latency.png",
                       title="HORUS-2B nominal, drag-energy guidance re-planned every 20 s: computing latency",
                       caption="Look at: engagement and every re-planned profile arrive one latency later; the plan "
                               "in use flies on meanwhile.")
    return {"flights": flights, "plot": path}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 19: guidance computing latency")
    flights = r["flights"]
    base = flights[0.0].guidance.fields["engaged_at_s"]
    for latency, f in flights.items():
        engaged = f.guidance.fields["engaged_at_s"]
        c.check(f"latency {latency:g} s: the first plan flies exactly one latency after engagement's plan",
                abs(engaged - (base + latency)) < 1e-9, f"engaged at {engaged:.1f} s (without latency {base:.1f} s)")
        c.check(f"latency {latency:g} s: the flight reaches its terminal interface", bool(f.reached),
                f"miss {f.errors['distance_m'] / 1e3:.2f} km")
    c.check("the figure is written", bool(r["plot"]), r["plot"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/19", quick="latencies 0 and 5 s only"))
