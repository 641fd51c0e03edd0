"""Example 7: paper 001's successive convexification (SCvx) on SPHYNX: plan the minimum-heat-load
entry from the Table 1 interface to the Azores site (direct bank and angle of attack with their
rates as controls, eqs. 54-55, the form of the paper's Tables 2 and 4-7; free final time), then
fly the plan's bank and alpha with the Drake Simulator and compare with the plan and the site.
``--formulation lossless`` plans the lossless bank (eqs. 37-45) instead: its relaxed |u| < 1 shows
up as a flown error, and the planner says so. The direct plan is then cross-checked: the same
problem (``guidance.scvx.as_ocp``) solved by the NLP path (Hermite-Simpson collocation + SNOPT) from
the same glide guess, its controls flown by the Drake Simulator; the two heat loads agree
within 1 % (0.5 % measured).

SPHYNX's aerodynamic table is not public: the vehicle carries the paper's mass, area and nose
radius with a labelled representative aerodynamic model (drake_entry/vehicles/sphynx.yaml).

    python examples/07_scvx_entry.py [--quick] [--out out/examples/07]
"""
import math

from drake_entry.claims import Claims, run_example
from drake_entry.diagrams.verification import fly_controls
from drake_entry.guidance.scvx.as_ocp import nlp_form
from drake_entry.guidance.scvx.mission import ScvxMission
from drake_entry.guidance.scvx.planner import plan_entry
from drake_entry.guidance.scvx.plots import plan_figure
from drake_entry.guidance.scvx.settings import FORMULATIONS, EntryProblemSettings
from drake_entry.models.atmosphere import US76Atmosphere
from drake_entry.models.planet import Earth
from drake_entry.models.vehicles import load_vehicle
from drake_entry.planning import nlp


def main(quick: bool = False, out_dir: str = "out/examples/07", formulation: str = "direct") -> dict:
    vehicle, planet, atmosphere = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere()
    mission = ScvxMission()  # paper 001 Table 1 and eqs. 64-70
    # 100 nodes (33 segments of 4 LGL nodes); --quick uses the same mesh: the plan takes ~5 s
    settings = EntryProblemSettings(segments=33, nodes_per_segment=4, formulation=formulation, objective="heat_load")

    def progress(k, rec):
        print(f"  iteration {k + 1:2d}: merit {rec.merit:9.4g}  trust radius {rec.trust_radius:8.2g}  "
              f"{'accepted' if rec.accepted else 'rejected'}  max defect {rec.max_defect:.1e}")

    # the plan's verdict flies its controls with the Drake Simulator through the closed loop's actuators
    plan = plan_entry(vehicle, planet, atmosphere, mission, problem_settings=settings,
                      progress=None if quick else progress, verifier=fly_controls)
    print(f"plan: {plan.message}; heat load {plan.objective:.1f} MJ/m^2, t_f {plan.final_time:.0f} s, "
          f"{plan.iterations} iterations, {plan.build_time + plan.solve_time:.1f} s; lossless gap "
          f"{plan.lossless_gap:.3f}; planned miss {plan.miss_m / 1e3:.1f} km; its controls flown end "
          f"{plan.propagated_error_m / 1e3:.2f} km from it")
    m = plan.metrics
    print(f"paper 001 Table 6 form: integrated |bank rate| {m['bank_effort_deg']:.0f} deg, max {m['max_bank_rate_deg_s']:.2f} "
          f"deg/s; integrated |alpha rate| {m['alpha_effort_deg']:.1f} deg, max {m['max_alpha_rate_deg_s']:.3f} deg/s")
    flight = plan.flown
    print(f"flown by Drake: {flight.from_plan_m / 1e3:.2f} km from the plan, {flight.from_site_m / 1e3:.2f} km "
          f"from the site; DRS altitude {flight.drs['altitude_m'] / 1e3:.2f} km, Mach {flight.drs['mach']:.2f}, "
          f"vertical speed {flight.drs['vertical_speed_m_s']:.1f} m/s; DRS box met: {flight.drs_ok}")
    crosscheck = None
    if formulation == "direct" and not quick:  # the same problem by the NLP path, from the same glide guess
        problem, start = nlp_form(plan)
        crosscheck = nlp.solve(problem, transcription="hermite_simpson", solver="snopt", nodes=100, guess=start, tolerance=1e-6,
                               verifier=fly_controls)
        flown = nlp.propagate(problem, crosscheck, fly_controls).terminal_error.get("position_m", math.nan)
        print(f"NLP path (Hermite-Simpson collocation + SNOPT, {crosscheck.nodes} samples): {crosscheck.message}; heat load "
              f"{crosscheck.objective / 1e6:.2f} MJ/m^2 (SCvx {plan.objective / (crosscheck.objective / 1e6) - 1:+.2%}), "
              f"t_f {crosscheck.final_time:.0f} s, {crosscheck.solve_time:.1f} s; flown {flown / 1e3:.2f} km from it")

    plot = plan_figure(plan, flight, mission.site(planet), out_dir, title=f"SCvx minimum heat load ({plan.formulation}), "
                       "SPHYNX (representative aero), paper 001 Table 1 mission: what is planned and what the "
                       "Drake Simulator flies of it")
    return {"plan": plan, "flight": flight, "plot": plot, "nlp": crosscheck}


def check(r: dict, quick: bool = False) -> Claims:
    """What this example shows, checked."""
    c = Claims("example 07: an SCvx plan of SPHYNX")
    plan, flight = r["plan"], r["flight"]
    c.check("the plan converges and is verified by its flight through the actuators", plan.success, plan.message)
    c.check("flown by the Drake Simulator through the actuators: within 5 km of the plan and 15 km of the site",
            flight.from_plan_m < 5e3 and flight.from_site_m < 15e3,
            f"{flight.from_plan_m / 1e3:.2f} km, {flight.from_site_m / 1e3:.2f} km")
    c.check("the flown DRS point is inside the box (10-13 km, subsonic, vertical speed)", flight.drs_ok,
            f"{flight.drs['altitude_m'] / 1e3:.2f} km, Mach {flight.drs['mach']:.2f}")
    c.check("the flight holds every path limit (q, n, bank, gamma)", all(k.held for k in flight.checks),
            flight.violations_text() or "all held")
    if r["nlp"] is not None:
        q = r["nlp"].objective / 1e6
        c.check("the NLP path solves the same problem, verified", r["nlp"].success, r["nlp"].message[:120])
        c.check("SCvx's heat load is within 1 % of the NLP's", abs(plan.objective / q - 1.0) < 0.01,
                f"{plan.objective:.1f} vs {q:.1f} MJ/m^2")
    return c


if __name__ == "__main__":
    raise SystemExit(run_example(__doc__, main, check, out="out/examples/07",
                                 options=[("--formulation", {"default": "direct", "choices": list(FORMULATIONS)})]))
