"""``fpga-robotics bench shadow``: what a shadow design costs in the closed loop, against what
the shadow design costs on its own.

The closed loop runs alone and with the shadow design, taking turns (the machine is shared;
alternating lets both see the same periods); the shadow design then processes the very frames
of the run on its own. Each is timed by the thread's CPU time (what other jobs on a shared
machine do not inflate), per frame of the run. The figure is the loop's extra time per frame
over the shadow design's own time per frame (the target: at most 1.1).
"""

import statistics
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.run import _shadow_params
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BACKEND_NAMES, fastest_backend_name

__all__ = ["main", "measure"]


def measure(scenario, backend, shadow_params, repeats):
    """``(alone_ms, shadowed_ms, own_ms)``: medians of CPU milliseconds per frame over
    ``repeats`` turns."""
    design = make_backend(backend, scenario.params)
    shadow = make_backend(backend, shadow_params)
    frames = []
    alone, shadowed, own = [], [], []

    def cpu_ms_per_frame(fn):
        with scaffold.stopwatch(time.thread_time) as t:
            fn()
        return 1000.0 * t.cpu / max(1, len(frames))

    def replay():
        shadow.reset()
        for rgb, color in frames:
            shadow.process_frame(rgb, color)

    try:
        # The run's frames, for the shadow design alone (an untimed run: recording them costs).
        run_scenario(
            scenario,
            backend=design,
            on_frame=lambda record: frames.append((record.camera_rgb, record.color_sel)),
        )
        for _turn in range(repeats):
            alone.append(cpu_ms_per_frame(lambda: run_scenario(scenario, backend=design)))
            shadowed.append(
                cpu_ms_per_frame(lambda: run_scenario(scenario, backend=design, shadow=shadow))
            )
            own.append(cpu_ms_per_frame(replay))
    finally:
        design.close()
        shadow.close()
    return statistics.median(alone), statistics.median(shadowed), statistics.median(own)


def _options(p):
    p.add_argument("--scenario", default="follow_person")
    p.add_argument(
        "--shadow",
        default="diff_min=5",
        metavar="SPEC",
        help="the shadow design, as run --shadow takes it (default diff_min=5)",
    )
    p.add_argument("--backend", default="auto", choices=("auto", *BACKEND_NAMES))
    p.add_argument("--duration", type=float, default=10.0, help="simulated seconds a run")


def _check(args):
    if not args.repeats <= 100:
        raise UsageError(f"--repeats must be 1..100, got {args.repeats}")
    if not 0 < args.duration <= 600:
        raise UsageError(f"--duration must be in (0, 600] s, got {args.duration}")


def run(args):
    scenario = load_scenario(args.scenario, [f"sim.duration={args.duration!r}"])
    scaffold.check_follow_target_scenario(scenario, "shadow")
    shadow_params = _shadow_params(scenario, args.shadow)
    # The backend that runs, named in the header ("auto" is the fastest one here).
    backend = fastest_backend_name() if args.backend == "auto" else args.backend
    alone, shadowed, own = measure(scenario, backend, shadow_params, args.repeats)
    extra = shadowed - alone
    print(
        f"{scenario.name}, {backend} backend, shadow {args.shadow}, "
        f"medians of {args.repeats} turns (CPU ms per frame)"
    )
    print(f"  closed loop alone           {alone:8.3f}")
    print(f"  closed loop with the shadow {shadowed:8.3f}")
    print(f"  shadow design on its own    {own:8.3f}")
    print(f"  extra per frame / own time  {extra / own:8.2f}  (target <= 1.10)")
    return {
        "alone_cpu_ms": alone,
        "shadowed_cpu_ms": shadowed,
        "own_cpu_ms": own,
        "extra_over_own": extra / own,
    }


main = scaffold.command(run, __doc__, name="shadow", options=_options, check=_check, repeats=3)
