"""Standard entry plots shared by every command: altitude-velocity, groundtrack, heat
flux, dynamic pressure and load factors against their limits; ``save_figure``, the one way a
figure is titled and written. Headless: ``plt`` is pyplot with the Agg backend set, so every
module that draws imports it from here."""
from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["plt", "limit_line", "trajectory_plots", "save_figure"]


def limit_line(ax, value, label):
    if value is not None and np.isfinite(value):
        ax.axhline(value, color="r", ls="--", lw=1, label=label)
        ax.legend(loc="best", fontsize=8)


def trajectory_plots(tr, out_dir: str, *, limits=None, target=None, title: str = "") -> list[str]:
    """Write PNG plots of a Trajectory to out_dir; return their paths.

    Args:
      tr: diagrams.open_loop.Trajectory (or anything with .time/.state/.column()).
      limits: drake_entry.models.constraints.PathLimits for the limit lines.
      target: (lon_deg, lat_deg) of the target site for the groundtrack.
    """
    os.makedirs(out_dir, exist_ok=True)
    paths = []

    def save(fig, name):
        save_figure(fig, out_dir, name, paths, title)

    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(tr.column("V") / 1e3, tr.column("h") / 1e3)
    ax.set_xlabel("velocity [km/s]")
    ax.set_ylabel("altitude [km]")
    ax.grid(True)
    save(fig, "altitude_velocity.png")

    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(np.degrees(tr.column("lon")), np.degrees(tr.column("lat")), label="trajectory")
    ax.plot(np.degrees(tr.column("lon")[0]), np.degrees(tr.column("lat")[0]), "go", label="entry")
    if target is not None:
        ax.plot(*target, "r*", ms=12, label="target")
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.legend(fontsize=8)
    ax.grid(True)
    ax.set_aspect("equal", adjustable="datalim")
    save(fig, "groundtrack.png")

    t = tr.time
    for name, col, scale, unit, lim_attr in (
        ("heat_flux.png", "heat_flux", 1e-3, "heat flux [kW/m^2]", "heat_flux_max"),
        ("dynamic_pressure.png", "dynamic_pressure", 1e-3, "dynamic pressure [kPa]", "dynamic_pressure_max"),
    ):
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(t, tr.column(col) * scale)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(unit)
        ax.grid(True)
        if limits is not None:
            limit_line(ax, getattr(limits, lim_attr) * scale, "limit")
        save(fig, name)

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(t, tr.column("normal_load"), label="normal n_z")
    ax.plot(t, tr.column("total_load"), label="total n", alpha=0.7)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("load factor [g]")
    ax.grid(True)
    ax.legend(fontsize=8)
    if limits is not None:
        if np.isfinite(limits.normal_load_max):
            limit_line(ax, limits.normal_load_max, "n_z limit")
        if np.isfinite(limits.total_load_max):
            limit_line(ax, limits.total_load_max, "n limit")
    save(fig, "load_factor.png")

    fig, axes = plt.subplots(2, 1, figsize=(6, 5), sharex=True)
    axes[0].plot(t, np.degrees(tr.column("bank")))
    axes[0].set_ylabel("bank [deg]")
    axes[1].plot(t, np.degrees(tr.column("alpha")))
    axes[1].set_ylabel("alpha [deg]")
    axes[1].set_xlabel("time [s]")
    for a in axes:
        a.grid(True)
    save(fig, "controls.png")
    return paths


def save_figure(fig, out_dir, name, paths=None, title="", caption="") -> str:
    """Save fig as out_dir/name (PNG; the directory made), titled ``title`` and captioned
    ``caption`` (what to look at, in a band along the bottom) when given, laid out tight, closed;
    append the path to ``paths`` when given and return it."""
    if title:
        fig.suptitle(title, fontsize=10)
    if caption:
        fig.text(0.01, 0.01, caption, fontsize=8)
    fig.tight_layout(rect=(0, 0.04, 1, 1) if caption else None)
    os.makedirs(out_dir, exist_ok=True)
    p = os.path.join(out_dir, name)
    fig.savefig(p, dpi=110)
    plt.close(fig)
    if paths is not None:
        paths.append(p)
    return p
