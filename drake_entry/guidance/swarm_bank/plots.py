"""Paper 004 figures: each case's flown histories against the path limits and the optimisers'
convergence."""
from __future__ import annotations

import os

import numpy as np

from drake_entry.figures import limit_line, plt, save_figure  # the Agg backend is set there

__all__ = ["swarm_case_plots", "swarm_convergence_plot"]


def swarm_case_plots(histories: dict, columns, out_dir: str, *, limits=None, flown=None, title: str = "") -> list[str]:
    """Paper 004 Figs. 4-13 form: altitude, speed, ground track, alpha, bank, heat rate,
    dynamic pressure and total load against time, one line per case.

    histories: {case: (steps, len(columns)) array} (guidance.swarm_bank.evaluator.HISTORY_COLUMNS);
    limits: PathLimits for the limit lines; flown: {case: Trajectory} of Drake flights to
    overlay (dashed)."""
    os.makedirs(out_dir, exist_ok=True)
    col = {name: i for i, name in enumerate(columns)}
    panels = [("altitude_m", "altitude [km]", 1e-3, "swarm_altitude.png"),
              ("velocity_m_s", "speed [m/s]", 1.0, "swarm_speed.png"),
              ("alpha_rad", "angle of attack [deg]", np.degrees(1.0), "swarm_alpha.png"),
              ("bank_rad", "bank angle [deg]", np.degrees(1.0), "swarm_bank.png"),
              ("heat_flux_W_m2", "heat rate [MW/m^2]", 1e-6, "swarm_heat.png"),
              ("dynamic_pressure_Pa", "dynamic pressure [kPa]", 1e-3, "swarm_q.png"),
              ("total_load_g", "total load [g]", 1.0, "swarm_load.png")]
    limit_of = {} if limits is None else {"heat_flux_W_m2": limits.heat_flux_max * 1e-6,
                                          "dynamic_pressure_Pa": limits.dynamic_pressure_max * 1e-3,
                                          "total_load_g": limits.total_load_max}
    paths: list[str] = []
    for name, label, scale, file in panels:
        fig, ax = plt.subplots(figsize=(7, 4))
        for case, h in histories.items():
            ax.plot(h[:, col["time_s"]], h[:, col[name]] * scale, lw=1, label=case)
        for case, tr in (flown or {}).items():
            flown_col = {"altitude_m": tr.state[:, 0], "velocity_m_s": tr.state[:, 3]}.get(name)
            if flown_col is not None:
                ax.plot(tr.time, flown_col * scale, "k--", lw=0.8, label=f"{case}: Drake closed loop")
        if name in limit_of:
            limit_line(ax, limit_of[name], "limit")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        save_figure(fig, out_dir, file, paths, title)
    fig, ax = plt.subplots(figsize=(7, 4))
    for case, h in histories.items():
        ax.plot(np.degrees(h[:, col["longitude_rad"]]), np.degrees(h[:, col["latitude_rad"]]), lw=1, label=case)
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    save_figure(fig, out_dir, "swarm_groundtrack.png", paths, title)
    return paths


def swarm_convergence_plot(histories: dict, out_dir: str, *, title: str = "") -> list[str]:
    """Best J against iteration per method (paper 004 Fig. 4 form): {method: [history per seed]}."""
    os.makedirs(out_dir, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 4))
    for k, (method, runs) in enumerate(histories.items()):
        for i, h in enumerate(runs):
            ax.plot(np.arange(len(h)), h, color=f"C{k}", lw=0.8, alpha=0.5, label=method if i == 0 else None)
    ax.set_yscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("best J (eq. 32)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    paths: list[str] = []
    save_figure(fig, out_dir, "swarm_convergence.png", paths, title)
    return paths
