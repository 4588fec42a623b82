"""``python -m fpga_robotics.bench.camera`` (or ``fpga-robotics bench camera``): time the camera
renderer at several resolutions.

    python -m fpga_robotics.bench.camera [--frames 60] [--repeats 5] [--noise 2.0]
                                         [--sizes 160x120,320x240,640x480] [--sensor]

``--sensor`` times the OV7670 sensor model's stages instead (``fpga_robotics.sim.camera.sensor.bench``);
``--stage-images DIR`` writes PNGs of one frame through each stage (docs/camera.md) and exits.

The benchmark itself (scene, camera loop, timing) is ``fpga_robotics.bench.camera_frames``; this
is its command line, which reports bad arguments as one-line usage errors.
"""

import argparse
import math
import statistics
import sys

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.bench import camera_frames as _bench
from fpga_robotics.bench.camera_frames import DEFAULT_SIZES, benchmark, typical_scene

__all__ = ["MAX_SIDE", "PROG", "cli", "main"]

#: The command (also ``fpga-robotics bench camera``).
PROG = "python -m fpga_robotics.bench.camera"

#: Largest width or height timed (the design's own limit).
MAX_SIDE = 4096


def _size(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise UsageError(f"a size is WIDTHxHEIGHT, e.g. 160x120; got {text!r}") from None
    if not (1 <= w <= MAX_SIDE and 1 <= h <= MAX_SIDE):
        raise UsageError(f"a size needs a width and height of 1..{MAX_SIDE}, got {text!r}")
    return w, h


def main(argv=None, prog=PROG):
    ap = argparse.ArgumentParser(prog=prog,
                                 description=_bench.__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=60, help="poses per loop (default 60)")
    ap.add_argument("--repeats", type=int, default=5, help="loops per size (default 5)")
    ap.add_argument("--noise", type=float, default=2.0,
                    help="also time with sensor noise of this std, 8-bit units (0: skip)")
    ap.add_argument("--sizes", default=",".join(f"{w}x{h}" for w, h in DEFAULT_SIZES),
                    help="comma-separated WIDTHxHEIGHT list")
    ap.add_argument("--sensor", action="store_true",
                    help="time each stage of the OV7670 sensor model instead of the renderer")
    ap.add_argument("--stage-images", metavar="DIR",
                    help="write PNGs of one frame through each sensor stage to DIR, and exit")
    args = ap.parse_args(argv)
    if not (1 <= args.frames <= 10**5 and 1 <= args.repeats <= 1000):
        raise UsageError(f"--frames must be 1..100000 and --repeats 1..1000, got "
                         f"{args.frames} and {args.repeats}")
    if not (math.isfinite(args.noise) and 0 <= args.noise <= 64):
        raise UsageError(f"--noise must be a number of 8-bit levels in 0..64, got {args.noise}")
    sizes = [_size(s) for s in args.sizes.split(",") if s.strip()]
    if args.stage_images is not None:
        return _stage_images(args.stage_images)
    if args.sensor:
        return _sensor_table(sizes, args.frames, args.repeats)
    print(f"camera renderer, typical room ({len(typical_scene().walls)} walls, 3 people), "
          f"{args.frames} poses x {args.repeats} repeats; median milliseconds per frame "
          f"(wall clock / CPU time of this process)")
    header = f"{'size':>9}  {'wall':>7}  {'cpu':>7}"
    if args.noise:
        header += f"  {'noise wall':>10}  {'noise cpu':>9}"
    print(header)
    for w, h in sizes:
        wall, cpu = benchmark(w, h, frames=args.frames, repeats=args.repeats)
        line = f"{w:>4}x{h:<4}  {statistics.median(wall):7.3f}  {statistics.median(cpu):7.3f}"
        if args.noise:
            wall, cpu = benchmark(w, h, frames=args.frames, repeats=args.repeats,
                                  noise_std=args.noise)
            line += f"  {statistics.median(wall):10.3f}  {statistics.median(cpu):9.3f}"
        print(line, flush=True)
    return 0


def _sensor_table(sizes, frames, repeats):
    from fpga_robotics.bench.camera_sensor import STAGES, stage_times

    print(f"OV7670 sensor model on the renderer's frames of the typical room, turning at "
          f"0.5 rad/s, {frames} frames x {repeats} repeats; median milliseconds per frame "
          f"(stages: wall clock; frame: wall / CPU time of this process)")
    print(f"{'size':>9}  " + "  ".join(f"{n:>8}" for n in STAGES) + f"  {'frame':>7}  {'cpu':>7}")
    for w, h in sizes:
        t = stage_times(w, h, frames=frames, repeats=repeats)
        cells = "  ".join(f"{statistics.median(t[n]):8.3f}" for n in STAGES)
        print(f"{w:>4}x{h:<4}  {cells}  {statistics.median(t['frame']):7.3f}  "
              f"{statistics.median(t['frame_cpu']):7.3f}", flush=True)
    return 0


def _stage_images(folder):
    """One 160x120 view of the typical room (the red person beside the divider, the robot
    turning at 1 rad/s) through each stage, shown twice the size, one PNG a stage."""
    import cv2
    import numpy as np

    from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length
    from fpga_robotics.sim.files import check_output_dir, write_atomic
    from fpga_robotics.sim.camera.scene import CameraPose
    from fpga_robotics.sim.camera.sensor import OV7670Params
    from fpga_robotics.sim.camera.sensor.figure import stage_images

    folder = check_output_dir(folder, what="--stage-images folder")
    rgb = CameraRenderer(160, 120, 1.047).render(typical_scene(),
                                                 CameraPose(2.0, 4.3, -0.3, height=0.3))
    stages = stage_images(rgb, OV7670Params(), rng=np.random.default_rng(0), turn_rate=1.0,
                          focal_px=focal_length(160, 1.047))
    folder.mkdir(parents=True, exist_ok=True)
    for i, (title, img) in enumerate(stages):
        big = cv2.resize(img, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
        ok, png = cv2.imencode(".png", cv2.cvtColor(big, cv2.COLOR_RGB2BGR))
        if not ok:
            raise UsageError("OpenCV could not encode a PNG (is its image codec installed?)")
        path = folder / f"sensor_stage_{i}.png"
        write_atomic(path, png.tobytes(), what="stage image")
        print(f"{path}: {title}")
    return 0


def cli():
    """The console entry point: usage errors as one line and exit status 2."""
    run_cli(main, sys.argv[1:], prog=PROG)


if __name__ == "__main__":
    cli()
