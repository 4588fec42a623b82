"""``python -m fpga_robotics.sweep --bench``: campaign throughput on 1 worker and on N.

The same runs (``--bench-runs``, default 40: follow_person, 160x120, 10 s simulated, model
backend, seeds 0..) go through the whole campaign path twice, on an embedded cluster of 1
worker and of N (``--workers``, default the machine's cores). Printed: runs/s each way, the
speed-up against N, and the time outside ``run_scenario`` per run (planning, scheduling,
result writing), as a share of the run time.
"""

import os
import statistics
import tempfile
import time

from .api import run_campaign
from .campaign import load_campaign

__all__ = ["bench"]


def _campaign(runs, args):
    return load_campaign({
        "name": "bench", "scenarios": [args.scenarios or "follow_person"],
        "seeds": [*range(runs)], "backend": args.backend or "model",
        "resolution": args.resolution or "160x120", "duration": args.duration or 10.0})


def bench(args):
    n = args.workers or os.cpu_count() or 1
    runs = args.bench_runs
    print(f"campaign benchmark: {runs} runs of follow_person, {args.resolution or '160x120'}, "
          f"{args.duration or 10.0} s simulated, backend {args.backend or 'model'}")
    results = {}
    for workers in sorted({1, n}):
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix="sweep-bench-") as out:
            rows = run_campaign(_campaign(runs, args), out, workers=workers, record="none")
            from .results import read_meta

            meta = read_meta(out)
        total = time.perf_counter() - t0
        runs_wall = meta["runs_wall_s"]
        run_s = [r["run_s"] for r in rows]
        # Time a worker spends on a run outside run_scenario, plus the client's share.
        overhead = runs_wall * workers / runs - statistics.mean(run_s)
        results[workers] = (runs / runs_wall, overhead, statistics.median(run_s))
        print(f"  {workers} worker(s): {runs / runs_wall:.2f} runs/s "
              f"(runs {runs_wall:.1f} s, cluster start and build {total - runs_wall:.1f} s); "
              f"median run_scenario {statistics.median(run_s) * 1000:.0f} ms, outside it "
              f"{overhead * 1000:.1f} ms per run "
              f"({100 * overhead / statistics.mean(run_s):.1f}% of a run)")
    if n > 1:
        speedup = results[n][0] / results[1][0]
        print(f"  speed-up with {n} workers: {speedup:.2f}x ({speedup / n:.2f} x N)")
    return 0
