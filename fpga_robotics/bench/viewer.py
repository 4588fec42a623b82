"""``fpga-robotics bench viewer``: what logging to rerun adds per frame, to a file sink.

For each resolution, a run of synthetic frames (a moving target over a noisy background, the
design's filtered frame from the golden model) is logged with ``Recorder.log_frame`` to a
temporary ``.rrd``. Printed per resolution, each the median over ``--repeats`` runs: the
median and the mean wall milliseconds of a ``log_frame`` call (most calls only buffer; the
mean includes the column sends every 32 frames, and any time the machine gave to other
processes), the CPU milliseconds per frame of the calling thread and of the whole process
(rerun's encoder and writer threads included, through ``close``), and the file size per frame.
"""

import math
import os
import statistics
import tempfile
import time

import numpy as np

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.models.follow_target import FollowTargetModel
from fpga_robotics.sim.records import FrameRecord, PersonState, WorldMap
from fpga_robotics.viz import ViewerError, open_recorder

__all__ = ["bench_once", "main", "make_records"]

RESOLUTIONS = ((160, 120), (640, 480))
_WORLD = WorldMap(
    walls=[((0, 0), (8, 0)), ((8, 0), (8, 6)), ((8, 6), (0, 6)), ((0, 6), (0, 0))],
    obstacles=[[(2, 2), (3, 2), (3, 2.6), (2, 2.6)]],
    obstacle_colors=[(140, 90, 50)],
    bounds=(0, 0, 8, 6),
)


def make_records(width, height, n, seed=0):
    """``n`` FrameRecords: a red target drifting across a noisy frame, through the model."""
    rng = np.random.default_rng(seed)
    params = FollowTargetParams(width=width, height=height)
    model = FollowTargetModel(params)
    red = COLOR_SELECT["red"]
    records = []
    for i in range(n):
        cx = width * (0.2 + 0.6 * (0.5 + 0.5 * math.sin(i / 15)))
        rgb = synthetic.blob_frame(width, height, "red", cx=cx, radius=height / 6, rng=rng)
        out = model.process(to_rgb444(rgb, width, height), red)
        t = out.tracker
        result = FrameResult(
            filtered=out.filtered,
            found=t.found,
            proximity=t.proximity,
            centroid_x=t.centroid_x,
            centroid_leds=t.centroid_leds,
            motor_left=out.motor_left,
            motor_right=out.motor_right,
            cycles=0,
        )
        records.append(
            FrameRecord(
                frame=i,
                sim_time=i / 30,
                camera_rgb=rgb,
                color_sel=red,
                result=result,
                robot_x=2 + 0.01 * i,
                robot_y=3.0,
                robot_heading=0.01 * i,
                robot_v=0.2,
                robot_w=0.05,
                cmd_v=0.21,
                cmd_w=0.06,
                camera_hfov=1.047,
                people=[
                    PersonState("target", 5 + 0.01 * i, 3.2, 0.25, True),
                    PersonState("walker", 6, 1 + 0.01 * i, 0.25, False),
                ],
                target_distance=3.0,
                target_in_view=True,
                events=["target found"] if i == 0 else [],
            )
        )
    return records


def bench_once(records, folder, **options):
    """Log ``records`` to a new file.

    Returns per-call wall seconds, the CPU seconds per frame of the calling thread and of the
    whole process (rerun's writer threads included, up to the end of ``close``), and the file
    size in bytes.
    """
    path = os.path.join(folder, f"bench-{time.monotonic_ns()}.rrd")
    rec = open_recorder(f"save:{path}", default_path=path, **options)
    rec.log_world_map(_WORLD)
    times = []
    cpu0, proc0 = time.thread_time(), time.process_time()
    for r in records:
        t0 = time.perf_counter()
        rec.log_frame(r)
        times.append(time.perf_counter() - t0)
    rec.close()
    cpu = (time.thread_time() - cpu0) / len(records)
    proc = (time.process_time() - proc0) / len(records)
    size = os.path.getsize(path)
    os.remove(path)
    return times, cpu, proc, size


def _options(p):
    p.add_argument("--log-every", type=int, default=1, help="image decimation (default 1)")
    p.add_argument(
        "--jpeg-quality", type=int, default=None, help="0 raw, 1..100 JPEG (default: auto)"
    )


def run(args):
    if args.log_every < 1:
        raise UsageError(f"--log-every must be >= 1, got {args.log_every}")
    options = {"log_every": args.log_every, "jpeg_quality": args.jpeg_quality}
    try:  # a bad --jpeg-quality is said before any work
        open_recorder("off", default_path=None, **options).close()
    except ViewerError as exc:
        raise UsageError(str(exc)) from None
    quality = "auto" if args.jpeg_quality is None else args.jpeg_quality
    print(
        f"viz logging cost per frame, file sink, {args.frames} frames x {args.repeats} runs, "
        f"log_every={args.log_every}, jpeg_quality={quality}"
    )
    figures = []
    with tempfile.TemporaryDirectory(prefix="viz-bench-") as folder:
        for width, height in RESOLUTIONS:
            records = make_records(width, height, args.frames)
            bench_once(records[:20], folder, **options)  # warm-up (imports, caches)
            medians, means, cpus, procs, sizes = [], [], [], [], []
            for _ in range(args.repeats):
                times, cpu, proc, size = bench_once(records, folder, **options)
                medians.append(statistics.median(times) * 1e3)
                means.append(statistics.fmean(times) * 1e3)
                cpus.append(cpu * 1e3)
                procs.append(proc * 1e3)
                sizes.append(size / len(records))
            med = statistics.median
            figures.append(
                {
                    "size": f"{width}x{height}",
                    "call_median_ms": med(medians),
                    "call_mean_ms": med(means),
                    "caller_cpu_ms": med(cpus),
                    "process_cpu_ms": med(procs),
                    "bytes_per_frame": med(sizes),
                }
            )
            print(
                f"  {width}x{height}: wall median {med(medians):.3f} ms/frame, "
                f"mean {med(means):.3f} ms/frame; CPU {med(cpus):.3f} ms/frame in the caller, "
                f"{med(procs):.3f} ms/frame with rerun's threads; "
                f"{med(sizes) / 1e3:.1f} kB/frame"
            )
    return {"sizes": figures}


main = scaffold.command(run, __doc__, name="viewer", options=_options, repeats=5, frames=300)
