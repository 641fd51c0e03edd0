"""Paper 000 figures: the drag-energy corridor with its reference (Figs. 3-4), the reference
against its flown extraction, and the flown drag against the reference."""
from __future__ import annotations

import os

import numpy as np

from drake_entry.figures import plt, save_figure  # the Agg backend is set there

__all__ = ["corridor_plot", "extraction_plot", "tracking_plot"]


def corridor_plot(corridor, E0: float, Ef: float, out_dir: str, *, reference=None, title: str = "") -> list[str]:
    """Drag-energy corridor with each constraint's bound (paper 000 Fig. 3) and, if given,
    the reference profile on a dense grid with its nodes (Fig. 4)."""
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    e = (E0 - corridor.energy) / (E0 - Ef)
    fig, ax = plt.subplots(figsize=(7, 4.8))
    styles = {"heat_flux": "C3", "normal_load": "C1", "dynamic_pressure": "C2", "total_load": "C4"}
    for name, D in corridor.upper.items():
        if np.isfinite(D).any():
            ax.plot(e, D, color=styles[name], lw=1, ls=":", label=f"{name.replace('_', ' ')} bound")
    ax.plot(e, corridor.D_max, "k-", lw=1.5, label=f"D_max (margin {100 * corridor.margin:g} %)")
    ax.plot(e, corridor.D_min, "k--", lw=1.5, label="D_min (equilibrium glide)")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.15 * np.nanmax(np.where(np.isfinite(corridor.D_max), corridor.D_max, np.nan)))
    ax.set_xlabel("normalised energy e = (E0 - E)/(E0 - Ef)")
    ax.set_ylabel("drag [m/s^2]")
    ax.grid(True)
    ax.legend(fontsize=8, loc="upper left")
    save_figure(fig, out_dir, "corridor.png", paths, title)
    if reference is not None:
        p = reference.problem
        E = np.linspace(p.E0, p.Ef, 1500)
        D = reference.profile(E)[0]
        lo, hi = p.corridor.bounds(E)
        ee = (E0 - E) / (E0 - Ef)
        fig, ax = plt.subplots(figsize=(7, 4.8))
        ax.fill_between(ee, lo, hi, color="0.85", label="corridor")
        ax.plot(ee, D, "C0-", label="reference D(E)")
        ax.plot((E0 - reference.energy) / (E0 - Ef), reference.D, "C0o", ms=3, label=f"{p.n_nodes} LGL nodes")
        ax.set_xlabel("normalised energy e")
        ax.set_ylabel("drag [m/s^2]")
        ax.grid(True)
        ax.legend(fontsize=8, loc="upper left")
        save_figure(fig, out_dir, "reference_profile.png", paths, title)
    return paths


def extraction_plot(reference, propagated, planet, out_dir: str, *, title: str = "") -> list[str]:
    """Extracted altitude, speed, flight-path angle and bank at the nodes against an
    open-loop propagation of the extracted bank (paper 000 Fig. 5)."""
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    x = reference.extraction
    p = reference.problem
    e_nodes = (p.E0 - reference.energy) / (p.E0 - p.Ef)
    s = propagated.state
    E = np.array([planet.specific_energy(r[0], r[3]) for r in s])
    e = (p.E0 - E) / (p.E0 - p.Ef)
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    pairs = ((x.h / 1e3, s[:, 0] / 1e3, "altitude [km]"), (x.V / 1e3, s[:, 3] / 1e3, "speed [km/s]"),
             (np.degrees(x.gamma), np.degrees(s[:, 4]), "flight-path angle [deg]"),
             (np.degrees(x.sigma), np.degrees(np.abs(propagated.bank)), "bank [deg]"))
    for ax, (ext, prop, label) in zip(axes.ravel(), pairs):
        ax.plot(e, prop, "C1-", lw=1, label="open-loop propagation")
        ax.plot(e_nodes, ext, "C0o", ms=3, label="extracted (eqs. 93-96)")
        sat = x.saturated
        if label.startswith("bank") and sat.any():
            ax.plot(e_nodes[sat], ext[sat], "rx", label="bank saturated")
        ax.set_ylabel(label)
        ax.grid(True)
    axes[0, 0].legend(fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("normalised energy e")
    save_figure(fig, out_dir, "extraction_vs_propagation.png", paths, title)
    return paths


def tracking_plot(tr, out_dir: str, *, title: str = "") -> list[str]:
    """Flown drag against the guidance reference over time (closed loop)."""
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    ref = tr.extra["reference"]
    on = ref[:, 3] > 0.5
    fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    axes[0].plot(tr.time, tr.column("drag"), label="flown D")
    axes[0].plot(tr.time[on], ref[on, 0], "--", label="reference D_ref")
    axes[0].set_ylabel("drag [m/s^2]")
    axes[0].legend(fontsize=8)
    axes[1].plot(tr.time[on], 100 * (tr.column("drag")[on] / ref[on, 0] - 1))
    axes[1].set_ylabel("tracking error [%]")
    axes[1].set_xlabel("time [s]")
    for a in axes:
        a.grid(True)
    save_figure(fig, out_dir, "drag_tracking.png", paths, title)
    return paths
