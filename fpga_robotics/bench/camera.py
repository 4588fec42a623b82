"""``fpga-robotics bench camera``: the camera renderer's milliseconds per frame at several
sizes, or (``--sensor``) each stage of the OV7670 sensor model.

The scene is a typical room: 8 m x 6 m walls (2.5 m), four pieces of furniture made of four
walls each (a 1.2 m wooden divider among them) and three people. The camera drives a loop
through the room turning as it goes, so every frame sees a different view; each repeat renders
the whole loop and the figures reported are medians over every frame of every repeat: wall
clock, and CPU time of the process (which a busy machine does not inflate). With ``--noise``
(default 2.0) the same again with sensor noise. ``--sensor`` takes the same frames (rendering
untimed) through the sensor model with the robot turning at 0.5 rad/s, every stage timed on its
own; ``--stage-images DIR`` writes PNGs of one frame through each stage (docs/camera.md).
"""

import math
import statistics
import time

import cv2
import numpy as np

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.sim.camera.raster import DEFAULT_HFOV, CameraRenderer, focal_length
from fpga_robotics.sim.camera.scene import Band, CameraPose, Cylinder, Lighting, Scene, Wall
from fpga_robotics.sim.camera.sensor import OV7670Params
from fpga_robotics.sim.camera.sensor.figure import stage_images
from fpga_robotics.sim.camera.sensor.pipeline import OV7670Sensor
from fpga_robotics.sim.files import check_output_dir, write_atomic

__all__ = [
    "DEFAULT_SIZES",
    "STAGES",
    "benchmark",
    "camera_loop",
    "main",
    "stage_times",
    "typical_scene",
]

DEFAULT_SIZES = ((160, 120), (320, 240), (640, 480))


def _box(cx, cy, length, width, angle, height, color):
    c, s = math.cos(angle), math.sin(angle)
    pts = [
        (-length / 2, -width / 2),
        (length / 2, -width / 2),
        (length / 2, width / 2),
        (-length / 2, width / 2),
    ]
    pts = [(cx + c * x - s * y, cy + s * x + c * y) for x, y in pts]
    return [Wall(*pts[i], *pts[(i + 1) % 4], height, color) for i in range(4)]


def _person(x, y, shirt):
    return Cylinder(
        x,
        y,
        0.2,
        (
            Band(0.0, 0.85, (0.15, 0.15, 0.22)),
            Band(0.85, 1.45, shirt),
            Band(1.5, 1.75, (0.87, 0.68, 0.56)),
        ),
    )


def typical_scene():
    """The benchmark room as a :class:`~fpga_robotics.sim.camera.scene.Scene`."""
    walls = _box(4.0, 3.0, 8.0, 6.0, 0.0, 2.5, (0.8, 0.78, 0.72))
    walls += _box(5.5, 4.2, 1.6, 0.05, 0.3, 1.2, (0.55, 0.27, 0.15))  # wooden divider
    walls += _box(1.2, 5.2, 1.2, 0.6, 0.0, 0.9, (0.45, 0.42, 0.38))  # cupboard
    walls += _box(6.8, 1.0, 1.0, 1.0, 0.0, 0.75, (0.35, 0.3, 0.25))  # table
    walls += _box(3.0, 1.2, 0.5, 0.5, 0.6, 0.45, (0.3, 0.35, 0.6))  # stool
    people = (
        _person(4.5, 3.5, (0.85, 0.1, 0.1)),
        _person(6.5, 4.8, (0.2, 0.5, 0.25)),
        _person(2.0, 2.8, (0.25, 0.3, 0.7)),
    )
    return Scene(
        walls=tuple(walls),
        cylinders=people,
        lighting=Lighting(ambient=0.6, intensity=0.5, direction=(1.0, 0.5, -1.0)),
    )


def camera_loop(frames):
    """``frames`` camera poses on an ellipse through the room, looking ahead and inwards."""
    poses = []
    for i in range(frames):
        a = 2 * math.pi * i / frames
        x, y = 4.0 + 2.2 * math.cos(a), 3.0 + 1.5 * math.sin(a)
        poses.append(CameraPose(x, y, a + 2.2 + 0.5 * math.sin(3 * a), height=0.3))
    return poses


def benchmark(width, height, *, frames=60, repeats=5, noise_std=0.0, hfov=DEFAULT_HFOV):
    """Per-frame render times in milliseconds: ``(wall, cpu)``, ``frames * repeats`` each.

    Wall time is what a caller waits; CPU time (of this process) leaves out the time the
    process waited for a core, so it stays meaningful on a machine busy with other work.
    """
    renderer = CameraRenderer(width, height, hfov)
    scene, poses = typical_scene(), camera_loop(frames)
    rng = np.random.default_rng(0)
    for pose in poses[:5]:  # warm-up: caches, allocator
        renderer.render(scene, pose, noise_std=noise_std, rng=rng)
    wall, cpu = [], []
    for _ in range(repeats):
        for pose in poses:
            t0, c0 = time.perf_counter(), time.process_time()
            renderer.render(scene, pose, noise_std=noise_std, rng=rng)
            cpu.append((time.process_time() - c0) * 1e3)
            wall.append((time.perf_counter() - t0) * 1e3)
    return wall, cpu


#: The stages in the order a frame meets them (``OV7670Sensor._frame``).
STAGES = ("light", "expose", "noise", "amplify", "demosaic", "tone", "adapt")


def stage_times(width, height, *, frames=60, repeats=5, turn_rate=0.5, hfov=DEFAULT_HFOV):
    """``{stage: [ms, ...], "frame": [...], "frame_cpu": [...]}``, ``frames * repeats`` each."""
    renderer = CameraRenderer(width, height, hfov)
    scene = typical_scene()
    images = [renderer.render(scene, pose) for pose in camera_loop(frames)]
    cam = OV7670Sensor(
        width,
        height,
        OV7670Params(),
        rng=np.random.default_rng(0),
        focal_px=focal_length(width, hfov),
    )
    for img in images[:5]:  # warm-up (and the settling frames)
        cam.process(img, turn_rate)
    out = {name: [] for name in STAGES + ("frame", "frame_cpu")}
    clock = time.perf_counter
    for _ in range(repeats):
        for img in images:
            t0, c0 = clock(), time.process_time()
            raw = cam.light(img, turn_rate)
            t1 = clock()
            q = cam.expose(raw)
            t2 = clock()
            cam.noise.add(q)
            t3 = clock()
            codes, means = cam.amplify(q)
            t4 = clock()
            codes3 = cam.demosaic(codes)
            t5 = clock()
            cam.tone(codes3)
            t6 = clock()
            cam.adapt(codes3, means)
            t7 = clock()
            cam.frames += 1
            c1 = time.process_time()
            marks = (t0, t1, t2, t3, t4, t5, t6, t7)
            for name, a, b in zip(STAGES, marks, marks[1:]):
                out[name].append((b - a) * 1e3)
            out["frame"].append((t7 - t0) * 1e3)
            out["frame_cpu"].append((c1 - c0) * 1e3)
    return out


def _options(parser):
    parser.add_argument(
        "--noise",
        type=float,
        default=2.0,
        help="also time with sensor noise of this std, 8-bit units (0: skip)",
    )
    parser.add_argument(
        "--sizes",
        default=",".join(f"{w}x{h}" for w, h in DEFAULT_SIZES),
        help="comma-separated WIDTHxHEIGHT list",
    )
    parser.add_argument(
        "--sensor",
        action="store_true",
        help="time each stage of the OV7670 sensor model instead of the renderer",
    )
    parser.add_argument(
        "--stage-images",
        metavar="DIR",
        help="write PNGs of one frame through each sensor stage to DIR, and exit",
    )


def _check(args):
    if args.stage_images is not None:
        scaffold.check_not_given(
            args,
            ("sensor", "noise", "sizes", "frames", "repeats", "json", "calibrate"),
            "with --stage-images DIR (it writes one frame's stage images, no figures)",
        )
    if args.sensor:
        scaffold.check_not_given(
            args, ("noise",), "with --sensor (it times the sensor model's stages, no noise)"
        )
    if not (math.isfinite(args.noise) and 0 <= args.noise <= 64):
        raise UsageError(f"--noise must be a number of 8-bit levels in 0..64, got {args.noise}")
    args.sizes = scaffold.parse_sizes(args.sizes, hfov=DEFAULT_HFOV)


def run(args):
    if args.stage_images is not None:
        _stage_images(args.stage_images)
        return None
    if args.sensor:
        return _sensor_table(args.sizes, args.frames, args.repeats)
    print(
        f"camera renderer, typical room ({len(typical_scene().walls)} walls, 3 people), "
        f"{args.frames} poses x {args.repeats} repeats; median milliseconds per frame "
        f"(wall clock / CPU time of this process)"
    )
    header = ["size", "wall", "cpu"] + (["noise wall", "noise cpu"] if args.noise else [])
    rows, figures = [], []
    for w, h in args.sizes:
        wall, cpu = benchmark(w, h, frames=args.frames, repeats=args.repeats)
        row = {
            "size": f"{w}x{h}",
            "wall_ms": statistics.median(wall),
            "cpu_ms": statistics.median(cpu),
        }
        if args.noise:
            wall, cpu = benchmark(
                w, h, frames=args.frames, repeats=args.repeats, noise_std=args.noise
            )
            row.update(noise_wall_ms=statistics.median(wall), noise_cpu_ms=statistics.median(cpu))
        figures.append(row)
        rows.append([row["size"], *(f"{v:.3f}" for k, v in row.items() if k != "size")])
    scaffold.print_table(header, rows, first_width=9)
    return {"renderer": figures}


def _sensor_table(sizes, frames, repeats):
    print(
        f"OV7670 sensor model on the renderer's frames of the typical room, turning at "
        f"0.5 rad/s, {frames} frames x {repeats} repeats; median milliseconds per frame "
        f"(stages: wall clock; frame: wall / CPU time of this process)"
    )
    rows, figures = [], []
    for w, h in sizes:
        t = stage_times(w, h, frames=frames, repeats=repeats)
        row = {
            "size": f"{w}x{h}",
            **{f"{n}_ms": statistics.median(t[n]) for n in (*STAGES, "frame", "frame_cpu")},
        }
        figures.append(row)
        rows.append([row["size"], *(f"{v:.3f}" for k, v in row.items() if k != "size")])
    scaffold.print_table(["size", *STAGES, "frame", "cpu"], rows, first_width=9)
    return {"sensor": figures}


def _stage_images(folder):
    """One 160x120 view of the typical room (the red person beside the divider, the robot
    turning at 1 rad/s) through each stage, shown twice the size, one PNG a stage."""
    folder = check_output_dir(folder, what="--stage-images folder")
    rgb = CameraRenderer(160, 120, 1.047).render(
        typical_scene(), CameraPose(2.0, 4.3, -0.3, height=0.3)
    )
    stages = stage_images(
        rgb,
        OV7670Params(),
        rng=np.random.default_rng(0),
        turn_rate=1.0,
        focal_px=focal_length(160, 1.047),
    )
    folder.mkdir(parents=True, exist_ok=True)
    for i, (title, img) in enumerate(stages):
        big = cv2.resize(img, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
        ok, png = cv2.imencode(".png", cv2.cvtColor(big, cv2.COLOR_RGB2BGR))
        if not ok:
            raise UsageError("OpenCV could not encode a PNG (is its image codec installed?)")
        path = folder / f"sensor_stage_{i}.png"
        write_atomic(path, png.tobytes(), what="stage image")
        print(f"{path}: {title}")


main = scaffold.command(
    run, __doc__, name="camera", options=_options, check=_check, repeats=5, frames=60
)
