"""Example 17: FNPEG on a low-lift capsule under Lu (2008)'s dispersions, beside his 500-run
Monte-Carlo.

Lu (2008) flew his predictor-corrector on a low-lift capsule returning from low Earth orbit,
500 dispersed runs, with two bank profiles: linear in energy (sigma_0 solved, sigma_f fixed) and
constant (sigma_0 solved, held to the end). His capsule, entry and target are not public, so the
scenario ``capsule_lu2008`` flies a labelled substitute (the Apollo command module, an entry and
target chosen here) with his dispersions. Three campaigns share the seed, so sample i draws the
same dispersions in each:

- ``linear``: the packaged scenario (FNPEG's linear profile, predictions scaled by the lift and
  drag ratios the flight has sensed, this library's addition);
- ``constant``: ``guidance.bank_profile: constant``, Lu's comparison profile;
- ``nominal_models``: the linear profile predicting with the nominal models only
  (``guidance.acceleration_scaling: false``), as Lu's on-board models are described.

It prints the miss distance of each beside Lu's figures, writes each campaign's report and one
figure of the three miss distributions, and checks what the comparison shows.

    python examples/17_fnpeg_capsule_lu2008.py [--quick] [--runs N] [--out out/examples/17]

Full size (500 runs each) took 42 minutes on 2 cores; ``--quick`` flies 5 runs each.
"""
import os

import numpy as np
import pandas as pd

from drake_entry.campaign.montecarlo import run_campaign
from drake_entry.campaign.report import write_report
from drake_entry.claims import Claims, run_example
from drake_entry.figures import plt, save_figure

SCENARIO, SEED = "capsule_lu2008", 2008
#: the three campaigns: label -> (scenario overrides, report title)
VARIANTS = {
    "linear": ({}, f"{SCENARIO} (linear profile)"),
    "constant": ({"guidance.bank_profile": "constant"}, f"{SCENARIO} (constant profile)"),
    "nominal_models": ({"guidance.acceleration_scaling": False}, f"{SCENARIO} (linear profile, nominal on-board models)"),
}
#: Lu (2008), 500 runs: miss distance [km] mean, 1-sigma, max, per profile
LU2008 = {"linear": (0.945, 0.353, 2.44), "constant": (1.478, 1.24, 7.09)}
#: Lu (2008): every linear-profile run within this [km]; the scenario's acceptance radius too
LU2008_RADIUS_KM = 2.5
#: runs per campaign of the quick run
QUICK_RUNS = 5


def miss_statistics(df: pd.DataFrame) -> dict:
    """Miss distance [km] mean, 1-sigma, median, P95, max and the counts of one campaign's rows."""
    miss = df["err_distance_m"].to_numpy(float) / 1e3
    return {"runs": len(df), "successful": int(df["success"].sum()), "mean": float(np.mean(miss)),
            "std": float(np.std(miss, ddof=1)), "median": float(np.median(miss)),
            "p95": float(np.percentile(miss, 95)), "max": float(np.max(miss)),
            "within_radius": int(np.sum(miss <= LU2008_RADIUS_KM)), "miss_km": miss}


def table(stats: dict) -> str:
    """The Markdown table of the campaigns beside Lu (2008)."""
    lines = ["| campaign | successful | miss mean ± 1σ [km] | median / P95 / max [km] | within 2.5 km | Lu 2008: mean ± 1σ, max [km] |",
             "|---|---|---|---|---|---|"]
    for label, s in stats.items():
        ref = LU2008.get(label)
        lines.append(f"| {label} | {s['successful']}/{s['runs']} | {s['mean']:.3f} ± {s['std']:.3f} | "
                     f"{s['median']:.2f} / {s['p95']:.2f} / {s['max']:.2f} | {s['within_radius']}/{s['runs']} | "
                     + (f"{ref[0]} ± {ref[1]}, {ref[2]} |" if ref else "— |"))
    return "\n".join(lines)


def figure(stats: dict, path: str) -> str:
    """Empirical distributions of the miss distance, with Lu (2008)'s means and maxima marked."""
    fig, ax = plt.subplots(figsize=(8, 4.8))
    colours = {"linear": "C0", "constant": "C1", "nominal_models": "C2"}
    for label, s in stats.items():
        x = np.sort(s["miss_km"])
        ax.step(x, np.arange(1, len(x) + 1) / len(x), where="post", color=colours[label],
                label=f"{label}: {s['runs']} runs, mean {s['mean']:.2f} km, max {s['max']:.2f} km")
        if label in LU2008:
            mean, _, peak = LU2008[label]
            ax.axvline(mean, color=colours[label], ls="--", lw=1)
            ax.axvline(peak, color=colours[label], ls=":", lw=1)
    ax.axvline(LU2008_RADIUS_KM, color="k", lw=1.2, label=f"acceptance radius {LU2008_RADIUS_KM} km")
    ax.plot([], [], "k--", lw=1, label="Lu 2008 mean (colour: profile)")
    ax.plot([], [], "k:", lw=1, label="Lu 2008 max (colour: profile)")
    ax.set(xscale="log", xlabel="miss distance at the terminal energy [km] (log scale)",
           ylabel="fraction of runs with a smaller miss [-]",
           title=f"{SCENARIO}: FNPEG miss distance, same dispersions per sample")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower right")
    return save_figure(fig, os.path.dirname(path), os.path.basename(path))


def main(quick: bool = False, out_dir: str = "out/examples/17", runs: int = 500, workers: int | None = None) -> dict:
    """The three campaigns (``runs`` each; QUICK_RUNS when ``quick``), their reports, table and figure."""
    runs = QUICK_RUNS if quick else runs
    os.makedirs(out_dir, exist_ok=True)
    stats = {}
    for label, (overrides, title) in VARIANTS.items():
        d = os.path.join(out_dir, label)
        print(f"{label}: {runs} runs, overrides {overrides or 'none'}", flush=True)
        run_campaign(SCENARIO, runs=runs, seed=SEED, out_dir=d, overrides=overrides or None, workers=workers)
        write_report(d, title=title)
        df = pd.read_parquet(os.path.join(d, "samples.parquet")).sort_values("index").head(runs)
        stats[label] = {**miss_statistics(df), "disp": df.filter(like="disp_").to_numpy(float)}
    print("\n" + table(stats))
    print(f"wrote {figure(stats, os.path.join(out_dir, 'miss_distributions.png'))}")
    return stats


def check(stats: dict, quick: bool = False) -> Claims:
    """What the comparison shows, checked (the same claims at both sizes)."""
    c = Claims("example 17: FNPEG on a low-lift capsule beside Lu (2008)")
    lin, con, nom = stats["linear"], stats["constant"], stats["nominal_models"]
    c.check("the three campaigns drew the same dispersions sample by sample",
            np.array_equal(lin["disp"], con["disp"]) and np.array_equal(lin["disp"], nom["disp"]))
    c.check("linear profile: every run successful (inside 2.5 km and within every path limit), as Lu's "
            "linear-profile runs all ended within 2.5 km", lin["successful"] == lin["runs"],
            f"{lin['successful']}/{lin['runs']}, max {lin['max']:.2f} km")
    c.check("linear profile: mean miss no larger than Lu's 0.945 km", lin["mean"] <= LU2008["linear"][0],
            f"{lin['mean']:.3f} km")
    c.check("the constant profile misses more than the linear one on average (Lu's ranking)",
            con["mean"] > lin["mean"], f"{con['mean']:.3f} vs {lin['mean']:.3f} km")
    c.check("without the sensed lift and drag ratios in its predictions the linear profile misses more",
            nom["mean"] > lin["mean"], f"{nom['mean']:.3f} vs {lin['mean']:.3f} km")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(
        __doc__, main, check, out="out/examples/17", quick="5 runs per campaign instead of --runs",
        options=[("--runs", {"type": int, "default": 500, "help": "runs per campaign (default: Lu's 500)"}),
                 ("--workers", {"type": int, "default": None, "help": "processes (default: all cores)"})]))
