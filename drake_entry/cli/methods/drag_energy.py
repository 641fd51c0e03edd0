"""The drag-energy method's commands: ``drake-entry plan`` (the corridor and the reference planned
at engagement, with its extracted states against an open-loop propagation of the extracted bank,
paper 000 Figs. 3-5) and ``drake-entry fit-horus`` (the HORUS-2B aerodynamic fit of paper 000
eqs. 32-33). This module is at the CLI layer (it flies diagrams)."""
from __future__ import annotations

import dataclasses as dc
import sys

import numpy as np

from drake_entry.cli.common import Command

__all__ = ["plan_report", "propagate_extracted_bank", "fit_horus", "COMMANDS"]


def plan_report(scenario, out_dir: str) -> int:
    """Fly to engagement (plan once), plot and print the plan; exit code."""
    from drake_entry.diagrams.closed_loop import fly
    from drake_entry.guidance.drag_energy.plots import corridor_plot, extraction_plot

    scenario.guidance.replan_period_s = 0.0
    res = fly(scenario)
    mem = res.guidance.details
    ref = mem.first_reference
    if ref is None:
        print(f"drake-entry: the guidance never engaged: {res.message}", file=sys.stderr)
        return 1
    p = ref.problem
    E0, Ef = scenario.entry_energy(), p.Ef
    paths = corridor_plot(p.corridor, E0, Ef, out_dir, reference=ref, title=f"{scenario.name}: drag-energy plan")
    prop = propagate_extracted_bank(scenario, ref, mem.engaged_state)
    paths += extraction_plot(ref, prop, p.planet, out_dir, title=f"{scenario.name}: extraction")
    viol = ref.corridor_violation()
    x = ref.extraction
    print(f"engaged at t = {mem.engaged_at:.0f} s, e = {(E0 - p.E0) / (E0 - Ef):.3f}, D0 = {p.D0:.3f} m/s^2, "
          f"range to go {p.range_to_go / 1e3:.1f} km")
    print(f"SOCP ({p.solver}, {p.n_nodes} nodes): {ref.message}; build {1e3 * ref.build_time:.1f} ms, "
          f"solve {1e3 * ref.solve_time:.1f} ms")
    print(f"binding: {[(b['bound'], b['nodes']) for b in ref.binding]}; between nodes: "
          f"{100 * viol['above_max']:.2f} % above D_max (at e = {viol['above_max_at_e']:.3f}), "
          f"{100 * viol['below_min']:.2f} % below D_min")
    print(f"extracted: final h {x.h[-1] / 1e3:.2f} km, V {x.V[-1]:.0f} m/s; bank saturated at "
          f"{int(x.saturated.sum())} nodes; open-loop propagation ends at h {prop.state[-1, 0] / 1e3:.2f} km")
    print(f"wrote {len(paths)} plots to {out_dir}")
    return 0


def propagate_extracted_bank(scenario, reference, x0):
    """Open-loop flight from x0 with the extracted bank magnitude sigma(E) and alpha(E)
    (paper 000 Fig. 5: extracted states against open-loop propagation); a ``Trajectory``."""
    from drake_entry.diagrams.open_loop import simulate

    sc = dc.replace(scenario)
    x = reference.extraction
    E = reference.energy[::-1]  # increasing
    sc.bank = dc.replace(scenario.bank, variable="energy", breakpoints=list(E),
                         values_deg=list(np.degrees(x.sigma[::-1])), smooth=False)
    sc.alpha = dc.replace(scenario.alpha, variable="energy", breakpoints=list(reference.problem.alpha.breakpoints),
                          values_deg=list(np.degrees(reference.problem.alpha.values)),
                          smooth=reference.problem.alpha.smooth)
    sc.terminal = dc.replace(scenario.terminal, altitude_km=None, mach=None, velocity_m_s=None,
                             energy_MJ_kg=reference.problem.Ef / 1e6)
    sc.simulation = dc.replace(scenario.simulation, integrator="runge_kutta5", accuracy=1e-8)
    return simulate(sc, initial_state=x0)


def fit_horus(args) -> int:
    """Refit paper 000 eqs. 32-33 to the clean M-692 cells and print the residuals; exit 0."""
    from drake_entry.models.aerodynamics import fit_horus_forms
    from drake_entry.models.vehicles import load_vehicle

    rep = fit_horus_forms(initial_aL=load_vehicle("horus2b").aero.aL)
    print("least-squares fit of paper 000 eqs. 32-33 to the clean, untrimmed M-692 cells")
    print(f"C_D: {rep.cells_CD} cells, RMS {rep.rms_CD:.4f}, max |residual| {rep.max_CD:.4f}")
    print(f"C_L: {rep.cells_CL} cells, RMS {rep.rms_CL:.4f}, max |residual| {rep.max_CL:.4f}")
    print("aD =", [float(f"{v:.10g}") for v in rep.aD])
    print("aL =", [float(f"{v:.10g}") for v in rep.aL])
    return 0


COMMANDS = (Command("fit-horus", "refit paper 000 eqs. 32-33 to the M-692 table; print residuals",
                    lambda parser: None, fit_horus),)
