"""The SCvx plan against its flight (paper 001 Figs. 3-6 form): altitude-velocity, ground track
with the site, the planned bank and alpha, and the flight-path angle, planned and flown. Headless."""
from __future__ import annotations

import math
import os

import numpy as np

from drake_entry.figures import plt, save_figure

__all__ = ["plan_figure"]


def plan_figure(plan, flight, site_rad: tuple[float, float], out_dir: str, *, title: str,
                name: str = "scvx_entry.png") -> str:
    """Write the four-panel figure of ``plan`` (``ScvxPlan``) and ``flight`` (its ``PlanFlight``,
    the controls flown by the Drake Simulator) to out_dir/name; return the path.

    Args:
      site_rad: the site's longitude and geocentric latitude [rad].
    """
    os.makedirs(out_dir, exist_ok=True)
    fig, ax = plt.subplots(2, 2, figsize=(11, 7))
    t = np.linspace(0.0, plan.final_time, 600)
    ref = plan.evaluate(t)
    ax[0, 0].plot(ref["V"] / 1e3, ref["h"] / 1e3, label="plan")
    ax[0, 0].plot(flight.states[:, 3] / 1e3, flight.states[:, 0] / 1e3, "--", label="flown (Drake)")
    ax[0, 0].set(xlabel="V [km/s]", ylabel="h above the equatorial sphere [km]", title="altitude-velocity")
    ax[0, 1].plot(np.degrees(ref["lon"]), np.degrees(ref["lat"]), label="plan")
    ax[0, 1].plot(np.degrees(flight.states[:, 1]), np.degrees(flight.states[:, 2]), "--", label="flown (Drake)")
    ax[0, 1].plot(math.degrees(site_rad[0]), math.degrees(site_rad[1]), "r*", ms=12, label="site")
    ax[0, 1].set(xlabel="longitude [deg]", ylabel="geocentric latitude [deg]", title="ground track")
    ax[1, 0].plot(t, np.degrees(ref["bank"]), label="bank (plan)")
    ax[1, 0].plot(t, np.degrees(ref["alpha"]), label="alpha (plan)")
    ax[1, 0].set(xlabel="t [s]", ylabel="angle [deg]", title="planned controls")
    ax[1, 1].plot(t, np.degrees(ref["gamma"]), label="plan")
    ax[1, 1].plot(flight.time, np.degrees(flight.states[:, 4]), "--", label="flown (Drake)")
    lo, hi = plan.problem.mission.flight_path_bounds_deg
    for value, label in ((lo, f"eq. 70 bound {lo:g} deg"), (hi, f"eq. 70 bound {hi:g} deg")):
        ax[1, 1].axhline(value, color="r", ls=":", lw=1, label=label)
    ax[1, 1].set(xlabel="t [s]", ylabel="flight-path angle [deg]", title="flight-path angle (path bounds in red)")
    for a in ax.flat:
        a.grid(True)
        a.legend(fontsize=8)
    paths = []
    save_figure(fig, out_dir, name, paths, title)
    return paths[0]
