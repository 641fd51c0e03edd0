"""Example 23: your own vehicle and mission, every guidance method, one command.

Writes what a new user writes from scratch, three files in one folder:

- ``glider.yaml``: a Shuttle-class winged glider with polynomial aerodynamics and its own limits
  (representative numbers: L/D 1.0 at 40 deg, 1.7 at 15 deg; not Space Shuttle data);
- ``glider_taem.yaml``: a mission from a Pacific entry interface to a TAEM box 6300 km down-range
  (25 +- 2 km, Mach 2.5 +- 0.5, 5 km from the target), alpha scheduled in Mach, entry dispersions;
  it names the vehicle as ``glider.yaml`` (read beside the mission file, from any directory);
- nothing else: no guidance block and no comparison file.

Then flies the mission alone as a comparison, ``drake-entry compare FOLDER/glider_taem.yaml``:
every registered method derives its settings from the mission (the box centre, the alpha schedule
rewritten in its variable, the vehicle's limits with a margin) and searches its free ones on the
nominal entry and two dispersed draws of a seed of its own, or says why it cannot fly the mission;
then each flies a Monte-Carlo campaign with the same seed, into one report.

    python examples/23_your_mission_every_method.py [--quick] [--runs N] [--out out/examples/23]

--quick flies FNPEG alone on 4 samples (the others listed as not selected).
"""
import json
import os

from drake_entry.claims import Claims, run_example
from drake_entry.comparison.report import summary_text
from drake_entry.comparison.runner import run_comparison
from drake_entry.comparison.spec import load_comparison_or_mission
from drake_entry.guidance import REGISTRY, folder_of

SEED = 2026

VEHICLE = """\
# A Shuttle-class winged glider written from scratch: representative polynomial aerodynamics
# (not Space Shuttle data), its own limits.
name: glider
description: "Shuttle-class winged glider, representative polynomial aerodynamics"
representative: true
source: "a user's representative numbers (L/D 1.0 at 40 deg, 1.7 at 15 deg)"
mass_kg: 92000.0
reference_area_m2: 249.9
nose_radius_m: 1.0
default_aero: poly
aero:
  poly:
    model: polynomial        # rows: powers of alpha [deg]; columns: powers of 1/M
    CL: [[-0.05], [0.0225]]
    CD: [[0.06], [0.0], [0.00049]]
heat_flux:
  form: chapman
heat_flux_max_kW_m2: 650.0
dynamic_pressure_max_kPa: 16.0
normal_load_max_g: 2.5
bank_limit_deg: 80.0
bank_rate_limit_deg_s: 10.0
bank_accel_limit_deg_s2: 5.0
"""

MISSION = """\
# A Pacific entry to a TAEM box 6300 km down-range, alpha scheduled in Mach; no guidance block:
# every method derives its settings from this mission.
name: glider_taem
description: "Shuttle-class glider from a Pacific entry interface to a TAEM box over the runway"
vehicle: glider.yaml
planet: {model: spherical, rotating: true, j2: false}
atmosphere: {model: us76}
entry: {altitude_km: 121.9, longitude_deg: -164.22, latitude_deg: -1.57, velocity_m_s: 7450.0,
        flight_path_deg: -1.2, heading_deg: 45.3}
target: {longitude_deg: -117.9, latitude_deg: 34.9}
terminal: {altitude_km: 25.0, mach: 2.5, altitude_tolerance_km: 2.0, mach_tolerance: 0.5,
           distance_tolerance_km: 5.0}
alpha: {variable: mach, breakpoints: [3.0, 10.0], values_deg: [15.0, 40.0], smooth: true}
bank: {variable: time, breakpoints: [0.0], values_deg: [50.0]}   # open-loop runs only
dispersions:
  source: "entry interface, uniform (a user's choice)"
  entry:
    altitude_m: !Uniform {min: -250.0, max: 250.0}
    velocity_m_s: !Uniform {min: -15.0, max: 15.0}
    flight_path_deg: !Uniform {min: -0.02, max: 0.02}
    heading_deg: !Uniform {min: -0.05, max: 0.05}
simulation: {max_time_s: 3000.0, closed_loop_step_s: 0.5}
"""


def write_mission(folder: str) -> str:
    """The user's two files in ``folder``; the mission file's path."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "glider.yaml"), "w") as f:
        f.write(VEHICLE)
    path = os.path.join(folder, "glider_taem.yaml")
    with open(path, "w") as f:
        f.write(MISSION)
    return path


def main(quick: bool = False, out_dir: str = "out/examples/23", runs: int = 20) -> dict:
    mission = write_mission(os.path.join(out_dir, "mission"))
    comparison = load_comparison_or_mission(mission)
    runs = 4 if quick else runs
    only = ["fnpeg"] if quick else None
    print(f"drake-entry compare {mission} --runs {runs} --seed {SEED}" + (" --only fnpeg" if quick else ""))
    report = run_comparison(comparison, runs=runs, out_dir=os.path.join(out_dir, "compare"), seed=SEED, only=only)
    folder = os.path.dirname(report)
    with open(os.path.join(folder, "comparison_summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(folder, "comparison.json")) as f:
        manifest = json.load(f)
    print("\n" + summary_text(summary))
    fnpeg = manifest["methods"]["fnpeg"].get("derivation", {})
    print("\nFNPEG's settings, derived:", json.dumps(fnpeg.get("chosen", {})))
    return {"summary": summary, "manifest": manifest, "report": report, "runs": runs, "quick": quick,
            "mission": comparison.mission}


def check(r: dict, quick: bool = False) -> Claims:
    c = Claims("example 23: your vehicle and mission, every method")
    s, m, n = r["summary"], r["manifest"], r["runs"]
    labels = {folder_of(spec) for spec in REGISTRY}
    c.check("every registered method is in the comparison, flown or not with its reason",
            set(m["methods"]) == labels, ", ".join(sorted(m["methods"])))
    derived = m["methods"]["fnpeg"].get("derivation") or {}
    c.check("FNPEG's settings were derived from the mission and searched by flying",
            bool(derived.get("choices")) and bool(derived.get("trials")),
            f"{len(derived.get('trials', []))} candidates flown; kept {derived.get('chosen')}")
    f = s["methods"].get("fnpeg", {})
    c.check("FNPEG with derived settings succeeds on every sample of the user's mission",
            f.get("successful") == n and f.get("samples") == n, f"{f.get('successful')} of {f.get('samples')}")
    cannot = [label for label, reason in s["not_flown"].items() if reason.startswith("cannot fly this mission")]
    c.check("the methods that cannot fly it say why with the mission's figures",
            all(len(s["not_flown"][label]) > 60 for label in cannot),
            f"{len(cannot)} refused: {', '.join(cannot)}")
    if quick:  # the others derive their settings from the mission and are not selected
        waiting = set(s["not_flown"]) - set(cannot)
        c.check("the methods not selected say that their settings derive from the mission",
                all(s["not_flown"][label].startswith("yet to fly in this directory") for label in waiting)
                and {"lgl_terminal", "ampi"} <= waiting, ", ".join(sorted(waiting)))
    if not quick:
        c.check("every method that flew drew the same dispersions", s["same_dispersions"],
                f"{s['samples_compared']} samples compared")
    c.check("the report is written, with the searches", os.path.exists(r["report"]) and
            "Settings derived from the mission" in open(r["report"]).read(), r["report"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/23", quick="FNPEG alone, 4 samples",
                                 options=[("--runs", {"type": int, "default": 20,
                                                      "help": "samples per method (default: 20)"})]))
