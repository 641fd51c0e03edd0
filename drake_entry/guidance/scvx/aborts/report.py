"""Report of an abort campaign directory (``guidance.scvx.aborts.study``): counts of feasible aborts at
10 and 40 km, the Tables 4-7 statistics beside paper 001's, and the figures of its Sec. VI
(reachability map coloured by heat load as its Fig. 8, flown miss as its Fig. 13, attitude
as Fig. 7, altitude-speed as Fig. 9; descent aborts: ground tracks as Fig. 14 and the miss by
abort time). Headless (Agg)."""
from __future__ import annotations

import math
import os
import textwrap

import numpy as np

from drake_entry.campaign.store import coverage, read_trajectories
from drake_entry.figures import plt, save_figure
from drake_entry.guidance.scvx.aborts.cases import FEASIBLE_RADII_M, abort_statistics, feasible, statistics_markdown
from drake_entry.models.planet import Earth

__all__ = ["write_abort_report"]


def _geodetic_track(traj: dict, planet: Earth):
    lon = np.degrees(traj["lon"])
    _, lat = planet.geodetic(planet.radius(np.asarray(traj["h"])), np.asarray(traj["lat"]))
    return lon, np.degrees(lat)


def _orbital_figures(rows, trajs, site, out_dir, planet) -> list[str]:
    paths = []
    good = [r for r in rows if feasible(r, FEASIBLE_RADII_M[1])]
    lon = np.array([r["entry_longitude_deg"] for r in rows])
    lat = np.array([r["entry_latitude_deg"] for r in rows])
    for name, key, label in (("reachability_map.png", "heat_load_MJ_m2", "heat load [MJ/m^2]"),
                             ("miss_map.png", "flown_miss_km", "flown miss from the site [km]")):
        fig, ax = plt.subplots(figsize=(7.5, 5))
        for r in good:
            if r["index"] in trajs:
                tl, tb = _geodetic_track(trajs[r["index"]], planet)
                ax.plot(tl, tb, color="0.75", lw=0.6, zorder=1)
        values = [r.get(key, math.nan) for r in good]
        vmin, vmax = (np.nanmin(values), np.nanmax(values)) if good else (0.0, 1.0)
        bad = [i for i, r in enumerate(rows) if not feasible(r, FEASIBLE_RADII_M[1])]
        ax.scatter(lon[bad], lat[bad], marker="x", color="0.4", label="not feasible at 40 km", zorder=2)
        for radius, marker in ((FEASIBLE_RADII_M[0], "o"), (FEASIBLE_RADII_M[1], "s")):
            pick = [i for i, r in enumerate(rows) if feasible(r, radius)
                    and (radius == FEASIBLE_RADII_M[0] or not feasible(r, FEASIBLE_RADII_M[0]))]
            if pick:
                sc = ax.scatter(lon[pick], lat[pick], c=[rows[i].get(key, math.nan) for i in pick], cmap="RdYlGn_r",
                                vmin=vmin, vmax=vmax, marker=marker, edgecolors="k", zorder=3,
                                label=f"feasible at {radius / 1e3:g} km" if radius == FEASIBLE_RADII_M[0]
                                else f"feasible at {radius / 1e3:g} km only")
        if good:
            fig.colorbar(sc, ax=ax, label=label)
        ax.plot(*site, "k*", ms=14, label="site")
        ax.set_xlabel("longitude [deg]")
        ax.set_ylabel("geodetic latitude [deg]")
        ax.grid(True)
        ax.legend(fontsize=8, loc="best")
        save_figure(fig, out_dir, name, paths, "orbital aborts: entry interface points")
    if good:
        fig, axs = plt.subplots(1, 2, figsize=(11, 4))
        fig2, ax2 = plt.subplots(figsize=(6, 4.5))
        for r in good:
            t = trajs.get(r["index"])
            if t is None:
                continue
            axs[0].plot(t["time"], np.degrees(t["bank"]), lw=0.8)
            axs[1].plot(t["time"], np.degrees(t["alpha"]), lw=0.8)
            ax2.plot(np.asarray(t["V"]) / 1e3, np.asarray(t["h"]) / 1e3, lw=0.8)
        for ax, lab in zip(axs, ("bank [deg]", "angle of attack [deg]")):
            ax.set_xlabel("time [s]")
            ax.set_ylabel(lab)
            ax.grid(True)
        ax2.set_xlabel("velocity [km/s]")
        ax2.set_ylabel("altitude [km]")
        ax2.grid(True)
        save_figure(fig, out_dir, "attitude.png", paths, "feasible orbital aborts: planned attitude")
        save_figure(fig2, out_dir, "altitude_velocity.png", paths, "feasible orbital aborts")
    return paths


def _descent_figures(rows, trajs, manifest, out_dir, planet) -> list[str]:
    paths = []
    site = manifest.get("site", [math.nan, math.nan])
    nominal = manifest.get("nominal", {})
    fig, ax = plt.subplots(figsize=(7.5, 5))
    if nominal.get("flown_lon_deg"):
        ax.plot(nominal["flown_lon_deg"], nominal["flown_lat_deg"], "k-", lw=1.5, label="nominal (flown)")
    cmap = plt.get_cmap("viridis")
    t_max = max((r["abort_time_s"] for r in rows), default=1.0)
    for r in rows:
        t = trajs.get(r["index"])
        if t is None:
            continue
        lon, lat = _geodetic_track(t, planet)
        ok = feasible(r, FEASIBLE_RADII_M[1])
        ax.plot(lon, lat, color=cmap(r["abort_time_s"] / t_max) if ok else "0.7", lw=1.0 if ok else 0.6,
                ls="-" if ok else ":")
    ax.plot(*site, "r*", ms=14, label=f"alternative site ({manifest.get('site_name', '')})")
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("geodetic latitude [deg]")
    ax.grid(True)
    ax.legend(fontsize=8)
    save_figure(fig, out_dir, "descent_tracks.png", paths, "descent aborts (colour: abort time; dotted: not feasible)")
    fig, ax = plt.subplots(figsize=(6, 4))
    ta = [r["abort_time_s"] for r in rows]
    ax.semilogy(ta, [max(r.get("planned_miss_km", math.nan), 1e-3) for r in rows], "o", label="planned")
    ax.semilogy(ta, [max(r.get("flown_miss_km", math.nan), 1e-3) for r in rows], "s", mfc="none", label="flown (Drake)")
    for radius in FEASIBLE_RADII_M:
        ax.axhline(radius / 1e3, color="r", ls="--", lw=1)
    ax.set_xlabel("abort time [s]")
    ax.set_ylabel("miss from the alternative site [km]")
    ax.grid(True)
    ax.legend(fontsize=8)
    save_figure(fig, out_dir, "descent_miss.png", paths, "descent aborts")
    return paths


def write_abort_report(out_dir: str, *, figures: bool = True) -> str:
    """Write ``report.md`` (and the figures) into an abort campaign directory; returns its path."""
    cov = coverage(out_dir)
    manifest, rows = cov["manifest"], [cov["rows"][k] for k in sorted(cov["rows"])]
    kind = manifest.get("kind", "orbital_aborts")
    planet = Earth.oblate()
    n = len(rows)
    lines = [f"# {kind.replace('_', ' ').capitalize()}: paper 001 Sec. VI", "",
             f"{n} of {cov['requested']} cases done; plan flies as planned (converged, checked between the "
             f"nodes, flown through the actuators within 5 km of its end, inside its DRS box and every path "
             f"limit; for a minimum-miss abort the box is the opened cone, so this says nothing of reaching "
             f"the site): {sum(bool(r.get('plan_success')) for r in rows)}."]
    for radius in FEASIBLE_RADII_M:
        lines.append(f"Feasible at {radius / 1e3:g} km (plan within the 10-km site radius and its Drake flight "
                     f"within {radius / 1e3:g} km of the site): {sum(feasible(r, radius) for r in rows)}.")
    walls = [r["plan_wall_s"] for r in rows if "plan_wall_s" in r]
    if walls:
        lines.append(f"Plan time per case: mean {np.mean(walls):.1f} s, max {np.max(walls):.1f} s (one core each).")
    if kind == "descent_aborts":
        ok = [r["abort_time_s"] for r in rows if feasible(r, FEASIBLE_RADII_M[1])]
        lines.append(f"Feasible abort times [s]: {', '.join(f'{t:g}' for t in ok) or 'none'} "
                     f"(paper: up to 900 s, 700 s failing).")
        lines += ["", "| abort time s | flies as planned | iterations | planned miss km | flown miss km | "
                  "feasible 10 km | feasible 40 km | message |", "|---|---|---|---|---|---|---|---|"]
        for r in rows:
            message = textwrap.shorten(str(r.get("message", "")), width=200, placeholder=" ...")
            lines.append(f"| {r['abort_time_s']:g} | {'yes' if r.get('plan_success') else 'no'} | "
                         f"{r.get('iterations', '')} | {r.get('planned_miss_km', math.nan):.2f} | "
                         f"{r.get('flown_miss_km', math.nan):.2f} | "
                         + " | ".join("yes" if feasible(r, radius) else "no" for radius in FEASIBLE_RADII_M)
                         + f" | {message} |")
    else:
        lines.append(statistics_markdown(abort_statistics(rows)))
        lines += ["", "Statistics over the cases feasible at 40 km. The paper's figures come from its own "
                  "(non-public) SPHYNX aerodynamic table and EIP computation; ours from the labelled "
                  "representative model and the substitute EIP grid (guidance.scvx.aborts)."]
    if figures and rows:
        trajs = read_trajectories(out_dir, {r["index"] for r in rows})
        paths = (_descent_figures(rows, trajs, manifest, out_dir, planet) if kind == "descent_aborts"
                 else _orbital_figures(rows, trajs, manifest.get("site", [math.nan, math.nan]), out_dir, planet))
        lines += [""] + [f"![{os.path.basename(p)}]({os.path.basename(p)})" for p in paths]
    path = os.path.join(out_dir, "report.md")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path
