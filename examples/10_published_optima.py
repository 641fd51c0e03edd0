"""Example 10: published optimal-control problems (nlp.catalogue) solved with the library
defaults, then with mesh refinement, each against its published optimum.

The problems are posed as a user would pose them: the Brachistochrone (the cycloid), the
Goddard rocket (COPS 3.0), Betts' Space Shuttle maximum crossrange with and without the wing
heating limit q = q_a(alpha) q_r (Betts 2010, Sec. 6.1). Each is solved by
``nlp.solve(problem, verifier=fly_controls)`` (40 LGL nodes, solver 'auto': SNOPT, then Ipopt if SNOPT fails), verified between the nodes
and by the Drake Simulator, and compared with the published figure; then the Brachistochrone
and the shuttle are solved from a coarse mesh with ``refine=True``, which raises the node
count until the between-node error meets the tolerance. Plots: the shuttle ground tracks and
the heating along them.

    python examples/10_published_optima.py [--quick] [--out out/examples/10]
"""
import math
import os

import numpy as np

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.verification import fly_controls
from drake_entry.figures import plt, save_figure
from drake_entry.planning import nlp
from drake_entry.planning.nlp import catalogue

PROBLEMS = {"brachistochrone": catalogue.brachistochrone, "goddard_rocket": catalogue.goddard_rocket,
            "shuttle_crossrange": catalogue.shuttle_crossrange,
            "shuttle_crossrange_heating": lambda: catalogue.shuttle_crossrange(heating_limit=True)}


def main(quick: bool = False, out_dir: str = "out/examples/10") -> dict:
    """Solve the catalogue (quick: the shuttle without refinement); return per problem the
    result, the published optimum, the relative difference, and the plot path."""
    os.makedirs(out_dir, exist_ok=True)
    out = {}
    print(f"{'problem':28s} {'solver':6s} {'verified':8s} {'objective':>12s} {'published':>12s} {'relative':>9s} "
          f"{'wall [s]':>8s}")
    for name, make in PROBLEMS.items():
        problem, published = make()
        r = nlp.solve(problem, verifier=fly_controls)
        rel = abs(r.objective - published["objective"]) / abs(published["objective"])
        out[name] = {"result": r, "published": published, "relative": rel}
        print(f"{name:28s} {r.solver:6s} {str(r.success):8s} {r.objective:12.7g} {published['objective']:12.7g} "
              f"{rel:9.1e} {r.total_time:8.1f}")
    refine = ["brachistochrone"] if quick else ["brachistochrone", "shuttle_crossrange"]
    for name in refine:
        problem, published = PROBLEMS[name]()
        r = nlp.solve(problem, nodes=5 if name == "brachistochrone" else 20, refine=True, dynamics_tolerance=1e-4,
                      verifier=fly_controls)
        steps = ", ".join(f"{m.nodes} nodes: {m.error:.1e}" for m in r.mesh_history)
        print(f"refined {name}: {steps}; verified {r.success}, objective {r.objective:.7g}")
        out[f"{name}_refined"] = {"result": r, "published": published}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    for name in ("shuttle_crossrange", "shuttle_crossrange_heating"):
        r = out[name]["result"]
        problem = r.problem
        t = np.linspace(0.0, r.final_time, 400)
        x = r.state_function()(t)
        u = r.control_function()(t)
        q = [float(problem.conditions(xi, ui).heat_flux) / catalogue.BTU_FT2_S for xi, ui in zip(x, u)]
        ax1.plot(np.degrees(x[:, 1]), np.degrees(x[:, 2]), label=name)
        ax2.plot(t, q, label=name)
    ax2.axhline(70.0, color="k", ls="--", lw=0.8, label="limit 70 BTU/ft^2/s")
    ax1.set(xlabel="longitude [deg]", ylabel="latitude [deg]", title="Betts' shuttle: ground tracks")
    ax2.set(xlabel="time [s]", ylabel="wing heating [BTU/ft^2/s]", title="q = q_a(alpha) q_r")
    ax1.legend(fontsize=8)
    ax2.legend(fontsize=8)
    out["plot"] = save_figure(fig, out_dir, "shuttle.png")
    print(f"wrote {out['plot']}; max crossrange {math.degrees(-out['shuttle_crossrange']['result'].objective):.4f} deg")
    return out


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 10: published optima")
    for name in PROBLEMS:
        x = r[name]
        c.check(f"{name}: verified and within 1e-4 of the published optimum",
                x["result"].success and x["relative"] <= 1e-4,
                f"{x['result'].objective:.7g} vs {x['published']['objective']:.7g} ({x['relative']:.1e})")
    for name in [k for k in r if k.endswith("_refined")]:
        res = r[name]["result"]
        steps = ", ".join(f"{m.nodes}: {m.error:.1e}" for m in res.mesh_history)
        c.check(f"{name}: refinement ends verified with every mesh's error finite", res.success and all(
            np.isfinite(m.error) for m in res.mesh_history), steps)
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/10"))
