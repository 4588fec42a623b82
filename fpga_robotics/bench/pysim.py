"""``fpga-robotics bench pysim``: time Amaranth's own simulator on ``FollowTarget``, one frame
at a time, every frame checked against the golden model."""

import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.param_options import add_param_arguments, params_from_args
from fpga_robotics.sim.backends.base import BackendError
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.backends.pysim import PysimBackend
from fpga_robotics.sim.camera.synthetic import blob_frame

__all__ = ["benchmark", "main"]


def benchmark(params=None, *, frames=7, line_blank=0, frame_blank=0, seed=0):
    """Time ``frames`` synthetic frames (a red target moving across) on one backend and check
    each against the golden model. Returns ``(wall_seconds, cpu_seconds, cycles)`` lists."""

    params = params if params is not None else PysimBackend().params
    w, h = params.width, params.height
    wall, cpu, cycles = [], [], []
    with (
        PysimBackend(params, line_blank=line_blank, frame_blank=frame_blank) as sim,
        ModelBackend(params, line_blank=line_blank, frame_blank=frame_blank) as model,
    ):
        for i in range(frames):
            frame = blob_frame(
                w,
                h,
                "red",
                cx=w * (0.2 + 0.6 * i / max(1, frames - 1)),
                cy=h / 2,
                radius=h / 5,
                rng=seed + i,
            )
            t0, c0 = time.perf_counter(), time.process_time()
            got = sim.process_frame(frame, "red")
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            cycles.append(got.cycles)
            if got != model.process_frame(frame, "red"):
                raise BackendError(f"frame {i}: pysim differs from the golden model")
    return wall, cpu, cycles


def _options(parser):
    parser.add_argument(
        "--line-blank", type=int, default=0, help="idle cycles after each line (default 0)"
    )
    parser.add_argument(
        "--frame-blank",
        type=int,
        default=0,
        help="idle cycles after each frame, at least (default 0)",
    )
    add_param_arguments(parser)


def run(args):
    params = params_from_args(args)
    wall, cpu, cycles = benchmark(
        params, frames=args.frames, line_blank=args.line_blank, frame_blank=args.frame_blank
    )
    print(
        f"pysim {params.width}x{params.height}, {args.frames} frames, "
        f"{cycles[0]} cycles per frame, every frame equal to the golden model"
    )
    print("wall s per frame: " + " ".join(f"{t:.3f}" for t in wall))
    med = scaffold.Spread.of(wall).median
    cpu_med = scaffold.Spread.of(cpu).median
    print(f"median {med:.3f} s wall ({cycles[0] / med:,.0f} cycles/s), {cpu_med:.3f} s CPU")
    return {
        "size": f"{params.width}x{params.height}",
        "frame_ms": med * 1e3,
        "cpu_ms": cpu_med * 1e3,
        "cycles_per_frame": cycles[0],
    }


main = scaffold.command(run, __doc__, name="pysim", options=_options, frames=7)
