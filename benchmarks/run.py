"""Benchmarks, each printing its figures and ratios measured side by side in one run.

    python benchmarks/run.py [open-loop|socp|nlp|nlp-cost|dymos|campaign|interface-cost|method-cost|memory|paper001|aborts|paper003|paper004|examples|all] [options]

open-loop       Drake open loop vs scipy solve_ivp at equal accuracy (ratio)
socp            both SOCP planners with Clarabel vs SCS: drag-energy SOCP by node count, SCvx
                nominal plan, closed-loop drag-energy campaign
nlp             NLP path: LGL / DirectCollocation x Ipopt / SNOPT from the same starts
nlp-cost        NLP path's guesses and solves (--cases guess:NAME, solve:NAME:TRANSCRIPTION:NODES,
                scvx_crosscheck:TRANSCRIPTION), core seconds vs a baseline commit (--baseline,
                default the previous commit), objectives side by side
dymos           NLP path vs dymos (pip extra "bench"; not in "all") on the Brachistochrone and
                Betts' shuttle, same problem and nodes (default 31)
campaign        closed-loop campaign runs/s: 1 worker, 2 processes, Dask (ratios)
interface-cost  paper-000 campaign cost per sample: this checkout vs a baseline commit
method-cost     every packaged guidance scenario: core seconds per sample split into the plant
                (the scenario's own, native or Python), on-board planning and the rest, vs a
                baseline commit (--baseline, default the previous commit; --scenarios names)
memory          a campaign worker's resident memory and live Python systems after its set-up
                and each sample, growth per sample, vs a baseline commit (--baseline, default
                the previous commit; --scenarios names)
paper001        paper 001: SCvx nominal plan time and iterations by mesh vs the paper, flown by Drake
aborts          paper 001: the 9 x 9 orbital-abort map through the campaign engine vs the 15-min goal
paper003        paper 003: AMPI database storage, LD-HD reconstruction, synthesis vs OCP CPU time,
                eq. 13 accuracy and open-loop miss of AMPI and NTT references (--cases)
paper004        paper 004: Table 1 over seeds, scipy baselines, cases, two parameters, figures
examples        every example's wall time, exit status (its claims) and last line against the
                time docs/examples.md gives (--mode quick|full|both, --only 05 07, --write;
                not in "all")
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("which", nargs="?", default="all",
                        choices=("all", "open-loop", "socp", "nlp", "nlp-cost", "dymos", "campaign", "interface-cost",
                                 "method-cost", "memory",
                                 "paper001", "aborts", "paper003", "paper004", "examples"))
    parser.add_argument("--samples", type=int, default=100, help="campaign: samples per backend")
    parser.add_argument("--rounds", type=int, default=2, help="campaign / interface-cost: interleaved rounds")
    parser.add_argument("--nodes", type=int, default=40, help="nlp: nodes / samples")
    parser.add_argument("--repeats", type=int, default=3, help="open-loop / socp: repeats (best is kept)")
    parser.add_argument("--baseline", default=None,
                        help="interface-cost: git revision to compare with (default: the commit before the "
                             "guidance-method interface)")
    parser.add_argument("--grid", type=int, nargs=2, default=(9, 9), metavar=("ROWS", "COLUMNS"),
                        help="aborts: EIP grid size")
    parser.add_argument("--seeds", type=int, default=20, help="paper004: seeds per swarm method (Table 1)")
    parser.add_argument("--cases", nargs="*", default=None,
                        help="paper003: entries of the accuracy study (one number, default 100); nlp-cost: case names")
    parser.add_argument("--out", default="out/paper004", help="paper004: figure directory")
    parser.add_argument("--mode", default="both", choices=("quick", "full", "both"), help="examples: which runs")
    parser.add_argument("--only", nargs="*", default=None, help="examples: numbers or names to run")
    parser.add_argument("--write", action="store_true", help="examples: write the measured times into the docs")
    parser.add_argument("--scenarios", nargs="*", default=None,
                        help="method-cost, memory: packaged scenarios to measure; method-cost also variants "
                        "NAME:field=value[,field=value] (e.g. cav_h_paper004:guidance.replan_period_s=100)")
    args = parser.parse_args()
    if args.which == "examples":  # minutes of wall time: on request only
        from example_times import examples_benchmark

        examples_benchmark(mode=args.mode, only=args.only, write=args.write)
    if args.which in ("all", "open-loop"):
        from open_loop import open_loop_benchmark

        open_loop_benchmark(repeats=args.repeats)
    if args.which in ("all", "socp"):
        from socp import campaign_solver_benchmark, scvx_solver_benchmark, socp_benchmark

        socp_benchmark(repeats=max(args.repeats, 5))
        scvx_solver_benchmark()
        campaign_solver_benchmark()
    if args.which in ("all", "nlp"):
        from nlp import nlp_benchmark

        nlp_benchmark(nodes=args.nodes)
    if args.which in ("all", "nlp-cost"):
        from nlp_cost import nlp_cost_benchmark

        nlp_cost_benchmark(baseline=args.baseline or "HEAD~1", rounds=args.rounds if args.which == "nlp-cost" else 1,
                           cases=args.cases if args.which == "nlp-cost" else None)
    if args.which == "dymos":  # needs the 'bench' extra, so not part of 'all'
        from dymos_peer import dymos_benchmark

        dymos_benchmark(nodes=args.nodes if args.nodes != 40 else 31)
    if args.which in ("all", "campaign"):
        from campaign import campaign_benchmark

        campaign_benchmark(samples=args.samples, rounds=args.rounds)
    if args.which in ("all", "interface-cost"):
        from interface_cost import interface_cost_benchmark

        interface_cost_benchmark(baseline=args.baseline, rounds=args.rounds)
    if args.which in ("all", "method-cost"):
        from method_cost import method_cost_benchmark

        method_cost_benchmark(baseline=args.baseline or "HEAD~1", rounds=args.rounds, only=args.scenarios)
    if args.which in ("all", "memory"):
        from memory import memory_benchmark

        memory_benchmark(baseline=args.baseline or "HEAD~1", only=args.scenarios)
    if args.which in ("all", "paper001"):
        from paper001 import paper001_benchmark

        paper001_benchmark()
    if args.which in ("all", "aborts"):
        from aborts import aborts_benchmark

        aborts_benchmark(rows=args.grid[0], columns=args.grid[1])
    if args.which in ("all", "paper003"):
        from paper003 import paper003_benchmark

        paper003_benchmark(cases=int(args.cases[0]) if args.cases else 100)
    if args.which in ("all", "paper004"):
        from paper004 import paper004_study

        paper004_study(seeds=args.seeds, out_dir=args.out)
