"""``fpga-robotics bench fork``: a parameter sweep of design variants on one scenario, run in
full against forked from one reference run (fpga_robotics.loop.fork, pin_fork).

The variants are the scenario with ``--key`` set to each of ``--values``; each is run in full
(``run_scenario``), then the scenario's own design runs once as the reference and every
variant is forked from it, all in one process, one after the other. Every forked result is
checked against the variant's full run (summary equal, the wall-clock fields excepted). The
figures are the CPU-time ratio of the full runs to the forked ones (the reference included)
and where the variants parted from the reference.
"""

import statistics
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.checks import envelopes
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.loop.pin_fork import reference_run
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BACKEND_NAMES

__all__ = ["main", "measure"]

#: Summary fields that measure the machine, not the run.
_TIMES = ("wall_time_s", "ms_per_frame", "realtime_factor", "cpu_ms_per_frame", "cycles_per_wall_s")


def _same(a, b):
    return {k: v for k, v in a.items() if k not in _TIMES} == {
        k: v for k, v in b.items() if k not in _TIMES
    }


def measure(scenario, variants, backend, checkpoint_every=30):
    """``(full_cpu_s, forked_cpu_s, parted)``: CPU seconds of the variants' full runs and of
    the reference plus the forked runs, and each variant's first differing frame (None: never
    differed). Raises ``AssertionError`` if a forked result is not its full run."""

    def open_design(s):
        if s.sim.timing == "real_clock":
            return make_pin_backend(backend, s)
        return make_backend(backend, s.params)

    designs = [open_design(s) for s in variants]
    base = open_design(scenario)
    try:
        full = []
        envelopes._STOP_DISTANCES.clear()  # each way starts without the summary's cache
        with scaffold.stopwatch(time.process_time) as t_full:
            for s, design in zip(variants, designs, strict=True):
                full.append(run_scenario(s, backend=design).summary)
        parted = []
        envelopes._STOP_DISTANCES.clear()
        with scaffold.stopwatch(time.process_time) as t_fork:
            reference = reference_run(scenario, design=base, checkpoint_every=checkpoint_every)
            forked = []
            for s, design in zip(variants, designs, strict=True):
                forked.append(reference.run_variant(design, s).summary)
                parted.append(reference.last_divergence)
    finally:
        for design in [*designs, base]:
            design.close()
    for s, a, b in zip(variants, full, forked, strict=True):
        assert _same(a, b), f"the forked run of {s.overrides[-1]} is not its full run"
    return t_full.cpu, t_fork.cpu, parted


def _options(p):

    p.add_argument("--scenario", default="lost_target")
    p.add_argument("--key", default="design.lost_frames", help="the design key the variants set")
    p.add_argument(
        "--values",
        default=",".join(str(v) for v in range(5, 25)),
        help="its values, one variant each (default 5..24: 20 variants)",
    )
    p.add_argument("--backend", default="model", choices=("auto", *BACKEND_NAMES))
    p.add_argument("--duration", type=float, default=10.0, help="simulated seconds a run")
    p.add_argument("--checkpoint-every", type=int, default=30, metavar="N")


def _check(args):
    if not args.key.startswith("design."):
        raise UsageError(f"--key must be a design key (design.NAME), got {args.key!r}")
    if not 0 < args.duration <= 600:
        raise UsageError(f"--duration must be in (0, 600] s, got {args.duration}")
    if args.checkpoint_every < 1:
        raise UsageError(f"--checkpoint-every must be >= 1, got {args.checkpoint_every}")
    if not [v for v in args.values.split(",") if v.strip()]:
        raise UsageError("--values needs at least one value")


def run(args):

    scenario = load_scenario(args.scenario, [f"sim.duration={args.duration!r}"])
    values = [v.strip() for v in args.values.split(",") if v.strip()]
    variants = [scenario.with_overrides([f"{args.key}={v}"]) for v in values]
    full, forked, parted = measure(scenario, variants, args.backend, args.checkpoint_every)
    differed = [p for p in parted if p is not None]
    print(
        f"{scenario.name}, {args.backend} backend, {len(variants)} variants of {args.key}, "
        f"{args.duration:g} s each (one run each way, CPU time)"
    )
    print("  every forked result equals its full run")
    where = (
        f"frames {min(differed)} .. {max(differed)} (median {statistics.median(differed):g})"
        if differed
        else "none"
    )
    print(f"  variants that drove differently: {len(differed)}, first differing at {where}")
    print(f"  full runs / forked (reference included)  {full / forked:6.2f}x")
    return {"full_over_forked": full / forked, "variants": len(variants), "parted": parted}


main = scaffold.command(
    run,
    __doc__,
    name="fork",
    options=_options,
    check=_check,
    calibrate=False,  # no times
)
