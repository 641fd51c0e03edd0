"""Figures of an NLP solution: states, controls, costates and their propagated flight."""
from __future__ import annotations

import os

import numpy as np

from drake_entry.figures import plt, save_figure  # the Agg backend is set there
from drake_entry.planning.nlp.result import TRANSCRIPTION_LABELS

__all__ = ["nlp_solution_plots"]


def nlp_solution_plots(problem, result, out_dir: str, *, propagated=None, extremal=None, title: str = "") -> list[str]:
    """Paper 002 Figs. 1-10 for an entry NLP solution: altitude, dynamic pressure against
    its bounds, downtrack-crosstrack, speed, flight-path angle, alpha, bank, u_alpha and
    u_sigma against the extremal controls, and the Hamiltonian. NLP nodes as markers,
    the Drake propagation of the controls (``propagated``: nlp.verify.PropagationCheck) as a line."""
    from drake_entry.models.geodesy import downtrack_crosstrack

    os.makedirs(out_dir, exist_ok=True)
    paths = []
    t, X, U = result.time, result.states, result.controls
    P = propagated
    x0, xf = X[0], X[-1]
    R = problem.planet.reference_radius

    def save(fig, name):
        save_figure(fig, out_dir, name, paths, title)

    def series(name, ylabel, node_values, prop_values=None, scale=1.0, limits=()):
        fig, ax = plt.subplots(figsize=(6, 4))
        if prop_values is not None:
            ax.plot(P.time, prop_values * scale, "-", lw=1, label="Drake propagation")
        ax.plot(t, node_values * scale, "o", ms=3, label=f"{TRANSCRIPTION_LABELS[result.transcription]} nodes")
        for value, label in limits:
            ax.axhline(value, color="r", ls="--", lw=1, label=label)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(ylabel)
        ax.grid(True)
        ax.legend(fontsize=8)
        save(fig, name)

    deg = np.degrees(1.0)
    series("fig01_altitude.png", "altitude [km]", X[:, 0], None if P is None else P.states[:, 0], 1e-3)
    q = np.array([problem.conditions(x, u).dynamic_pressure for x, u in zip(X, U)])
    qp = None if P is None else np.array([problem.conditions(x, np.zeros(2)).dynamic_pressure for x in P.states])
    qlim = [(v / 1e3, f"q {end}") for c in problem.path if c.quantity == "dynamic_pressure"
            for v, end in ((c.min, "min"), (c.max, "max")) if np.isfinite(v)]
    series("fig02_dynamic_pressure.png", "dynamic pressure [kPa]", q, qp, 1e-3, qlim)
    fig, ax = plt.subplots(figsize=(6, 4))
    d, c = downtrack_crosstrack(X[:, 1], X[:, 2], x0[1], x0[2], xf[1], xf[2], R)
    if P is not None:
        dp, cp = downtrack_crosstrack(P.states[:, 1], P.states[:, 2], x0[1], x0[2], xf[1], xf[2], R)
        ax.plot(cp / 1e3, dp / 1e3, "-", lw=1, label="Drake propagation")
    ax.plot(c / 1e3, d / 1e3, "o", ms=3, label="nodes")
    ax.set_xlabel("crosstrack [km]")
    ax.set_ylabel("downtrack [km]")
    ax.grid(True)
    ax.legend(fontsize=8)
    save(fig, "fig03_downtrack_crosstrack.png")
    series("fig04_speed.png", "speed [km/s]", X[:, 3], None if P is None else P.states[:, 3], 1e-3)
    series("fig05_flight_path.png", "flight-path angle [deg]", X[:, 4], None if P is None else P.states[:, 4], deg)
    if problem.n_states > 6:
        series("fig06_alpha.png", "angle of attack [deg]", X[:, 6], None if P is None else P.states[:, 6], deg)
        series("fig07_bank.png", "bank angle [deg]", X[:, 7], None if P is None else P.states[:, 7], deg)
    for j, (name, label) in enumerate((("fig08_u_alpha.png", "u_alpha [deg/s]"), ("fig09_u_sigma.png", "u_sigma [deg/s]"))):
        if problem.n_controls <= j:
            break
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(t, U[:, j] * deg, "o", ms=3, label="NLP")
        if extremal is not None:
            ax.plot(result.costate_time, extremal[:, j] * deg, "-", lw=1, label="extremal (eq. 23 from costates)")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(True)
        ax.legend(fontsize=8)
        save(fig, name)
    if result.hamiltonian is not None:
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(result.costate_time, result.hamiltonian, "o-", ms=3, lw=0.8)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("Hamiltonian H [cost units / s]")
        ax.grid(True)
        save(fig, "fig10_hamiltonian.png")
    return paths
