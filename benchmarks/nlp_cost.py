"""Benchmark: the NLP path's cost, this checkout against a baseline commit (default the previous
one), side by side in one run.

Cases (``--cases``; default all but the SCvx cross-check, four minutes on the baseline's dircol):

- ``guess:NAME``: the built-in initial guess of problem NAME (marv, shefex3, shuttle,
  shuttle_heating), core seconds and the guess's final time;
- ``solve:NAME:TRANSCRIPTION:NODES``: one solve from the built-in guess (SNOPT, the library's
  tolerance, 1e-7 for shefex3 as its examples), core seconds for guess and solve, our callbacks,
  the objective and the solver's verdict;
- ``scvx_crosscheck:TRANSCRIPTION``: example 07's NLP cross-check (the SCvx direct plan's problem,
  100 samples, SNOPT, tolerance 1e-6, verified), after the SCvx plan.

Each side runs in a fresh process on its own tree, one after the other, ``rounds`` times
interleaved, keeping each side's best; a case the baseline cannot run (a transcription it does
not have) says so. Objectives of both sides are printed next to each other: the solver's
answer, not only its time, must stay.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

from interface_cost import ROOT, _checkout, _installed_layout

DEFAULT_CASES = ("guess:marv", "guess:shefex3", "guess:shuttle", "guess:shuttle_heating",
                 "solve:shuttle:dircol:40", "solve:shuttle:hermite_simpson:40",
                 "solve:shefex3:dircol:100", "solve:shefex3:hermite_simpson:100")

_SCRIPT = r"""
import json, sys, time
from drake_entry.planning import nlp
from drake_entry.planning.nlp import catalogue
from drake_entry.planning.ocp_yaml import load_problem

def problem(name):
    if name in ("marv", "shefex3"):
        return load_problem(name)[0]
    return catalogue.shuttle_crossrange(heating_limit=name == "shuttle_heating")[0]

case = sys.argv[1].split(":")
kind = case[0]
out = {}
if kind == "guess":
    p = problem(case[1])
    t0 = time.process_time()
    t, X, U = nlp.initial_guess(p)
    out = {"core_s": time.process_time() - t0, "final_time": float(t[-1])}
elif kind == "solve":
    name, transcription, nodes = case[1], case[2], int(case[3])
    if transcription not in nlp.TRANSCRIPTIONS:
        out = {"missing": f"no transcription '{transcription}'"}
    else:
        p = problem(name)
        t0 = time.process_time()
        r = nlp.solve(p, transcription=transcription, solver="snopt", nodes=nodes,
                      tolerance=1e-7 if name == "shefex3" else 1e-8)
        out = {"core_s": time.process_time() - t0, "callbacks_s": r.callback_time, "calls": r.callback_calls,
               "objective": r.objective, "converged": bool(r.converged), "final_time": r.final_time}
elif kind == "scvx_crosscheck":
    transcription = case[1]
    if transcription not in nlp.TRANSCRIPTIONS:
        out = {"missing": f"no transcription '{transcription}'"}
    else:
        from drake_entry.diagrams.verification import fly_controls
        from drake_entry.guidance.scvx.as_ocp import nlp_form
        from drake_entry.guidance.scvx.guess import glide_guess
        from drake_entry.guidance.scvx.mission import ScvxMission
        from drake_entry.guidance.scvx.planner import plan_entry
        from drake_entry.models.atmosphere import US76Atmosphere
        from drake_entry.models.planet import Earth
        from drake_entry.models.vehicles import load_vehicle
        v, pl, atm, m = load_vehicle("sphynx"), Earth.oblate(), US76Atmosphere(), ScvxMission()
        plan = plan_entry(v, pl, atm, m, guess=glide_guess(v, pl, atm, m), verifier=fly_controls)
        p, start = nlp_form(plan)
        t0 = time.process_time()
        r = nlp.solve(p, transcription=transcription, solver="snopt", nodes=100, guess=start, tolerance=1e-6,
                      verifier=fly_controls)
        out = {"core_s": time.process_time() - t0, "callbacks_s": r.callback_time, "calls": r.callback_calls,
               "objective": r.objective, "converged": bool(r.success), "final_time": r.final_time}
print(json.dumps(out))
"""


def _run(site: str, case: str) -> dict:
    env = dict(os.environ, PYTHONPATH=site)
    res = subprocess.run([sys.executable, "-c", _SCRIPT, case], cwd=site, env=env, capture_output=True, text=True)
    if res.returncode != 0:
        return {"missing": (res.stderr.strip().splitlines() or ["failed"])[-1][:120]}
    return json.loads(res.stdout.strip().splitlines()[-1])


def nlp_cost_benchmark(*, baseline: str = "HEAD~1", rounds: int = 1, cases=None) -> list:
    cases = list(cases or DEFAULT_CASES)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        sides = {f"baseline {baseline}": _installed_layout(_checkout(baseline, tmp), tmp),
                 "this checkout": _installed_layout(ROOT, tmp)}
        print(f"NLP path, core seconds: {baseline} against this checkout, best of {rounds} interleaved round(s)")
        print(f"{'case':36s} {'side':20s} {'core s':>8s} {'callbacks s':>11s} {'calls':>9s} {'objective':>16s} "
              f"{'t_f s':>9s} {'verdict':>9s}")
        for case in cases:
            best = {}
            for _ in range(rounds):
                for label, site in sides.items():
                    r = _run(site, case)
                    if "missing" in r or label not in best or r["core_s"] < best[label]["core_s"]:
                        best[label] = r
            for label, r in best.items():
                if "missing" in r:
                    print(f"{case:36s} {label:20s} {r['missing']}")
                    continue
                print(f"{case:36s} {label:20s} {r['core_s']:8.2f} {r.get('callbacks_s', float('nan')):11.2f} "
                      f"{r.get('calls', 0):9d} {r.get('objective', float('nan')):16.10g} {r['final_time']:9.2f} "
                      f"{('converged' if r.get('converged') else 'NOT') if 'converged' in r else '':>9s}")
            b, c = best.values()
            if "missing" not in b and "missing" not in c:
                print(f"{'':36s} ratio this/baseline {c['core_s'] / b['core_s']:.3f}")
            rows.append({"case": case, **{k: v for k, v in zip(("baseline", "current"), best.values())}})
    return rows
