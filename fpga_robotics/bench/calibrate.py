"""``fpga-robotics bench calibrate``: this machine's calibration frame time, the unit that
makes speed figures travel between machines.

The calibration design is the published FPGA-Robotics design as a preset of this project's
gateware (``design.preset=published``) at 160x120, on the fastest compiled backend here
(CXXRTL, else Verilator; the numpy model where neither builds): its milliseconds per frame of
seeded synthetic frames, as users call ``process_frame``. An absolute time divided by it, both
measured in one run (``--calibrate`` on a benchmark), compares across machines; the time
alone does not.
"""

from fpga_robotics.bench import scaffold
from fpga_robotics.bench.calibration import (
    CALIBRATION_SIZE,
    calibration_backend,
    measure_calibration,
)

__all__ = ["CALIBRATION_SIZE", "calibration_backend", "main", "measure_calibration"]


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


main = scaffold.command(
    run,
    __doc__,
    name="calibrate",
    options=_options,
    repeats=5,
    frames=30,
    calibrate=False,  # it is the calibration
)
