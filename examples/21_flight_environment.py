"""Example 21: one sample of a flight-like twin. ``horus2b_flight`` is the HORUS-2B mission and
guidance of paper 000 with, beside the paper's entry dispersions, perturbed density and
temperature, winds, aerodynamic errors by Mach regime, mass, an inertial navigation system and a
computing latency (docs/campaigns.md, "Flight-like twins"). Sample 0 of its seed-2018 campaign
is flown twice: with the INS, and with the perfect-navigation switch
(``dispersions.inertial_navigation.enabled: false``: the same draws, guidance reads the true state
and accelerations). The figure shows the sample's wind against the scenario's mean and 1-sigma,
the navigation error growing along the flight, and the two ground tracks near the target.

    python examples/21_flight_environment.py [--quick] [--out out/examples/21]
"""
import dataclasses as dc

import numpy as np
from pydrake.common import RandomGenerator

from drake_entry.campaign.sample import sample_seed
from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.closed_loop import ClosedLoopSetup, fly
from drake_entry.figures import plt, save_figure
from drake_entry.models.dispersions import draw
from drake_entry.scenario import load_scenario

SEED, SAMPLE = 2018, 0


def main(quick: bool = False, out_dir: str = "out/examples/21") -> dict:
    scenario = load_scenario("horus2b_flight")
    setup = ClosedLoopSetup.from_scenario(scenario)
    sample = draw(scenario.dispersions, RandomGenerator(sample_seed(SEED, SAMPLE)))  # as the campaign draws it
    perfect = dc.replace(sample, inertial=dc.replace(sample.inertial, enabled=False))
    flights = {"INS": fly(setup, draw=sample), "perfect navigation": fly(setup, draw=perfect)}
    for name, r in flights.items():
        print(f"{name:18s}: {r.message}")
    w = scenario.dispersions.winds
    h = np.array(sample.wind_altitude_m)

    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(14, 4.4))
    mean, sigma = np.interp(h / 1e3, w.altitude_km, w.east_mean_m_s), np.interp(h / 1e3, w.altitude_km, w.sigma_m_s)
    ax1.fill_betweenx(h / 1e3, mean - sigma, mean + sigma, color="C0", alpha=0.2, label="east: mean ± 1σ")
    ax1.plot(sample.wind_east_m_s, h / 1e3, color="C0", label="east: this sample")
    ax1.plot(sample.wind_north_m_s, h / 1e3, color="C1", label="north: this sample (mean 0)")
    ax1.set(xlabel="wind towards [m/s]", ylabel="altitude [km]", title="the sample's wind", ylim=(0, 120))
    tr = flights["INS"].trajectory
    error = tr.extra["navigation_error"]
    ax2.plot(tr.time, error[:, 0], label="|position error| [m]")
    ax2.plot(tr.time, 100 * error[:, 1], label="100 × |velocity error| [m/s]")
    ax2.set(xlabel="time [s]", ylabel="INS error", title="navigation error along the flight")
    for name, r in flights.items():
        t = r.trajectory
        ax3.plot(np.degrees(t.column("lon")), np.degrees(t.column("lat")),
                 label=f"{name}: miss {r.errors['distance_m'] / 1e3:.2f} km")
    ax3.plot(scenario.target.longitude_deg, scenario.target.latitude_deg, "k*", ms=10, label="target")
    lon, lat = scenario.target.longitude_deg, scenario.target.latitude_deg
    ax3.set(xlabel="longitude [deg]", ylabel="latitude [deg]", title="ground tracks near the target",
            xlim=(lon - 0.3, lon + 0.1), ylim=(lat - 0.3, lat + 0.1))
    ax3.xaxis.set_major_locator(plt.MaxNLocator(5))
    for ax in (ax1, ax2, ax3):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    path = save_figure(fig, out_dir, "flight_environment.png",
                       title=f"horus2b_flight, sample {SAMPLE} of seed {SEED}: wind, INS error and the flown tracks",
                       caption="Look at: the sample's wind against the scenario's mean and 1-sigma band (a draw "
                               "leaves the band about a third of the time), the INS position error growing to hundreds "
                               "of metres, and where the two tracks end beside the target.")
    return {"flights": flights, "sample": sample, "error": error, "plot": path}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 21: a flight-like twin's sample")
    for name, f in r["flights"].items():
        c.check(f"the flight with {name} is a success", bool(f.success), f.message)
    end = r["error"][-1]
    c.check("the INS position error grows from its entry value", bool(end[0] > r["error"][0, 0]),
            f"{r['error'][0, 0]:.0f} m at entry, {end[0]:.0f} m at the end")
    perfect = r["flights"]["perfect navigation"].trajectory.extra["navigation_error"]
    c.check("with perfect navigation the navigation error is zero", bool(np.all(perfect == 0.0)))
    miss = [f.errors["distance_m"] for f in r["flights"].values()]
    c.check("the INS changes the miss (the same draws otherwise)", miss[0] != miss[1],
            f"{miss[0]:.0f} m and {miss[1]:.0f} m")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/21", quick="the same two flights"))
