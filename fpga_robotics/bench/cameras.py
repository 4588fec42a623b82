"""``fpga-robotics bench cameras``: the closed loop with two cameras against one.

The shipped ``turret`` scenario (FollowTarget on the body camera, the turret channel on the
pan camera, both 160x120 at 15 fps) for ``--seconds`` of simulated time, and the same
scenario with its pan camera and servo taken out (FollowTarget on the body camera alone);
per run the wall and CPU milliseconds per body-camera frame, the median over ``--repeats``,
and the ratio of the two-camera run to the one-camera run (the figure that travels: both
are measured in the same run on the same machine). An untimed short run of each comes first
(imports, the model's first load, the caches of a process), so that ``--repeats 1`` is a
warm run too.
"""

import dataclasses
import math
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BACKEND_NAMES, BackendError
from fpga_robotics.sim.pins import PinError

__all__ = ["main"]

#: Simulated seconds of the untimed warm-up run of each scenario.
WARM_UP_S = 0.5


def _scenarios(seconds):

    two = load_scenario("turret", [f"sim.duration={seconds}"])
    one = dataclasses.replace(two, connectors=())
    return {"one camera": one, "two cameras": two}


def _times(scenario, backend):

    w0, c0 = time.perf_counter(), time.process_time()
    result = run_scenario(scenario, backend=backend)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    frames = result.summary["frames"]
    return wall / frames * 1e3, cpu / frames * 1e3


def _options(ap):
    ap.add_argument(
        "--seconds", type=float, default=4.0, help="simulated seconds of each run (default 4)"
    )
    ap.add_argument(
        "--backend",
        default="model",
        choices=("auto", *BACKEND_NAMES),
        help="the design's backend (default model)",
    )


def _check(args):
    if not (math.isfinite(args.seconds) and 0.5 <= args.seconds <= 600):
        raise UsageError(f"--seconds must be 0.5..600, got {args.seconds}")


def run(args):
    runs = _scenarios(args.seconds)
    try:
        for scenario in _scenarios(WARM_UP_S).values():
            run_scenario(scenario, backend=args.backend)
    except (BackendError, PinError) as exc:
        raise UsageError(
            f"the {args.backend} backend cannot run here: {exc}".splitlines()[0]
        ) from None
    print(
        f"turret scenario, {args.seconds:g} s simulated, backend {args.backend}; median of "
        f"{args.repeats}: ms per body-camera frame (wall / CPU of this process)"
    )
    figures = {}
    for name, scenario in runs.items():
        walls, cpus = [], []
        for _ in range(args.repeats):
            wall, cpu = _times(scenario, args.backend)
            walls.append(wall)
            cpus.append(cpu)
        figures[name] = {
            "frame_ms": scaffold.Spread.of(walls),
            "cpu_frame_ms": scaffold.Spread.of(cpus),
        }
        print(
            f"{name:>12}: {figures[name]['frame_ms']:.2f} ms/frame, CPU "
            f"{figures[name]['cpu_frame_ms']:.2f}",
            flush=True,
        )
    ratio = figures["two cameras"]["frame_ms"].median / figures["one camera"]["frame_ms"].median
    cpu_ratio = (
        figures["two cameras"]["cpu_frame_ms"].median / figures["one camera"]["cpu_frame_ms"].median
    )
    print(f"two cameras / one camera: {ratio:.2f} (CPU {cpu_ratio:.2f})")
    return {**figures, "ratio": ratio, "cpu_ratio": cpu_ratio}


main = scaffold.command(run, __doc__, name="cameras", options=_options, check=_check, repeats=3)
