"""Example 15: FNPEG, the field's baseline predictor-corrector (Lu 2014), on Lu's orbital CAV-H case.

Flies the packaged ``cav_h_fnpeg`` scenario (entry 121.9 km, 7400 m/s; the aim point 50 nmi
short of the site 65.7 E, 31.6 N; terminal 28 km, 2000 m/s) three ways, as Lu 2014 does:

  1. with the phugoid-damping altitude-rate feedback (the packaged scenario),
  2. without it (damping gain 0),
  3. constrained: heat rate <= 4315 kW/m^2 and load <= 1.8 g, enforced by the path-limit feedback
     (gain 40; the load at 1.7 g and the heat rate at 4200 kW/m^2, margins found by flying) and judged against those limits,

and prints each flight's terminal errors and peaks beside Lu's published figures (Lu 2014:
range error under 1 km; peaks without -> with damping: heat rate 7022.7 -> 4704.5 kW/m^2,
load 3.5 -> 1.56 g, q 158.0 -> 68.5 kPa). Lu's aerodynamic tables and alpha profile are not
public here: the CAV-H fit and this library's alpha profile stand in (docs/methods/fnpeg.md), so
the peaks are compared in kind (damping lowers them), not to the digit.

    python examples/15_fnpeg_cav_h.py [--quick] [--out out/examples/15]

--quick flies the first two cases to 900 s only (through the first pull-out and the first phugoid
dip, where the unconstrained peaks are) with a correction every 5 s instead of every second.
"""
import math
import os
import time

from drake_entry.campaign.sample import campaign_row
from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
from drake_entry.figures import plt, save_figure
from drake_entry.scenario import apply_overrides, load_scenario

#: Lu 2014's published CAV-H orbital-case figures (without, with phugoid damping)
LU_PEAKS = {"heat rate [kW/m^2]": (7022.7, 4704.5), "load [g]": (3.5, 1.56), "q [kPa]": (158.0, 68.5)}
#: the constrained run's limits (Lu 2014)
HEAT_LIMIT_KW_M2, LOAD_LIMIT_G = 4315.0, 1.8
#: the load the constrained run's feedback enforces [g], a margin under LOAD_LIMIT_G
GUIDANCE_LOAD_LIMIT_G = 1.7
#: the heat rate it enforces [kW/m^2], a margin under HEAT_LIMIT_KW_M2: enforcing 4315 itself let the
#: pull-out's peak through by 1.1 % (4361 kW/m^2 at t = 745 s), 4215 held it at 4288 (docs/methods/fnpeg.md)
GUIDANCE_HEAT_LIMIT_KW_M2 = 4200.0

CASES = {
    "with damping": {},
    "without damping": {"guidance.damping_gain": 0.0},
    # the guidance enforces 1.7 g to hold the vehicle's 1.8 g: enforcing 1.8 g itself let the end game's
    # dive through by 0.7 % (1.813 g in the last 11 s; docs/methods/fnpeg.md)
    "constrained": {"guidance.path_gain": 40.0, "guidance.heat_rate_limit_kW_m2": GUIDANCE_HEAT_LIMIT_KW_M2,
                    "guidance.load_limit_g": GUIDANCE_LOAD_LIMIT_G,
                    "vehicle_limits": {"heat_flux_max_kW_m2": HEAT_LIMIT_KW_M2, "total_load_max_g": LOAD_LIMIT_G,
                                       "dynamic_pressure_max_kPa": 100.0, "bank_rate_limit_deg_s": 10.0,
                                       "bank_accel_limit_deg_s2": 5.0}},
}


def fly_case(overrides: dict, quick: bool):
    scenario = load_scenario("cav_h_fnpeg")
    apply_overrides(scenario, {**overrides, **({"guidance.replan_period_s": 5.0} if quick else {})})
    if quick:
        scenario.simulation.max_time_s = 900.0
    setup = ClosedLoopSetup.from_scenario(scenario)
    t0 = time.perf_counter()
    result = fly(setup)
    row = campaign_row(result, setup)
    row["wall_s"] = time.perf_counter() - t0
    return result, row


def main(quick: bool = False, out_dir: str = "out/examples/15") -> dict:
    flights, rows = {}, {}
    cases = {k: v for k, v in CASES.items() if not quick or k != "constrained"}
    for name, overrides in cases.items():
        flights[name], rows[name] = fly_case(overrides, quick)
        r = rows[name]
        print(f"{name:16s} {flights[name].message}")
        print(f"{'':16s} range error {r['err_range_m'] / 1e3:+.2f} km, crossrange {r['err_crossrange_m'] / 1e3:+.2f} km, "
              f"altitude {r['err_altitude_m'] / 1e3:+.2f} km, speed {r['err_velocity_m_s']:+.1f} m/s; "
              f"{r['plans']} corrections, {r['predictions']} predictions, {r['wall_s']:.0f} s")
    peaks = {name: {"heat rate [kW/m^2]": r["peak_heat_flux_W_m2"] / 1e3, "load [g]": r["peak_total_load_g"],
                    "q [kPa]": r["peak_dynamic_pressure_Pa"] / 1e3} for name, r in rows.items()}
    print(f"\n{'peak':20s} {'Lu without':>11s} {'ours without':>13s} {'Lu with':>9s} {'ours with':>10s} "
          f"{'ours constrained':>17s}")
    for k, (lu_without, lu_with) in LU_PEAKS.items():
        constrained = peaks["constrained"][k] if "constrained" in peaks else math.nan
        print(f"{k:20s} {lu_without:11.1f} {peaks['without damping'][k]:13.1f} {lu_with:9.1f} "
              f"{peaks['with damping'][k]:10.1f} {constrained:17.1f}")

    os.makedirs(out_dir, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    styles = {"with damping": "-", "without damping": "--", "constrained": "-."}
    for name, res in flights.items():
        tr = res.trajectory
        t = tr.time
        axes[0].plot(tr.state[:, 3] / 1e3, tr.state[:, 0] / 1e3, styles[name], label=name)
        axes[1].plot(t, tr.column("heat_flux") / 1e3, styles[name], label=name)
        axes[2].plot(t, tr.column("total_load"), styles[name], label=name)
    if "constrained" in flights:
        axes[1].axhline(HEAT_LIMIT_KW_M2, color="r", lw=0.8, label=f"constrained limit {HEAT_LIMIT_KW_M2:.0f} kW/m$^2$")
        axes[2].axhline(LOAD_LIMIT_G, color="r", lw=0.8, label=f"constrained limit {LOAD_LIMIT_G} g")
    axes[0].set(xlabel="speed [km/s]", ylabel="altitude [km]", title="altitude-velocity")
    axes[1].set(xlabel="time [s]", ylabel="heat rate [kW/m$^2$]", title="stagnation heat rate")
    axes[2].set(xlabel="time [s]", ylabel="aerodynamic load [g]", title="total load")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("FNPEG on Lu (2014)'s CAV-H orbital case" + (" (first 900 s, corrections every 5 s)" if quick else ""))
    path = save_figure(fig, out_dir, "fnpeg_cav_h.png",
                       caption="Look at: without damping the glide oscillates (phugoid) and the first pull-out peaks "
                               "higher" + ("." if quick else "; the constrained flight stays under its red limits."))
    print(f"wrote {path}")
    return {"rows": rows, "peaks": peaks, "success": {k: f.success for k, f in flights.items()}, "plot": path}


def check(r: dict, quick: bool = False) -> Claims:
    c = Claims("example 15: FNPEG on Lu's CAV-H case")
    p, rows = r["peaks"], r["rows"]
    for k in LU_PEAKS:
        c.check(f"the phugoid damping lowers the peak {k} (as in Lu 2014)", p["with damping"][k] < p["without damping"][k],
                f"{p['without damping'][k]:.1f} -> {p['with damping'][k]:.1f}")
    if not quick:
        c.check("the constrained flight holds heat rate <= 4315 kW/m^2 and load <= 1.8 g",
                p["constrained"]["heat rate [kW/m^2]"] <= HEAT_LIMIT_KW_M2 and p["constrained"]["load [g]"] <= LOAD_LIMIT_G,
                f"{p['constrained']['heat rate [kW/m^2]']:.0f} kW/m^2, {p['constrained']['load [g]']:.2f} g")
        w = rows["with damping"]
        c.check("the packaged flight is a success (aim point within 5 km, 28 +- 3 km, every limit held)",
                r["success"]["with damping"], f"{w['err_distance_m'] / 1e3:.2f} km from the aim point")
        c.check("the constrained flight is a success", r["success"]["constrained"],
                f"{rows['constrained']['err_distance_m'] / 1e3:.2f} km")
    c.check("the plot is written", os.path.exists(r["plot"]), r["plot"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/15",
                                 quick="fly two cases to 900 s, correcting every 5 s"))
