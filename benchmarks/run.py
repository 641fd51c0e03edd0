"""All benchmarks in one command: python benchmarks/run.py [--samples N]"""
import argparse

from drake_entry.benchmark import campaign_benchmark, nlp_benchmark, open_loop_benchmark, socp_benchmark

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--samples", type=int, default=100, help="campaign benchmark samples per backend")
    parser.add_argument("--nodes", type=int, default=40, help="NLP benchmark nodes / samples")
    args = parser.parse_args()
    open_loop_benchmark()
    socp_benchmark()
    nlp_benchmark(nodes=args.nodes)
    campaign_benchmark(samples=args.samples)
