"""Benchmark: the NLP path side by side with dymos (pip, ``pip install -e ".[bench]"``) on
two problems dymos ships as examples, the same problem and node count, this machine.

- Brachistochrone to (2, 1) m (dymos.examples.brachistochrone's ODE, g = 9.81): optimum the
  cycloid. dymos GaussLobatto(order 3, N - 1 segments) is Hermite-Simpson on N nodes, the
  transcription of our 'dircol' with N samples; our LGL on N nodes beside them.
- Betts' Space Shuttle maximum crossrange (dymos.examples.shuttle_reentry's ODE, no heating
  limit): published 34.1412 deg (Betts 2010, Sec. 6.1); dymos Radau(order 3, N / 3 segments)
  against our LGL and dircol on N nodes.

dymos runs with OpenMDAO's ScipyOptimizeDriver (SLSQP) because pyOptSparse (its IPOPT and
SNOPT drivers) has no pip distribution; dymos starts from the linear guesses its own examples
use, we from our built-in guess. Each side is timed from building the problem to the verified
answer (ours: ``total_time``; dymos: setup, coloring and run_driver).
"""
from __future__ import annotations

import math
import time
import warnings


def _dymos_brachistochrone(nodes: int, g: float = 9.81):
    import dymos as dm
    import openmdao.api as om
    from dymos.examples.brachistochrone.brachistochrone_ode import BrachistochroneODE

    p = om.Problem()
    p.driver = om.ScipyOptimizeDriver(optimizer="SLSQP", tol=1e-8, maxiter=500, disp=False)
    p.driver.declare_coloring()
    phase = dm.Phase(ode_class=BrachistochroneODE,
                     transcription=dm.GaussLobatto(num_segments=nodes - 1, order=3))
    p.model.add_subsystem("traj", dm.Trajectory()).add_phase("phase0", phase)
    phase.set_time_options(fix_initial=True, duration_bounds=(0.1, 5.0))
    # dymos' ODE has y up: our (0, 0) -> (2, 1) with y down is y: 0 -> -1
    phase.add_state("x", fix_initial=True, fix_final=True)
    phase.add_state("y", fix_initial=True, fix_final=True)
    phase.add_state("v", fix_initial=True, fix_final=False, lower=0.0)
    phase.add_control("theta", units="rad", lower=0.0, upper=math.pi, continuity=True, rate_continuity=True)
    phase.add_parameter("g", units="m/s**2", opt=False, val=g)
    phase.add_objective("time", loc="final")
    p.setup()
    phase.set_time_val(initial=0.0, duration=1.0)
    phase.set_state_val("x", [0.0, 2.0])
    phase.set_state_val("y", [0.0, -1.0])
    phase.set_state_val("v", [0.0, 5.0])
    phase.set_control_val("theta", [0.01, math.radians(100.0)])
    return p, lambda: float(p.get_val("traj.phase0.timeseries.time")[-1, 0])


def _dymos_shuttle(nodes: int):
    import dymos as dm
    import numpy as np
    import openmdao.api as om
    from dymos.examples.shuttle_reentry.shuttle_ode import ShuttleODE

    p = om.Problem()
    p.driver = om.ScipyOptimizeDriver(optimizer="SLSQP", tol=1e-6, maxiter=1000, disp=False)
    p.driver.declare_coloring()
    phase = dm.Phase(ode_class=ShuttleODE, transcription=dm.Radau(num_segments=max(2, nodes // 3), order=3))
    p.model.add_subsystem("traj", dm.Trajectory()).add_phase("phase0", phase)
    deg = math.pi / 180.0
    phase.set_time_options(fix_initial=True, units="s", duration_ref=200)
    phase.add_state("h", fix_initial=True, fix_final=True, units="ft", rate_source="hdot", targets=["h"], lower=0,
                    ref0=75000, ref=300000, defect_ref=1000)
    phase.add_state("gamma", fix_initial=True, fix_final=True, units="rad", rate_source="gammadot",
                    targets=["gamma"], lower=-89 * deg, upper=89 * deg)
    phase.add_state("phi", fix_initial=True, fix_final=False, units="rad", rate_source="phidot", lower=0,
                    upper=89 * deg)
    phase.add_state("psi", fix_initial=True, fix_final=False, units="rad", rate_source="psidot", targets=["psi"],
                    lower=0, upper=90 * deg)
    phase.add_state("theta", fix_initial=True, fix_final=False, units="rad", rate_source="thetadot",
                    targets=["theta"], lower=-89 * deg, upper=89 * deg)
    phase.add_state("v", fix_initial=True, fix_final=True, units="ft/s", rate_source="vdot", targets=["v"],
                    lower=500, ref0=2500, ref=25000)
    phase.add_control("alpha", units="rad", lower=-90 * deg, upper=90 * deg, targets=["alpha"])
    phase.add_control("beta", units="rad", lower=-89 * deg, upper=1 * deg, targets=["beta"])
    phase.add_objective("theta", loc="final", ref=-0.01)
    p.setup()
    phase.set_time_val(initial=0, duration=2000, units="s")
    phase.set_state_val("h", [260000, 80000], units="ft")
    phase.set_state_val("gamma", [-1 * deg, -5 * deg], units="rad")
    phase.set_state_val("phi", [0, 75 * deg], units="rad")
    phase.set_state_val("psi", [90 * deg, 10 * deg], units="rad")
    phase.set_state_val("theta", [0, 25 * deg], units="rad")
    phase.set_state_val("v", [25600, 2500], units="ft/s")
    phase.set_control_val("alpha", [17.4 * deg, 17.4 * deg], units="rad")
    phase.set_control_val("beta", [-75 * deg, 0 * deg], units="rad")
    return p, lambda: -float(np.asarray(p.get_val("traj.phase0.timeseries.theta", units="rad"))[-1, 0])


def _run_dymos(build, nodes):
    """Build and run one dymos problem inside a temporary directory (OpenMDAO writes its
    reports and coloring files into <problem>_out/ under the working directory)."""
    import os
    import tempfile

    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="dymos_") as work, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        os.chdir(work)
        try:
            t0 = time.perf_counter()
            p, objective = build(nodes)
            outcome = p.run_driver()
            wall = time.perf_counter() - t0
            value = objective()
        finally:
            os.chdir(here)
    ok = bool(getattr(outcome, "success", not outcome))  # a DriverResult, or True on failure (older OpenMDAO)
    return {"ok": ok, "objective": value, "wall_s": wall}


def dymos_benchmark(*, nodes: int = 31) -> dict:
    """Both problems, dymos and ours, printed side by side with wall-time ratios."""
    import dataclasses as dc

    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning import nlp
    from drake_entry.planning.nlp import catalogue

    brachistochrone, cycloid = catalogue.brachistochrone()
    # the same problem on both sides: t_f in [0.1, 5] s as dymos' example poses it (from the
    # straight-line guess an open t_f lets DirectCollocation drift to t_f ~ 1e3-1e6 s)
    brachistochrone = dc.replace(brachistochrone, final_time=(0.1, 5.0))
    cases = {"brachistochrone": ((brachistochrone, cycloid), _dymos_brachistochrone),
             "shuttle_crossrange": (catalogue.shuttle_crossrange(), _dymos_shuttle)}
    out = {}
    for name, ((problem, published), build) in cases.items():
        print(f"{name}: {nodes} nodes, published objective {published['objective']:.7g} ({published['source']})")
        print(f"  {'who':34s} {'ok':5s} {'objective':>12s} {'rel. to published':>18s} {'wall [s]':>9s} "
              f"{'dymos / this':>13s}")
        try:
            peer = _run_dymos(build, nodes)
        except Exception as e:  # noqa: BLE001 - a peer failure is reported, not fatal
            peer = {"ok": False, "objective": float("nan"), "wall_s": float("nan"), "error": str(e)[:120]}
        rows = {"dymos (SLSQP)": peer}
        for tx in ("lgl", "dircol"):
            r = nlp.solve(problem, transcription=tx, nodes=nodes, verifier=fly_controls)
            rows[f"drake_entry {tx} ({r.solver})"] = {"ok": r.success, "objective": r.objective,
                                                      "wall_s": r.total_time}
        for who, row in rows.items():
            rel = abs(row["objective"] - published["objective"]) / abs(published["objective"])
            ratio = peer["wall_s"] / row["wall_s"] if row["wall_s"] > 0 else float("nan")
            print(f"  {who:34s} {str(row['ok']):5s} {row['objective']:12.7g} {rel:18.2e} {row['wall_s']:9.2f} "
                  f"{ratio:13.2f}" + (f"  ({peer['error']})" if who.startswith("dymos") and "error" in peer else ""))
        out[name] = rows
    return out
