"""Benchmark: the NLP path, both transcriptions x both solvers from the same starts."""
from __future__ import annotations


def nlp_benchmark(*, problem_name: str = "marv", nodes: int = 40, tolerance: float = 1e-6) -> dict:
    """The same optimal-control problem by both transcriptions (LGL pseudospectral, Drake
    DirectCollocation) and both solvers (Ipopt, SNOPT), all from the same start (the
    propagated guess, then a 30-node LGL solution): solve time, objective, final time and
    the Drake-propagated terminal position error, side by side in one run; the solve time
    split into our Python callbacks (models, Jacobians, AutoDiff packing) and the solver's
    own share (with Drake's conversions)."""
    from drake_entry.diagrams.verification import fly_controls
    from drake_entry.planning import nlp
    from drake_entry.planning.ocp_yaml import load_problem

    problem, _ = load_problem(problem_name)
    starts = {"propagated guess": nlp.initial_guess(problem)}
    seed = nlp.solve(problem, transcription="lgl", solver="snopt", nodes=30, tolerance=tolerance,
                     verifier=fly_controls)
    if seed.success:
        starts["30-node LGL/SNOPT solution"] = seed
    out = {}
    for start, guess in starts.items():
        print(f"{problem_name}: {nodes} nodes / samples, tolerance {tolerance:g}, all from the {start}")
        print(f"{'transcription':14s} {'solver':7s} {'ok':3s} {'solve [s]':>10s} {'callbacks [s]':>14s} "
              f"{'solver own':>10s} {'objective':>12s} {'t_f [s]':>9s} {'prop. miss [m]':>15s}")
        for transcription in nlp.TRANSCRIPTIONS:
            for solver in nlp.SOLVERS:
                try:
                    r = nlp.solve(problem, transcription=transcription, solver=solver, nodes=nodes, guess=guess,
                                  tolerance=tolerance, verifier=fly_controls)
                except Exception as e:  # noqa: BLE001 - one failing combination is reported, not fatal
                    print(f"{transcription:14s} {solver:7s} error: {type(e).__name__}: {str(e).splitlines()[0][:80]}")
                    continue
                check = r.verification.flight if r.success else None
                miss = check.terminal_error.get("position_m", float("nan")) if check else float("nan")
                out[(start, transcription, solver)] = dict(success=r.success, solve_time=r.solve_time,
                                                           callback_time=r.callback_time, objective=r.objective,
                                                           final_time=r.final_time, miss_m=miss)
                own = 1.0 - r.callback_time / r.solve_time if r.solve_time > 0 else float("nan")
                note = "" if check is None or "failed" not in check.terminal_error else "  (propagation did not reach t_f)"
                print(f"{transcription:14s} {solver:7s} {'yes' if r.success else 'no':3s} {r.solve_time:10.2f} "
                      f"{r.callback_time:14.2f} {own:10.0%} {r.objective:12.6g} {r.final_time:9.2f} {miss:15.1f}{note}")
    return out
