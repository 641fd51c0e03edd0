"""drake-entry: plan, fly and analyse atmospheric-entry trajectories on Drake.

Commands:
  simulate SCENARIO   fly the open-loop diagram; write the trajectory and PNG plots
  fit-horus           refit the HORUS-2B aero forms (paper 000 eqs. 32-33); print residuals
  bench               time the Drake open-loop HORUS flight against scipy solve_ivp
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

from .errors import ScenarioError


def _cmd_simulate(args) -> int:
    from diagrams.open_loop import simulate

    from .plots import trajectory_plots
    from .results import write_table
    from .scenario import load_scenario

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
        "distance_to_target_km": float(dist / 1e3),
        "peak_heat_flux_kW_m2": float(tr.column("heat_flux").max() / 1e3),
        "peak_dynamic_pressure_kPa": float(tr.column("dynamic_pressure").max() / 1e3),
        "peak_normal_load_g": float(tr.column("normal_load").max()),
        "wall_time_s": tr.wall_time,
    }
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    for k, v in summary.items():
        print(f"{k:28s} {v:.6g}" if isinstance(v, float) else f"{k:28s} {v}")
    print(f"wrote {path} and {len(pngs)} plots to {args.out}")
    return 0


def _cmd_fit_horus(args) -> int:
    from .aerodynamics import fit_horus_forms
    from .vehicles import load_vehicle

    rep = fit_horus_forms(initial_aL=load_vehicle("horus2b").aero.aL)
    print("least-squares fit of paper 000 eqs. 32-33 to the clean, untrimmed M-692 cells")
    print(f"C_D: {rep.cells_CD} cells, RMS {rep.rms_CD:.4f}, max |residual| {rep.max_CD:.4f}")
    print(f"C_L: {rep.cells_CL} cells, RMS {rep.rms_CL:.4f}, max |residual| {rep.max_CL:.4f}")
    print("aD =", [float(f"{v:.10g}") for v in rep.aD])
    print("aL =", [float(f"{v:.10g}") for v in rep.aL])
    return 0


def _cmd_bench(args) -> int:
    from .benchmark import open_loop_benchmark

    open_loop_benchmark(repeats=args.repeats)
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="drake-entry", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("simulate", help="fly the open-loop diagram of a scenario")
    p.add_argument("scenario", help="packaged scenario name (horus2b, shefex3, cav_h, marv) or a YAML path")
    p.add_argument("--out", default="out/simulate", help="output directory")
    p.add_argument("--format", choices=("parquet", "csv"), default="parquet")
    p.set_defaults(func=_cmd_simulate)
    f = sub.add_parser("fit-horus", help="refit paper 000 eqs. 32-33 to the M-692 table; print residuals")
    f.set_defaults(func=_cmd_fit_horus)
    b = sub.add_parser("bench", help="Drake open loop vs scipy solve_ivp, side by side")
    b.add_argument("--repeats", type=int, default=3)
    b.set_defaults(func=_cmd_bench)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ScenarioError as e:
        print(f"drake-entry: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
