"""Example 4: your own vehicle (an aerodynamic table CSV and a vehicle YAML) in your own
atmosphere (a tabulated density and temperature profile), flown open loop and planned with
the drag-energy planner (paper 000), then flown closed loop.

The files written here stand for what you would bring: ``my_aero.csv`` (C_L and C_D on an
alpha x Mach grid, e.g. from CFD or wind-tunnel data), ``my_vehicle.yaml`` (mass, area, nose
radius, limits) and ``my_atmosphere.csv`` (altitude, density, temperature, e.g. from GRAM or
NRLMSIS). To keep the example self-contained they are made from the HORUS-2B data with a
heavier vehicle and an atmosphere 8 % denser than US76 between 20 and 120 km.

    python examples/04_custom_vehicle.py [--quick] [--out out/examples/04]
"""
import math
import os

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import fly
from drake_entry.diagrams.open_loop import simulate
from drake_entry.guidance.drag_energy.planner import DragEnergyPlanner
from drake_entry.guidance.drag_energy.plots import corridor_plot
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.vehicles import load_vehicle
from drake_entry.scenario import load_scenario

VEHICLE_YAML = """\
name: my_glider
description: "a user's lifting vehicle (example 4)"
source: "example 4: HORUS-2B aerodynamics sampled into a table, 10 % heavier"
mass_kg: 28632.0
reference_area_m2: 110.0
nose_radius_m: 0.8
default_aero: cfd
aero:
  cfd:
    model: table
    table_csv: {table}              # wide CSV: coefficient, alpha_deg, M<mach>, ...
    source: "example table"
heat_flux:
  form: chapman
heat_flux_max_kW_m2: 600.0
dynamic_pressure_max_kPa: 12.0
normal_load_max_g: 2.5
bank_limit_deg: 89.0
bank_rate_limit_deg_s: 20.0
bank_accel_limit_deg_s2: 10.0
"""


def write_aero_table(path: str) -> None:
    """C_L, C_D on a grid, in the layout ``read_wide_table`` reads (one row per coefficient
    and angle of attack, one column per Mach number)."""
    aero = load_vehicle("horus2b").aero
    alphas, machs = np.arange(0.0, 46.0, 5.0), [1.2, 1.5, 2.0, 3.0, 5.0, 8.0, 12.0, 16.0, 20.0, 25.0]
    lines = ["coefficient,alpha_deg," + ",".join(f"M{m:g}" for m in machs)]
    for k, name in enumerate(("CL", "CD")):
        for a in alphas:
            values = [aero.coefficients(math.radians(a), float(m))[k] for m in machs]
            lines.append(f"{name},{a:g}," + ",".join(f"{float(v):.5f}" for v in values))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_atmosphere_table(path: str) -> None:
    """altitude_m, density_kg_m3, temperature_K every km from 0 to 150 km."""
    h = np.arange(0.0, 150001.0, 1000.0)
    rho, T, _ = US76Atmosphere().properties(h)
    rho = rho * np.where((h >= 20e3) & (h <= 120e3), 1.08, 1.0)
    with open(path, "w") as f:
        f.write("# example 4: US76, 8 % denser between 20 and 120 km\naltitude_m,density_kg_m3,temperature_K\n")
        f.writelines(f"{a:.0f},{r:.6e},{t:.3f}\n" for a, r, t in zip(h, rho, T))


def main(quick: bool = False, out_dir: str = "out/examples/04") -> dict:
    os.makedirs(out_dir, exist_ok=True)
    table, atmosphere_csv = os.path.join(out_dir, "my_aero.csv"), os.path.join(out_dir, "my_atmosphere.csv")
    write_aero_table(table)
    write_atmosphere_table(atmosphere_csv)
    vehicle_yaml = os.path.join(out_dir, "my_vehicle.yaml")
    with open(vehicle_yaml, "w") as f:
        f.write(VEHICLE_YAML.format(table=os.path.abspath(table)))

    # the HORUS-2B mission with our vehicle and atmosphere (a scenario YAML can say the same:
    # vehicle: path/to/my_vehicle.yaml; atmosphere: {model: table, table_csv: path/to/my_atmosphere.csv})
    scenario = load_scenario("horus2b")
    scenario.name = "my_glider"
    scenario.vehicle = vehicle_yaml
    scenario.aero = ""  # the vehicle file's default_aero
    scenario.atmosphere.model, scenario.atmosphere.table_csv = "table", atmosphere_csv
    scenario.validate()

    # 1. open loop: the scenario's alpha(E) and bank(t) schedules
    if quick:
        scenario.simulation.max_time_s = 400.0
    tr = simulate(scenario)
    print(f"open loop: {tr.reason} at t = {tr.time[-1]:.0f} s, h = {tr.state[-1, 0] / 1e3:.1f} km, "
          f"peak heat flux {tr.column('heat_flux').max() / 1e3:.0f} kW/m^2")

    # 2. the drag-energy planner (paper 000): its corridor for this vehicle and atmosphere, and
    #    a reference planned from the open-loop state at 350 s (after the drag stops rising)
    planner = DragEnergyPlanner.from_scenario(scenario)
    x = tr.state[np.searchsorted(tr.time, min(350.0, tr.time[-1]))]
    reference = planner.plan_from_state(x)
    print(f"plan from t = 350 s: {reference.message}; {reference.problem.n_nodes} nodes, "
          f"solve {1e3 * reference.solve_time:.1f} ms, range to go {reference.problem.range_to_go / 1e3:.0f} km")
    paths = corridor_plot(planner.corridor, scenario.entry_energy(), planner.E_final, out_dir, reference=reference,
                          title="my_glider: drag-energy corridor and reference")

    # 3. the closed loop (the full flight; skipped in quick mode)
    result = None
    if not quick:
        scenario.simulation.max_time_s = load_scenario("horus2b").simulation.max_time_s
        result = fly(scenario)
        print(f"closed loop: {result.message}")
    print(f"wrote {', '.join(paths)}")
    return {"open_loop": tr, "reference": reference, "closed_loop": result}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 04: your vehicle in your atmosphere")
    ref = r["reference"]
    c.check("the reference planned from 350 s is optimal and inside the corridor", ref.success and
            ref.corridor_violation()["above_max"] < 0.02, ref.message)
    if quick:
        c.check("the open loop flies the first 400 s", abs(r["open_loop"].time[-1] - 400.0) < 1e-6)
    else:
        c.check("the open loop reaches Mach 2.5", "mach" in r["open_loop"].reason, r["open_loop"].reason)
        cl = r["closed_loop"]
        c.check("the closed loop lands inside the 2-km box within every path limit", cl.success, cl.message)
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/04",
                                 quick="400 s of open loop, no closed loop"))
