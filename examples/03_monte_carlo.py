"""Example 3: a Monte-Carlo campaign from Python.

Load a packaged scenario, edit its dispersions in code (Drake's schema distributions; the
aerodynamic errors by Mach regime with a trim error, an entry delivery covariance, and density and
temperature perturbations along the flight), save
it, run the same campaign on local processes and on a Dask LocalCluster, read the rows back
with pandas and make a plot of your own. Each sample is a Drake ``RandomSimulation`` seeded
from (seed, sample index): both backends give the same rows.

    python examples/03_monte_carlo.py [--quick] [--out out/examples/03]
"""
import os

import pandas as pd
from dask.distributed import LocalCluster
from pydrake.common.schema import Gaussian, Uniform
from pydrake.common.yaml import yaml_dump_typed

from drake_entry.campaign.montecarlo import run_campaign
from drake_entry.claims import Claims, run_example
from drake_entry.figures import plt, save_figure
from drake_entry.models.dispersions import AeroRegimeDispersionSpec, AtmospherePerturbationSpec
from drake_entry.scenario import Scenario, load_scenario


def main(quick: bool = False, out_dir: str = "out/examples/03") -> pd.DataFrame:
    runs = 4 if quick else 40
    os.makedirs(out_dir, exist_ok=True)

    # 1. a scenario with dispersions edited in code: a larger density bias and a wider
    #    entry flight-path-angle dispersion than paper 000's Table 2
    scenario = load_scenario("horus2b")
    scenario.name = "horus2b_wider_density"
    scenario.dispersions.density_scale = Gaussian(mean=1.0, stddev=0.10)
    scenario.dispersions.entry.flight_path_deg = Uniform(min=-0.05, max=0.05)
    #    C_L and C_D errors per Mach regime (subsonic, transonic, supersonic, hypersonic; an
    #    illustration, not a vehicle's database uncertainty) and a trim error of 0.5 deg (1-sigma)
    scenario.dispersions.aero_regimes = AeroRegimeDispersionSpec(
        lift_sigma=[0.05, 0.10, 0.05, 0.03], drag_sigma=[0.05, 0.10, 0.05, 0.03], correlation=[0.0, 0.5, 0.5, 0.5],
        trim_alpha_sigma_deg=0.5)
    #    a delivery covariance on top of Table 2's box: altitude 100 m and speed 5 m/s (1-sigma),
    #    correlated -0.8 (table units: m, deg, deg, m/s, deg, deg)
    cov = [[0.0] * 6 for _ in range(6)]
    cov[0][0], cov[3][3], cov[0][3] = 100.0**2, 5.0**2, -0.8 * 100.0 * 5.0
    cov[3][0] = cov[0][3]
    scenario.dispersions.entry_covariance = cov
    #    density and temperature perturbations: a per-flight part and a part correlated over 6 km of
    #    altitude, 1-sigma growing with altitude (an illustration, not a GRAM profile)
    scenario.dispersions.atmosphere_perturbations = AtmospherePerturbationSpec(
        altitude_km=[0.0, 40.0, 80.0, 120.0], density_sigma=[0.01, 0.02, 0.05, 0.10],
        temperature_sigma=[0.005, 0.01, 0.02, 0.03], vertical_scale_km=6.0)
    scenario.validate()  # bad values raise a one-line ScenarioError naming the field
    path = os.path.join(out_dir, "horus2b_wider_density.yaml")
    with open(path, "w") as f:
        f.write(yaml_dump_typed(scenario, schema=Scenario))

    # 2. the same campaign on local processes and on a Dask cluster (here a LocalCluster; pass
    #    the address of any running Dask scheduler the same way)
    run_campaign(path, runs=runs, seed=7, workers=2, out_dir=os.path.join(out_dir, "processes"), progress=False)
    # (no dashboard, and the scheduler's own HTTP server on a free port: 8787 may be taken)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": ":0"}) as cluster:
        run_campaign(path, runs=runs, seed=7, backend="dask", scheduler=cluster.scheduler_address,
                     out_dir=os.path.join(out_dir, "dask"), progress=False)

    # 3. read the rows with pandas: one row per sample, dispersions (disp_*), terminal errors
    #    (err_*), peaks and margins, success and the stop reason
    rows = {b: pd.read_parquet(os.path.join(out_dir, b, "samples.parquet")).sort_values("index")
            for b in ("processes", "dask")}
    same = rows["processes"]["err_distance_m"].to_numpy() == rows["dask"]["err_distance_m"].to_numpy()
    print(f"{runs} samples per backend; identical terminal errors on both backends: {bool(same.all())}")
    df = rows["processes"]
    df.attrs["same_on_both_backends"] = bool(same.all())
    print(df[["disp_density_scale", "err_range_m", "err_crossrange_m", "err_altitude_m", "success"]].describe())

    # 4. a plot of your own: the miss against the density drawn
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.scatter(df["disp_density_scale"], df["err_range_m"] / 1e3, c=df["success"].map({True: "C0", False: "C3"}))
    ax.set(xlabel="density scale drawn", ylabel="range-to-go error [km]",
           title=f"{scenario.name}: {runs} closed-loop samples")
    ax.grid(alpha=0.3)
    figure = save_figure(fig, out_dir, "range_vs_density.png")
    print(f"wrote {figure}; the full report: drake-entry report {os.path.join(out_dir, 'processes')}")
    return df


def check(df, quick: bool = False) -> Claims:
    """What this example shows, checked (the wider dispersions are outside what the guidance was
    designed for: the example shows the campaign, its rows and verdicts, not that all succeed)."""
    c = Claims("example 03: Monte-Carlo campaigns from Python")
    c.check("both backends give identical terminal errors", bool(df.attrs.get("same_on_both_backends")))
    c.check("every sample ran (no sample lost to an exception)", int(df["traceback"].notna().sum()) == 0
            if "traceback" in df else True)
    c.check("every sample reached the terminal energy", bool(df["reached_terminal"].all()),
            f"{int(df['reached_terminal'].sum())} of {len(df)}")
    c.check("every row carries its verdict: success = inside the box and within every path limit",
            bool((df["success"] == (df["inside_box"] & df["within_limits"] & df["reached_terminal"])).all()),
            f"{int(df['success'].sum())} successful, {int(df['inside_box'].sum())} inside the box, "
            f"{int(df['within_limits'].sum())} within the limits")
    c.check("the edited density dispersion was drawn", float(df["disp_density_scale"].std()) > 0.01,
            f"sigma {df['disp_density_scale'].std():.3f}")
    c.check("every sample drew its own density perturbation profile",
            bool(df["disp_drho_50km"].nunique() == len(df) and df["disp_drho_70km"].nunique() == len(df)),
            f"at 50 km {df['disp_drho_50km'].min():+.3f} to {df['disp_drho_50km'].max():+.3f}")
    c.check("every sample drew its own hypersonic C_D error and trim error",
            bool((df["disp_dCD_hypersonic"] != 0).all() and df["disp_trim_alpha_deg"].nunique() == len(df)),
            f"C_D hypersonic {df['disp_dCD_hypersonic'].min():+.3f} to {df['disp_dCD_hypersonic'].max():+.3f}, trim "
            f"{df['disp_trim_alpha_deg'].min():+.2f} to {df['disp_trim_alpha_deg'].max():+.2f} deg")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/03",
                                 quick="4 samples per backend instead of 40"))
