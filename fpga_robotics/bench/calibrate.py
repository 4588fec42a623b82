"""``fpga-robotics bench calibrate``: this machine's calibration frame time, the unit that
makes speed figures travel between machines.

The calibration design is the published FPGA-Robotics design as a preset of this project's
gateware (``design.preset=published``) at 160x120, on the fastest compiled backend here
(CXXRTL, else Verilator; the numpy model where neither builds): its milliseconds per frame of
seeded synthetic frames, as users call ``process_frame``. An absolute time divided by it, both
measured in one run (``--calibrate`` on any benchmark), compares across machines; the time
alone does not.
"""

import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError

__all__ = ["CALIBRATION_SIZE", "calibration_backend", "main", "measure_calibration"]

CALIBRATION_SIZE = (160, 120)


def calibration_backend(name="auto"):
    from fpga_robotics.sim.backends import BACKEND_NAMES, fastest_backend_name

    if name == "auto":
        return fastest_backend_name()
    if name not in BACKEND_NAMES:
        raise UsageError(f"unknown backend {name!r}; choose from auto, {', '.join(BACKEND_NAMES)}")
    return name


def measure_calibration(*, repeats=5, frames=30, backend="auto", seed=0):
    """``{"what", "backend", "frame_ms": Spread, "cpu_ms": Spread}``: the published preset's
    median ms per frame in each of ``repeats`` passes over ``frames`` frames (wall clock, and
    CPU time of this thread), after one warm-up frame; the build (or cache load) untimed."""
    from fpga_robotics.bench.design import bench_frames
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.backends import BackendError, get_backend

    name = calibration_backend(backend)
    w, h = CALIBRATION_SIZE
    params = FollowTargetParams.published(width=w, height=h)
    images = bench_frames(w, h, frames, seed)
    walls, cpus = [], []
    try:
        design = get_backend(name, params)
    except BackendError as exc:
        raise UsageError(f"the {name} backend cannot run here: {exc}") from None
    with design:
        design.process_frame(images[0])
        with scaffold.gc_paused():
            for _ in range(repeats):
                wall, cpu = [], []
                for image in images:
                    with scaffold.stopwatch(time.thread_time) as t:
                        design.process_frame(image)
                    wall.append(t.wall * 1e3)
                    cpu.append(t.cpu * 1e3)
                walls.append(scaffold.Spread.of(wall).median)
                cpus.append(scaffold.Spread.of(cpu).median)
    return {
        "what": f"published preset, {name}, {w}x{h}",
        "backend": name,
        "frame_ms": scaffold.Spread.of(walls),
        "cpu_ms": scaffold.Spread.of(cpus),
    }


def _options(parser):
    parser.add_argument(
        "--backend",
        default="auto",
        help="the backend (default auto: the fastest compiled one here)",
    )


def run(args):
    cal = measure_calibration(repeats=args.repeats, frames=args.frames, backend=args.backend)
    print(f"calibration: {cal['what']}, {args.frames} frames x {args.repeats} repeats")
    scaffold.print_table(
        ("clock", "ms/frame median", "min", "max"),
        [
            (clock, f"{s.median:.4f}", f"{s.min:.4f}", f"{s.max:.4f}")
            for clock, s in (("wall", cal["frame_ms"]), ("cpu", cal["cpu_ms"]))
        ],
    )
    return {"calibration": cal}


def _no_self_calibration(args):
    if args.calibrate:
        raise UsageError("--calibrate: this command is the calibration; drop the option")


main = scaffold.command(
    run,
    __doc__,
    name="calibrate",
    options=_options,
    repeats=5,
    frames=30,
    check=_no_self_calibration,
)
