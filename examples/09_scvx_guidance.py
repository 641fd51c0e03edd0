"""Example 9: paper 001's SCvx as closed-loop guidance (``guidance: !Scvx``): the SPHYNX
nominal mission flown through the shared Drake closed loop (navigation, bank and alpha
actuators), re-planned on board from the navigation estimate every 200 s, then a small
Monte-Carlo campaign of it with its report.

The guidance reads its plan 1 s ahead, the actuators' lag (half the 1-s guidance period for the
sample-and-hold, 1/bandwidth for the loop), so the pre-flight plan alone, flown through the
actuators, already lands inside the 15-km box; read without the lead it ends about 21 km from
the site. Each re-plan starts from the estimated state holding the bank and alpha being flown. The scenario ``sphynx_paper001`` converts paper
001's geodetic Table 1 entry and site; its dispersions are a labelled choice (the paper flies
no Monte-Carlo).

    python examples/09_scvx_guidance.py [--quick] [--out out/examples/09]
"""
import dataclasses as dc
import json
import os

import numpy as np

from drake_entry.campaign.montecarlo import run_campaign
from drake_entry.campaign.report import write_report
from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
from drake_entry.figures import plt, save_figure
from drake_entry.scenario import load_scenario


def main(quick: bool = False, out_dir: str = "out/examples/09") -> dict:
    scenario = load_scenario("sphynx_paper001")
    setup = ClosedLoopSetup.from_scenario(scenario)  # the pre-flight SCvx plan, verified
    plan = setup.planner
    print(f"pre-flight plan: {plan.message}; heat load {plan.objective:.1f} MJ/m^2, t_f {plan.final_time:.0f} s")

    # 1. the nominal flight, re-planned every 200 s, and the pre-flight plan flown alone
    flights = {"re-planned every 200 s": fly(setup)}
    alone = dc.replace(scenario, guidance=dc.replace(scenario.guidance, replan_period_s=0.0))
    flights["pre-flight plan alone"] = fly(dc.replace(setup, scenario=alone))
    no_lead = dc.replace(alone, guidance=dc.replace(alone.guidance, command_lead_s=0.0))
    flights["plan alone, no lead"] = fly(dc.replace(setup, scenario=no_lead))
    for name, r in flights.items():
        print(f"{name:>23s}: {r.message}; {r.guidance.plans} re-plans ({r.guidance.planning_wall_s:.1f} s)")

    os.makedirs(out_dir, exist_ok=True)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    t = np.linspace(0.0, plan.final_time, 400)
    ref = plan.evaluate(t)
    ax1.plot(np.degrees(ref["lon"]), np.degrees(ref["lat"]), "k:", label="pre-flight plan")
    for name, r in flights.items():
        x = r.trajectory.state
        ax1.plot(np.degrees(x[:, 1]), np.degrees(x[:, 2]), label=name)
        ax2.plot(r.trajectory.time, np.degrees(r.trajectory.bank), label=name)
    ax1.plot(scenario.target.longitude_deg, scenario.target.latitude_deg, "r*", ms=12, label="site")
    ax1.set(xlabel="longitude [deg]", ylabel="geocentric latitude [deg]", title="ground tracks")
    ax2.plot(t, np.degrees(ref["bank"]), "k:", label="pre-flight plan")
    ax2.set(xlabel="t [s]", ylabel="bank [deg]", title="bank flown")
    ax1.legend(fontsize=8)
    plot = save_figure(fig, out_dir, "scvx_closed_loop.png")

    # 2. a Monte-Carlo campaign of the guidance through the shared engine (resumable directory)
    runs = 2 if quick else 20
    campaign = run_campaign("sphynx_paper001", runs=runs, out_dir=os.path.join(out_dir, "campaign"), seed=1,
                            progress=not quick)
    report = write_report(campaign)
    with open(os.path.join(campaign, "summary.json")) as f:
        summary = json.load(f)
    print(f"campaign of {runs}: {summary['successful']} successful; report {report}")
    return {"plan": plan, "flights": flights, "plot": plot, "report": report, "campaign": summary,
            "distance_km": {k: r.errors["distance_m"] / 1e3 for k, r in flights.items()}}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 09: SCvx closed-loop guidance")
    c.check("the pre-flight plan is verified by its flight through the actuators", r["plan"].success,
            r["plan"].message)
    for name in ("re-planned every 200 s", "pre-flight plan alone"):
        f = r["flights"][name]
        c.check(f"{name}: reached the DRS altitude inside the 15-km box, every path limit held", f.success, f.message)
    c.check("read without the 1-s lead the plan alone lands outside the box",
            r["distance_km"]["plan alone, no lead"] > 15.0, f"{r['distance_km']['plan alone, no lead']:.1f} km")
    c.check("the re-planned flight re-planned at least 5 times", r["flights"]["re-planned every 200 s"].guidance.plans >= 5,
            f"{r['flights']['re-planned every 200 s'].guidance.plans} re-plans")
    s = r["campaign"]
    c.check("every campaign sample is a success", s["successful"] == s["samples"],
            f"{s['successful']} of {s['samples']}")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/09",
                                 quick="two campaign samples instead of twenty"))
