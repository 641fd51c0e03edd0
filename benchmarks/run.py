"""All benchmarks in one command: python benchmarks/run.py"""
from drake_entry.benchmark import open_loop_benchmark, socp_benchmark

if __name__ == "__main__":
    open_loop_benchmark()
    socp_benchmark()
