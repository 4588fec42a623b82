"""``fpga-robotics bench render3d``: the raster and the 3D renderer per frame, and the closed
loop in each mode (``--figures DIR``: the figures of docs/render3d.md instead).

Frames: the room of the shipped ``divider_3d`` scenario (its warm lamp, the person in red),
seen from ``--frames`` poses on a loop through the room; per mode and size the median over
every frame of every repeat, wall clock and CPU time of this process (MuJoCo's software
OpenGL, Mesa's llvmpipe, runs in threads of this process, so its CPU time is counted).
Closed loop: ``follow_person`` for ``--seconds`` of simulated time in each mode; the median
over repeats of milliseconds per frame and of the real-time factor (simulated seconds per
wall second; 1 is real time at the camera's 30 frames a second), and the same per CPU second
of this process (which other jobs on a shared machine do not inflate), from the first frame
to the last; the start-up before the first frame (the 3D renderer's OpenGL context and
model, about 3 s) is printed apart.
"""

import math
import statistics
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.bench.render3d_figures import write_figures
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.connectors.camera import make_renderer
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BACKEND_NAMES
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.world import World

__all__ = ["MODES", "main"]

#: Renderer modes: name -> scenario overrides.
MODES = {
    "raster": ["camera.renderer=raster"],
    "3d, no shadows": ["camera.renderer=mujoco", "camera.shadows=false"],
    "3d, shadows 256": ["camera.renderer=mujoco", "camera.shadows=true", "camera.shadow_size=256"],
    "3d, shadows 1024": [
        "camera.renderer=mujoco",
        "camera.shadows=true",
        "camera.shadow_size=1024",
    ],
}


def _poses(world, frames):
    """``frames`` camera poses on an ellipse through the room, looking ahead and inwards."""
    room = world.config.room
    cx, cy = room.width / 2, room.depth / 2
    spec = world.robot_spec
    out = []
    for i in range(frames):
        a = 2 * math.pi * i / frames
        out.append(
            CameraPose(
                cx + 0.3 * room.width * math.cos(a),
                cy + 0.25 * room.depth * math.sin(a),
                a + 2.2 + 0.5 * math.sin(3 * a),
                height=spec.camera_height,
            )
        )
    return out


def _frame_times(mode, size, frames, repeats):
    scenario = load_scenario("divider_3d", MODES[mode])
    world = World.from_config(scenario.world, 0)
    for _ in range(60):  # the person walks into the room
        world.step(1 / 30)
    scene = world.scene()
    renderer = make_renderer(
        scenario.camera.renderer, *size, scenario.camera.hfov, scenario.camera.render3d
    )
    poses = _poses(world, frames)
    renderer.render(scene, poses[0])  # builds the model, compiles the shaders
    wall, cpu = [], []
    for _ in range(repeats):
        for pose in poses:
            w0, c0 = time.perf_counter(), time.process_time()
            renderer.render(scene, pose)
            wall.append(time.perf_counter() - w0)
            cpu.append(time.process_time() - c0)
    return statistics.median(wall) * 1e3, statistics.median(cpu) * 1e3


def _marker(marks):
    """An ``on_frame`` callback noting the wall and CPU time of each frame in ``marks``."""
    return lambda _record: marks.append((time.perf_counter(), time.process_time()))


def _loop_times(mode, seconds, repeats, backend):
    """Median wall ms per frame, real-time factor and the same per CPU second, from the first
    frame to the last (the renderer's start-up, an OpenGL context and the model, left out:
    ``startup`` seconds, its median)."""
    scenario = load_scenario("follow_person", [*MODES[mode], f"sim.duration={seconds}"])
    period = scenario.camera.frame_period
    ms, factor, cpu_factor, startup = [], [], [], []
    for _ in range(repeats):
        marks = []
        t0 = time.perf_counter()
        run_scenario(scenario, backend=backend, on_frame=_marker(marks))
        (w0, c0), (w1, c1) = marks[0], marks[-1]
        frames = len(marks) - 1
        ms.append((w1 - w0) / frames * 1e3)
        factor.append(frames * period / (w1 - w0))
        cpu_factor.append(frames * period / (c1 - c0))
        startup.append(w0 - t0)
    return (
        statistics.median(ms),
        statistics.median(factor),
        statistics.median(cpu_factor),
        statistics.median(startup),
    )


def _options(ap):
    ap.add_argument(
        "--seconds",
        type=float,
        default=5.0,
        help="simulated seconds of each closed-loop run (default 5; 0 skips them)",
    )
    ap.add_argument("--sizes", default="160x120,640x480", help="comma-separated WIDTHxHEIGHT")
    ap.add_argument("--backend", default="auto", help="the design's backend in the closed loop")
    ap.add_argument(
        "--figures",
        metavar="DIR",
        help="write the figures of docs/render3d.md to DIR instead, and exit",
    )
    ap.add_argument(
        "--viewer",
        action="store_true",
        help="with --figures: also a screenshot of the viewer (needs a Vulkan driver)",
    )


def _check(args):
    if not (math.isfinite(args.seconds) and 0 <= args.seconds <= 3600):
        raise UsageError(f"--seconds must be 0..3600, got {args.seconds}")
    if args.viewer and args.figures is None:
        raise UsageError("--viewer goes with --figures DIR")
    if args.figures is not None:
        scaffold.check_not_given(
            args,
            ("seconds", "sizes", "backend", "frames", "repeats", "json", "calibrate"),
            "with --figures DIR (it writes the figures of docs/render3d.md, no timings)",
        )
    if args.backend not in ("auto", *BACKEND_NAMES):
        raise UsageError(
            f"--backend {args.backend!r} is not a backend; choose one of: auto, "
            f"{', '.join(BACKEND_NAMES)}"
        )
    args.sizes = scaffold.parse_sizes(args.sizes, hfov=load_scenario("divider_3d").camera.hfov)


def run(args):
    if args.figures is not None:
        write_figures(args.figures, viewer=args.viewer)
        return None
    sizes = args.sizes
    print(
        f"renderers on the divider_3d room, {args.frames} poses x {args.repeats} repeats; "
        f"median ms per frame (wall / CPU of this process)"
    )
    print(f"{'mode':>18}" + "".join(f"  {f'{w}x{h} wall':>14} {'cpu':>7}" for w, h in sizes))
    frames, loops = [], []
    for mode in MODES:
        cells = [_frame_times(mode, size, args.frames, args.repeats) for size in sizes]
        frames += [
            {"mode": mode, "size": f"{w}x{h}", "wall_ms": wall, "cpu_ms": cpu}
            for (w, h), (wall, cpu) in zip(sizes, cells, strict=True)
        ]
        print(
            f"{mode:>18}" + "".join(f"  {wall:14.2f} {cpu:7.2f}" for wall, cpu in cells), flush=True
        )
    if args.seconds:
        print(
            f"closed loop, follow_person, {args.seconds:g} s simulated at 160x120, backend "
            f"{args.backend}; median of {args.repeats}: wall ms per frame, real-time factor "
            f"(simulated seconds per wall second, and per CPU second of this process)"
        )
        for mode in MODES:
            ms, factor, cpu, startup = _loop_times(mode, args.seconds, args.repeats, args.backend)
            loops.append(
                {
                    "mode": mode,
                    "frame_ms": ms,
                    "realtime": factor,
                    "cpu_realtime": cpu,
                    "startup_s": startup,
                }
            )
            print(
                f"{mode:>18}  {ms:8.2f} ms/frame  {factor:6.2f}x real time  "
                f"{cpu:6.2f}x per CPU second  (start-up {startup:.1f} s)",
                flush=True,
            )
    return {"frames": frames, "loop": loops}


main = scaffold.command(
    run, __doc__, name="render3d", options=_options, check=_check, repeats=3, frames=60
)
