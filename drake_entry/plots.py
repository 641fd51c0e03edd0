"""Standard entry plots shared by every command: altitude-velocity, groundtrack, heat
flux, dynamic pressure and load factors against their limits. Headless (Agg)."""
from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _limit(ax, value, label):
    if value is not None and np.isfinite(value):
        ax.axhline(value, color="r", ls="--", lw=1, label=label)
        ax.legend(loc="best", fontsize=8)


def trajectory_plots(tr, out_dir: str, *, limits=None, target=None, title: str = "") -> list[str]:
    """Write PNG plots of a Trajectory to out_dir; return their paths.

    Args:
      tr: diagrams.open_loop.Trajectory (or anything with .time/.state/.column()).
      limits: drake_entry.constraints.PathLimits for the limit lines.
      target: (lon_deg, lat_deg) of the target site for the groundtrack.
    """
    os.makedirs(out_dir, exist_ok=True)
    paths = []

    def save(fig, name):
        _save(fig, out_dir, name, paths, title)

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
            _limit(ax, getattr(limits, lim_attr) * scale, "limit")
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
            _limit(ax, limits.normal_load_max, "n_z limit")
        if np.isfinite(limits.total_load_max):
            _limit(ax, limits.total_load_max, "n limit")
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


def _save(fig, out_dir, name, paths, title=""):
    """Save fig as out_dir/name (PNG), append the path to ``paths``, close it."""
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    p = os.path.join(out_dir, name)
    fig.savefig(p, dpi=110)
    plt.close(fig)
    paths.append(p)


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
    _save(fig, out_dir, "corridor.png", paths, title)
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
        _save(fig, out_dir, "reference_profile.png", paths, title)
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
    _save(fig, out_dir, "extraction_vs_propagation.png", paths, title)
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
    _save(fig, out_dir, "drag_tracking.png", paths, title)
    return paths


def nlp_solution_plots(problem, result, out_dir: str, *, propagated=None, extremal=None, title: str = "") -> list[str]:
    """Paper 002 Figs. 1-10 for an entry NLP solution: altitude, dynamic pressure against
    its bounds, downtrack-crosstrack, speed, flight-path angle, alpha, bank, u_alpha and
    u_sigma against the extremal controls, and the Hamiltonian. NLP nodes as markers,
    the Drake propagation of the controls (``propagated``: PropagationCheck) as a line."""
    from drake_entry.geodesy import downtrack_crosstrack

    os.makedirs(out_dir, exist_ok=True)
    paths = []
    t, X, U = result.time, result.states, result.controls
    P = propagated
    x0, xf = X[0], X[-1]
    R = problem.planet.reference_radius

    def save(fig, name):
        _save(fig, out_dir, name, paths, title)

    def series(name, ylabel, node_values, prop_values=None, scale=1.0, limits=()):
        fig, ax = plt.subplots(figsize=(6, 4))
        if prop_values is not None:
            ax.plot(P.time, prop_values * scale, "-", lw=1, label="Drake propagation")
        ax.plot(t, node_values * scale, "o", ms=3, label=f"{result.transcription.upper()} nodes")
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
    qlim = [(c.min / 1e3, "q min") for c in problem.path if c.quantity == "dynamic_pressure" and np.isfinite(c.min)]
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


def swarm_case_plots(histories: dict, columns, out_dir: str, *, limits=None, flown=None, title: str = "") -> list[str]:
    """Paper 004 Figs. 4-13 form: altitude, speed, ground track, alpha, bank, heat rate,
    dynamic pressure and total load against time, one line per case.

    histories: {case: (steps, len(columns)) array} (planning.swarm.evaluator.HISTORY_COLUMNS);
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
            _limit(ax, limit_of[name], "limit")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        _save(fig, out_dir, file, paths, title)
    fig, ax = plt.subplots(figsize=(7, 4))
    for case, h in histories.items():
        ax.plot(np.degrees(h[:, col["longitude_rad"]]), np.degrees(h[:, col["latitude_rad"]]), lw=1, label=case)
    ax.set_xlabel("longitude [deg]")
    ax.set_ylabel("latitude [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    _save(fig, out_dir, "swarm_groundtrack.png", paths, title)
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
    _save(fig, out_dir, "swarm_convergence.png", paths, title)
    return paths
