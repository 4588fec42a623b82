"""``python -m fpga_robotics.bench.world`` (or ``fpga-robotics bench world``): the physics cost
per camera frame.

    python -m fpga_robotics.bench.world [--frames 900] [--repeats 5] [--physics-hz 200]
                                        [--fps 30]

The benchmark itself is ``fpga_robotics.bench.world_physics``; this is its command line, which
reports bad arguments as one-line usage errors.
"""

import argparse
import math
import statistics
import sys

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.bench.world_physics import WORLDS, time_frames, time_terrain_and_noise

__all__ = ["PROG", "cli", "main"]

#: The command (also ``fpga-robotics bench world``).
PROG = "python -m fpga_robotics.bench.world"


def _count(name, value, hi):
    if not 1 <= value <= hi:
        raise UsageError(f"{name} must be 1..{hi}, got {value}")
    return value


def _rate(name, value, hi):
    if not (math.isfinite(value) and 0 < value <= hi):
        raise UsageError(f"{name} must be a number of hertz in (0, {hi:g}], got {value}")
    return value


def main(argv=None, prog=PROG):
    parser = argparse.ArgumentParser(prog=prog,
                                     description="Physics cost per camera frame.")
    parser.add_argument("--frames", type=int, default=900, help="frames per run (default 900)")
    parser.add_argument("--repeats", type=int, default=5, help="runs per world (default 5)")
    parser.add_argument("--physics-hz", type=float, default=240.0,
                        help="physics steps per second (default 240, the closed loop's)")
    parser.add_argument("--fps", type=float, default=30.0, help="camera frames per second")
    args = parser.parse_args(argv)
    frames = _count("--frames", args.frames, 10**6)
    repeats = _count("--repeats", args.repeats, 1000)
    physics_hz = _rate("--physics-hz", args.physics_hz, 1e5)
    fps = _rate("--fps", args.fps, physics_hz)
    steps = math.ceil(physics_hz / fps)
    dt = 1.0 / physics_hz
    print(f"{steps} steps of {dt * 1e3:.2f} ms per frame, {frames} frames, "
          f"median of {repeats} runs")
    for name, cfg in WORLDS.items():
        per_frame = statistics.median(time_frames(cfg, frames, steps, dt)
                                      for _ in range(repeats))
        print(f"  {name:32s} {per_frame * 1e3:7.3f} ms/frame  "
              f"{per_frame / steps * 1e6:6.1f} us/step (incl. scene and queries)", flush=True)
    extra = statistics.median(time_terrain_and_noise(frames, steps, dt) for _ in range(repeats))
    print(f"  {'of which terrain and noise alone':32s} {extra * 1e3:7.3f} ms/frame  "
          f"{extra / steps * 1e6:6.1f} us/step (4 patches, every imperfection on)")
    return 0


def cli():
    """The console entry point: usage errors as one line and exit status 2."""
    run_cli(main, sys.argv[1:], prog=PROG)


if __name__ == "__main__":
    cli()
