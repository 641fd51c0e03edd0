"""The flight commands: ``scenarios`` (the packaged scenarios), ``simulate`` (the open-loop
diagram), ``fly`` (one closed-loop flight) and ``plan`` (the guidance method's plan report, found
through the registry in ``drake_entry.cli.methods``)."""
from __future__ import annotations

import json
import os
import sys

import numpy as np

from drake_entry.cli.common import Command, add_overrides_argument, add_scenario_argument, parse_overrides
from drake_entry.errors import ScenarioError

__all__ = ["COMMANDS"]


def simulate(args) -> int:
    from drake_entry.diagrams.open_loop import simulate
    from drake_entry.figures import trajectory_plots
    from drake_entry.models.trajectory import metrics
    from drake_entry.scenario import load_scenario
    from drake_entry.tables import write_table

    scenario = load_scenario(args.scenario)
    tr = simulate(scenario)
    os.makedirs(args.out, exist_ok=True)
    path = write_table(tr.table(), os.path.join(args.out, f"trajectory.{args.format}"))
    vehicle = scenario.make_vehicle()
    pngs = trajectory_plots(tr, args.out, limits=vehicle.limits,
                            target=(scenario.target.longitude_deg, scenario.target.latitude_deg),
                            title=f"{scenario.name}: open loop")
    planet = scenario.make_planet()
    x = tr.state[-1]
    dist = planet.great_circle_distance(x[1], x[2], np.radians(scenario.target.longitude_deg),
                                        np.radians(scenario.target.latitude_deg))
    summary = {
        "scenario": scenario.name, "stop": tr.reason, "flight_time_s": float(tr.time[-1]),
        "final_altitude_km": float(x[0] / 1e3), "final_mach": float(tr.column("mach")[-1]),
        "distance_to_target_km": float(dist / 1e3), **metrics(tr, vehicle.limits), "wall_time_s": tr.wall_time,
    }
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    for k, v in summary.items():
        print(f"{k:28s} {v:.6g}" if isinstance(v, float) else f"{k:28s} {v}")
    print(f"wrote {path} and {len(pngs)} plots to {args.out}")
    return 0


def fly(args) -> int:
    from drake_entry.campaign.preparation import prepare
    from drake_entry.campaign.sample import campaign_row
    from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
    from drake_entry.figures import trajectory_plots
    from drake_entry.scenario import apply_overrides, load_scenario
    from drake_entry.tables import write_table

    scenario = load_scenario(args.scenario)
    apply_overrides(scenario, parse_overrides(args.overrides))
    prepared = prepare(scenario)  # e.g. AMPI's database for this mission: built once, then cached
    if prepared:
        print(prepared)
    setup = ClosedLoopSetup.from_scenario(scenario)
    res = fly(setup)
    tr = res.trajectory
    os.makedirs(args.out, exist_ok=True)
    write_table(tr.table(), os.path.join(args.out, f"trajectory.{args.format}"))
    title = f"{scenario.name}: closed loop ({res.method})"
    trajectory_plots(tr, args.out, limits=setup.vehicle.limits,
                     target=(scenario.target.longitude_deg, scenario.target.latitude_deg), title=title)
    setup.method.flight_plots(res, args.out, title=scenario.name)
    summary = {**campaign_row(res, setup), "wall_time_s": tr.wall_time}  # the row a campaign would record
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2, default=float)
    for k, v in summary.items():
        print(f"{k:28s} {v:.6g}" if isinstance(v, float) else f"{k:28s} {v}")
    print(f"wrote trajectory, summary and plots to {args.out}")
    return 0 if res.success else 1


def plan(args) -> int:
    """A method's plan report is ``plan_report`` in ``drake_entry.cli.methods.<its folder>``."""
    import importlib

    from drake_entry.guidance import folder_of, method_for
    from drake_entry.scenario import load_scenario

    scenario = load_scenario(args.scenario)
    name = f"drake_entry.cli.methods.{folder_of(type(scenario.guidance))}"
    try:
        commands = importlib.import_module(name)
    except ModuleNotFoundError as e:
        if e.name != name:  # a missing import inside the module is a bug: raise it
            raise
        commands = None
    if not hasattr(commands, "plan_report"):
        print(f"drake-entry: guidance method '{method_for(scenario.guidance).name}' has no plan report",
              file=sys.stderr)
        return 2
    return commands.plan_report(scenario, args.out)


def scenarios(args) -> int:
    from importlib import resources

    from drake_entry.scenario import PACKAGED_SCENARIOS, closed_loop_scenarios, load_scenario

    names = list(PACKAGED_SCENARIOS)
    if args.name is not None:
        if args.name not in names:
            raise ScenarioError(f"scenario '{args.name}' is not packaged; packaged: {', '.join(names)}")
        print(resources.files("drake_entry").joinpath(f"scenarios/{args.name}.yaml").read_text(), end="")
        return 0
    rows = []
    closed = closed_loop_scenarios()
    for name in names:
        scenario = load_scenario(name)
        method = f"!{type(scenario.guidance).__name__}" if name in closed else "open loop (simulate)"
        rows.append((name, method, scenario.vehicle, scenario.description))
    widths = [max(len(r[i]) for r in rows + [("name", "guidance", "vehicle", "")]) for i in range(3)]
    print(f"{'name':{widths[0]}}  {'guidance':{widths[1]}}  {'vehicle':{widths[2]}}  description")
    for r in rows:
        print(f"{r[0]:{widths[0]}}  {r[1]:{widths[1]}}  {r[2]:{widths[2]}}  {r[3]}")
    print("\n`drake-entry scenarios NAME` prints one with its comments; a scenario YAML file of your own works "
          "wherever a name does.")
    return 0


def _add_scenarios_arguments(parser) -> None:
    parser.add_argument("name", nargs="?", default=None, help="a packaged scenario to print")


def _add_fly_arguments(parser) -> None:
    add_scenario_argument(parser)
    parser.add_argument("--out", default="out/fly", help="output directory: trajectory table, summary.json, figures")
    parser.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="trajectory table format")
    add_overrides_argument(parser, "guidance.bank_end_deg=45")


def _add_plan_arguments(parser) -> None:
    add_scenario_argument(parser)
    parser.add_argument("--out", default="out/plan", help="output directory: figures and tables of the plan")


def _add_simulate_arguments(parser) -> None:
    add_scenario_argument(parser)
    parser.add_argument("--out", default="out/simulate", help="output directory")
    parser.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="trajectory table format")


COMMANDS = (
    Command("scenarios", "list the packaged scenarios, or print one with its comments", _add_scenarios_arguments,
            scenarios),
    Command("fly", "one closed-loop guided flight (exit 1 when it is not a success)", _add_fly_arguments, fly),
    Command("plan", "the guidance method's plan report, flown by the Drake Simulator (drag-energy: corridor, "
            "reference and extraction, paper 000 Figs. 3-5; SCvx: the pre-flight plan and its flight, paper 001; "
            "AMPI: the database reference for the entry state, paper 003; swarm bank: sigma_0 search, Drake check, "
            "paper 004 figures; LGL terminal: the first solution and its flight, paper 002); exit 1 when it is not "
            "verified", _add_plan_arguments, plan),
    Command("simulate", "fly the open-loop diagram of a scenario", _add_simulate_arguments, simulate),
)
