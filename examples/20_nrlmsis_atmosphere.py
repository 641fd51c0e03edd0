"""Example 20: an empirical nominal atmosphere for a place and date. The HORUS-2B mission (paper
000) flown in US76 and in NRLMSIS 2.1 (``atmosphere.model: nrlmsis``, through the ``pymsis``
package) at its entry point on 21 June 2025, 12:00 UTC, with F10.7 = 150 sfu and Ap = 15 given
in the scenario (nothing is downloaded). The guidance plans in the same atmosphere it flies, so
both flights are nominal; the figure shows how NRLMSIS's density and temperature differ from
US76's at that place and season, and the two flights.

    python examples/20_nrlmsis_atmosphere.py [--quick] [--out out/examples/20]
"""

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import fly
from drake_entry.figures import plt, save_figure
from drake_entry.models.environment import AtmosphereSpec
from drake_entry.scenario import load_scenario


def main(quick: bool = False, out_dir: str = "out/examples/20") -> dict:
    us76 = load_scenario("horus2b")
    msis = load_scenario("horus2b")
    msis.atmosphere = AtmosphereSpec(model="nrlmsis", nrlmsis_utc="2025-06-21T12:00:00",
                                     nrlmsis_latitude_deg=us76.entry.latitude_deg,
                                     nrlmsis_longitude_deg=us76.entry.longitude_deg, f107_sfu=150.0, f107a_sfu=150.0,
                                     ap=15.0)
    msis.validate()
    flights = {"US76": fly(us76), "NRLMSIS 2.1": fly(msis)}
    for name, r in flights.items():
        print(f"{name:12s}: {r.message}")
    a_us76, a_msis = us76.make_atmosphere(), msis.make_atmosphere()
    h = np.arange(0.0, 120e3 + 1, 1e3)
    ratio_rho = a_msis.density(h) / a_us76.density(h)
    ratio_T = a_msis.temperature(h) / a_us76.temperature(h)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    ax1.plot(ratio_rho, h / 1e3, label="density")
    ax1.plot(ratio_T, h / 1e3, label="temperature")
    ax1.axvline(1.0, color="k", lw=0.8, ls=":", label="US76")
    ax1.set(xlabel="NRLMSIS 2.1 / US76 [-]", ylabel="altitude [km]",
            title=f"{us76.entry.latitude_deg:g} deg N, {us76.entry.longitude_deg:g} deg E, 21 June 2025")
    for name, r in flights.items():
        tr = r.trajectory
        ax2.plot(tr.column("V") / 1e3, tr.column("h") / 1e3, label=f"{name}: miss {r.errors['distance_m'] / 1e3:.2f} km")
    ax2.set(xlabel="velocity [km/s]", ylabel="altitude [km]", title="HORUS-2B nominal, drag-energy guidance")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    path = save_figure(fig, out_dir, "nrlmsis_atmosphere.png",
                       title="An empirical nominal atmosphere (NRLMSIS 2.1 through pymsis) beside US76",
                       caption="Look at: where NRLMSIS departs from US76 for this place and season, and that the "
                               "guidance flies either nominal atmosphere to its target.")
    return {"flights": flights, "ratio_density": ratio_rho, "altitude_m": h, "source": a_msis.source, "plot": path}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 20: an NRLMSIS nominal atmosphere")
    for name, f in r["flights"].items():
        c.check(f"the {name} flight is a success", bool(f.success), f.message)
    below_90 = r["ratio_density"][r["altitude_m"] <= 90e3]
    c.check("NRLMSIS's density is within 35 % of US76 below 90 km at this place and date",
            bool(np.all(np.abs(below_90 - 1.0) < 0.35)), f"ratio {below_90.min():.2f} to {below_90.max():.2f}")
    c.check("the atmosphere names its source (model, place, date, indices)", "NRLMSIS 2.1" in r["source"], r["source"])
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/20", quick="the same two flights"))
