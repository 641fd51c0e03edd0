"""``drake-entry plan`` for paper 003's guidance: the trajectory database checked, the reference
the guidance would make for the scenario's entry state (AMPI or NTT, its TVLQR gains), that
reference's controls flown open loop by the Drake Simulator, printed, plotted and written to
``plan.json``. CLI layer (it flies diagrams)."""
from __future__ import annotations

import math
import os
import sys

import numpy as np

from drake_entry.cli.common import write_plan_report
from drake_entry.models.verdict import box_text

__all__ = ["plan_report"]


def plan_report(scenario, out_dir: str) -> int:
    """Exit 0 when the database is verified and consistent and the reference, flown open loop,
    ends inside the scenario's acceptance box (Scenario.acceptance_box) with every path
    constraint of the database's problem (eq. 3) held; 1 otherwise."""
    from drake_entry.campaign.preparation import prepare
    from drake_entry.guidance.ampi.accuracy_study import fly_ld, reference_errors
    from drake_entry.guidance.ampi.method import METHOD

    prepared = prepare(scenario)  # a mission's own database: built (or found in the cache) first
    if prepared:
        print(prepared)
    planner = METHOD.make_planner(scenario, verifier=None)
    db, problem = planner.database, planner.problem
    print(f"database {scenario.guidance.database}: {planner.message}; {db.n_ld} LD nodes, "
          f"{db.storage_bytes / 1e6:.2f} MB, loaded in {planner.build_time:.2f} s")
    x0 = scenario.initial_state()
    ref = planner.reference(x0)
    syn = ref.synthesis
    offsets = ", ".join(f"{n} {v:+.4g}" for n, v in zip(db.grid.names, ref.offsets))
    print(f"reference ({ref.mode}) for the entry state (offsets from the grid centre, SI/rad: {offsets}): "
          f"t_f {syn.final_time:.1f} s from {len(syn.cases)} stored case(s), {int(syn.extrapolated.sum())} "
          f"extrapolated; synthesis {ref.synthesis_s * 1e3:.1f} ms, TVLQR gains {ref.gains_s:.2f} s")
    # flown as the accuracy study flies a reference: its LD-node polynomial from the entry state
    # with the reference's own initial bank and clock
    at_ld = db.reference(ref.mode, ref.offsets)
    x0 = np.concatenate([x0, [at_ld.states[0, problem.state_names.index("sigma")], 0.0]])
    check = fly_ld(problem, at_ld, db.n_ld, x0, accuracy=1e-9, samples_per_interval=16, log_points=400)
    errors = reference_errors(problem, at_ld, check)
    summary = {"scenario": scenario.name, "database": planner.message, "database_ok": bool(planner.success),
               "mode": ref.mode, "final_time_s": float(syn.final_time), "cases": [int(c) for c in syn.cases],
               "extrapolated": int(syn.extrapolated.sum()), "synthesis_ms": ref.synthesis_s * 1e3,
               "gains_s": ref.gains_s, "flown": errors}
    ok = bool(planner.success)
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    if "failed" in errors:
        print(f"drake-entry: the reference's controls, flown open loop, stopped early: {errors['failed']}",
              file=sys.stderr)
        ok = False
    else:
        peaks = _path_peaks(problem, at_ld, db.n_ld, check)
        xf = check.states[-1]
        h_f = problem.planet.atmospheric_altitude(xf[0], xf[2])
        box = scenario.acceptance_box(problem.planet, xf, mach=xf[3] / float(problem.atmosphere.air_data(h_f)[1]),
                                      distance_m=errors["miss_m"])
        inside = all(b["inside"] for b in box.values())
        held = all(p["held"] for p in peaks.values())
        ok = ok and inside and held
        summary.update(flown_geodetic_altitude_m=float(h_f), box=box, inside_box=inside, path_peaks=peaks,
                       within_limits=held)
        print(f"flown open loop by Drake: {errors['miss_m'] / 1e3:.2f} km from the target, geodetic altitude "
              f"{h_f / 1e3:.2f} km, {errors['altitude_m']:+.1f} m and {errors['velocity_m_s']:+.2f} m/s from the "
              f"reference's end; acceptance box: " + ("inside" if inside else "; ".join(
                  f"{k} {box_text(k, b)}" for k, b in box.items() if not b["inside"])))
        print("path constraints (eq. 3): " + "; ".join(
            f"{n} peak {p['peak']:.4g} of {p['max']:.4g}{'' if p['held'] else ' EXCEEDED'}" for n, p in peaks.items()))
        paths.append(_figure(scenario, problem, syn, check, out_dir))
    return write_plan_report(out_dir, summary, paths, ok, "the reference is not verified (see above)")


def _path_peaks(problem, syn, n_ld: int, check) -> dict:
    """Each path constraint's peak along the flown states (the flown controls at the log
    times), with its upper bound and whether it held."""
    from drake_entry.guidance.ampi.accuracy_study import flown_controls
    from drake_entry.planning.nlp.evaluator import model_values

    controls = flown_controls(problem, syn, n_ld)
    g = model_values(problem, check.states.T, controls(check.time).T)[1]
    return {c.label: {"peak": float(row.max()), "max": float(c.max),
                      "held": bool(row.max() <= c.max and row.min() >= c.min)} for c, row in zip(problem.path, g)}


def _figure(scenario, problem, syn, check, out_dir: str) -> str:
    from drake_entry.figures import plt, save_figure

    names = problem.state_names
    i_lon, i_lat, i_v, i_s = (names.index(n) for n in ("lon", "lat", "V", "sigma"))
    fig, ax = plt.subplots(2, 2, figsize=(11, 7))
    for label, t, x, style in (("reference", syn.time, syn.states, "-"),
                               ("flown (Drake)", check.time, check.states, "--")):
        ax[0, 0].plot(x[:, i_v] / 1e3, x[:, 0] / 1e3, style, label=label)
        ax[0, 1].plot(np.degrees(x[:, i_lon]), np.degrees(x[:, i_lat]), style, label=label)
        ax[1, 0].plot(t, np.degrees(x[:, i_s]), style, label=label)
        ax[1, 1].plot(t, x[:, 0] / 1e3, style, label=label)
    ax[0, 1].plot(scenario.target.longitude_deg, math.degrees(problem.final["lat"]), "r*", ms=12, label="target")
    xl, xh, _, _ = problem.bounds_arrays()
    for value in (xl[i_s], xh[i_s]):
        if np.isfinite(value):
            ax[1, 0].axhline(math.degrees(value), color="r", ls=":", lw=1, label=f"bound {math.degrees(value):g} deg")
    ax[0, 0].set(xlabel="V [km/s]", ylabel="h above the equatorial sphere [km]", title="altitude-velocity")
    ax[0, 1].set(xlabel="longitude [deg]", ylabel="latitude [deg]", title="ground track")
    ax[1, 0].set(xlabel="t [s]", ylabel="bank [deg]", title="bank angle")
    ax[1, 1].set(xlabel="t [s]", ylabel="h above the equatorial sphere [km]", title="altitude (state)")
    for a in ax.flat:
        a.grid(True)
        a.legend(fontsize=8)
    paths = []
    save_figure(fig, out_dir, "reference.png", paths,
                f"{scenario.name}: the database reference and its controls flown open loop by the Drake Simulator")
    return paths[0]
