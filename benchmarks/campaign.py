"""Benchmark: closed-loop campaign throughput by backend (serial, processes, Dask)."""
from __future__ import annotations


def campaign_benchmark(*, samples: int = 100, scenario_name: str = "horus2b", seed: int = 7, rounds: int = 2) -> dict:
    """Runs per second of the closed-loop campaign on the same samples: one worker process,
    two local worker processes, and Dask distributed (LocalCluster, two workers). Includes
    start-up (worker spawn, planner and corridor per worker). The backends run in
    interleaved ``rounds`` and each keeps its best round: timing on a shared 2-core
    machine varies by about 20 % from minute to minute."""
    import tempfile
    import time

    from drake_entry.campaign.montecarlo import run_campaign

    cases = (("1 worker (serial)", "serial", 1), ("2 workers (processes)", "processes", 2),
             ("Dask LocalCluster, 2 workers", "dask", 2))
    walls = {c[0]: [] for c in cases}
    print(f"closed-loop {scenario_name} campaign, the same {samples} samples (seed {seed}) on each backend, "
          f"{rounds} interleaved round(s)")
    for r in range(rounds):
        for label, backend, workers in cases:
            with tempfile.TemporaryDirectory() as d:
                t0 = time.perf_counter()
                run_campaign(scenario_name, runs=samples, out_dir=d, seed=seed, workers=workers, backend=backend,
                             progress=False)
                walls[label].append(time.perf_counter() - t0)
            print(f"round {r + 1}: {label:30s} {walls[label][-1]:7.1f} s  {samples / walls[label][-1]:6.2f} runs/s")
    out = {label: samples / min(w) for label, w in walls.items()}
    for label, rate in out.items():
        print(f"best: {label:30s} {samples / rate:7.1f} s  {rate:6.2f} runs/s")
    one, two, dask = (out[c[0]] for c in cases)
    print(f"2 workers / 1 worker: {two / one:.2f}x (goal >= 1.8); Dask / processes: {dask / two:.2f} "
          f"(goal within 10 %); 1000 runs on 2 workers: {1000 / two / 60:.1f} min (goal < 5)")
    return out
