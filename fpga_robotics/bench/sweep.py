"""``fpga-robotics bench sweep`` (also ``python -m fpga_robotics.sweep --bench``): campaign
throughput on 1 worker and on N.

The same runs (``--bench-runs``, default 40: follow_person, 160x120, 10 s simulated, model
backend, seeds 0..) go through the whole campaign path on an embedded cluster of 1 worker and
of N (``--workers``, default the machine's cores), alternately, ``--bench-repeats`` times
(default 3; medians printed). Printed: runs/s each way and the speed-up against N; a run's wall
and CPU time (a run slower for the same CPU time waited for a core: other work on the
machine); the share of the workers' time spent inside ``run_scenario``; and the time outside it per run
(planning, scheduling, result writing) with 1 worker, as a share of the run. The machine's
load average is printed too: other work on the machine shows as slower runs, not overhead.
"""

import os
import statistics
import tempfile
import time
from types import SimpleNamespace

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.sweep.api import run_campaign
from fpga_robotics.sweep.campaign import load_campaign
from fpga_robotics.sweep.plan import make_plan
from fpga_robotics.sweep.results import read_meta

__all__ = ["REPEATS", "RUNS", "bench", "main", "measure"]

#: Runs per measurement and measurements each way, by default.
RUNS = 40
REPEATS = 3


#: What a run is when an option does not say.
DEFAULTS = {
    "scenarios": "follow_person",
    "backend": "model",
    "resolution": "160x120",
    "duration": 10.0,
}


def _run_options(args):
    """The options that shape a run, each defaulted only when not given: an empty or zero
    value is checked with the campaign, not replaced."""
    return {
        k: default if getattr(args, k) is None else getattr(args, k)
        for k, default in DEFAULTS.items()
    }


def _campaign(runs, args):
    options = _run_options(args)
    return load_campaign(
        {"name": "bench", **options, "scenarios": [options["scenarios"]], "seeds": [*range(runs)]}
    )


def _once(runs, workers, args):
    with tempfile.TemporaryDirectory(prefix="sweep-bench-") as out:
        rows = run_campaign(_campaign(runs, args), out, workers=workers, record="none")
        meta = read_meta(out)
    wall = meta["runs_wall_s"]
    run_s = [r["run_s"] for r in rows]
    return {
        "rps": runs / wall,
        "inside": sum(run_s) / (workers * wall),
        "outside_s": wall * workers / runs - statistics.mean(run_s),
        "run_s": statistics.median(run_s),
        "cpu_s": statistics.median(r["cpu_s"] for r in rows),
    }


def bench(args):
    """``python -m fpga_robotics.sweep --bench``: print the figures; exit code 0."""
    measure(
        SimpleNamespace(
            **{
                **vars(args),
                "bench_runs": args.bench_runs or RUNS,
                "bench_repeats": args.bench_repeats or REPEATS,
            }
        )
    )
    return 0


def measure(args):
    """Print the figures and return them: per worker count, the medians."""
    n = args.workers or os.cpu_count() or 1
    runs, repeats = args.bench_runs, args.bench_repeats
    make_plan(_campaign(runs, args))  # every run checked before the first line
    options = _run_options(args)
    compared = f"1 and {n} workers alternately" if n > 1 else "1 worker"
    print(
        f"campaign benchmark: {runs} runs of {options['scenarios']}, "
        f"{options['resolution']}, {options['duration']} s simulated, backend "
        f"{options['backend']}; {compared}, {repeats} times; "
        f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"
    )
    counts = sorted({1, n})
    samples = {w: [] for w in counts}
    t0 = time.perf_counter()
    for _ in range(repeats):
        for workers in counts:
            samples[workers].append(_once(runs, workers, args))
    med = {
        w: {k: statistics.median(s[k] for s in samples[w]) for k in samples[w][0]} for w in counts
    }
    for workers in counts:
        m = med[workers]
        print(
            f"  {workers} worker(s): {m['rps']:.2f} runs/s, median run_scenario "
            f"{m['run_s'] * 1000:.0f} ms (CPU {m['cpu_s'] * 1000:.0f} ms), {m['inside']:.0%} "
            f"of the workers' time inside run_scenario"
        )
    one = med[1]
    print(
        f"  outside run_scenario with 1 worker: {one['outside_s'] * 1000:.1f} ms per run "
        f"({100 * one['outside_s'] / one['run_s']:.1f}% of a run)"
    )
    if n > 1:
        speedup = med[n]["rps"] / med[1]["rps"]
        print(
            f"  speed-up with {n} workers: {speedup:.2f}x ({speedup / n:.2f} x N); a run "
            f"takes {med[n]['run_s'] / med[1]['run_s']:.2f}x as long as with 1 worker"
        )
    print(f"  ({time.perf_counter() - t0:.0f} s; load average now {os.getloadavg()[0]:.1f})")
    return {
        str(w): {**m, "run_ms": m["run_s"] * 1e3, "cpu_ms": m["cpu_s"] * 1e3}
        for w, m in med.items()
    }


def _options(parser):
    parser.add_argument(
        "--runs", type=int, default=RUNS, help=f"runs per measurement (default {RUNS})"
    )
    parser.add_argument("--workers", type=int, help="N (default: the machine's cores)")
    parser.add_argument("--scenario", help="the scenario (default follow_person)")
    parser.add_argument("--backend", help="the design's backend (default model)")
    parser.add_argument("--resolution", help="default 160x120")
    parser.add_argument("--duration", type=float, help="simulated seconds a run (default 10)")


def _check(args):
    if not 1 <= args.runs <= 10000:
        raise UsageError(f"--runs must be 1..10000, got {args.runs}")
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise UsageError(f"--workers must be 1..256, got {args.workers}")


def run(args):
    figures = measure(
        SimpleNamespace(
            workers=args.workers,
            bench_runs=args.runs,
            bench_repeats=args.repeats,
            scenarios=args.scenario,
            backend=args.backend,
            resolution=args.resolution,
            duration=args.duration,
        )
    )
    return figures


main = scaffold.command(run, __doc__, name="sweep", options=_options, check=_check, repeats=REPEATS)
