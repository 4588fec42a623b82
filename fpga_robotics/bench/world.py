"""``fpga-robotics bench world``: the physics cost per camera frame.

For each world it runs the physics for many camera frame periods (``--physics-hz /
--fps`` steps each, plus ``scene()`` and the state queries the closed loop makes per frame)
with a changing wheel command, and prints the median over ``--repeats`` runs of the time per
frame and per step; then the terrain lookup and the drive noise alone. Each time is wall
clock and CPU time of this process: on a loaded machine the wall clock counts the other jobs'
turns (several times the CPU time of these short Python loops), the CPU time does not.
"""

import math
import statistics
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.sim.world.world import World

__all__ = ["TERRAIN_WORLD", "WORLDS", "main", "time_frames", "time_terrain_and_noise"]

_BUSY = {
    "room": {
        "furniture": [
            {"center": [2.0, 1.0]},
            {"center": [6.0, 1.0], "angle_deg": 20},
            {"center": [2.0, 5.0], "size": [1.5, 0.5]},
            {"center": [7.0, 5.0]},
            {"type": "divider", "center": [5.0, 5.2], "name": "divider"},
            {"center": [0.8, 0.8], "size": [0.5, 0.5]},
        ]
    },
    "people": [
        {"waypoints": [[4, 3], [6, 4.5], [6.5, 1.5]], "pause": 1.0, "speed_jitter": 0.2},
        {"waypoints": [[1, 3], [7, 3]], "speed": 1.0},
        {"waypoints": [[3, 1.8], [3, 4.2]], "speed": 0.7},
        {"waypoints": [[5, 2], [7, 2], [7, 4], [5, 4]], "speed": 0.5, "pause": 0.5},
        {"waypoints": [[4, 4.5]]},
    ],
}
# The default world with terrain under the whole drive (four patches, a ramp among them) and
# every drive imperfection on: against "default", the cost of terrain lookup and noise.
_TERRAIN = {
    "room": {
        "terrain": [
            {"center": [2.0, 3.0], "size": [4.0, 6.0], "friction": 0.8},
            {"points": [[4, 0], [8, 0], [8, 3], [4, 3]], "friction": 0.5, "color": [0.4, 0.4, 0.5]},
            {"center": [6.0, 4.5], "size": [4.0, 3.0], "slope_deg": 3.0, "slope_dir_deg": 90},
            {"center": [4.0, 3.0], "size": [1.0, 1.0], "friction": 0.3},
        ]
    },
    "robot": {"motor_gain_error": 0.05, "motor_noise_dps": 10.0, "slip_rate_hz": 0.2},
}
WORLDS = {"default": {}, "busy (6 furniture, 5 people)": _BUSY, "terrain, drive noise": _TERRAIN}

TERRAIN_WORLD = "terrain, drive noise"


def time_frames(cfg, frames, steps_per_frame, dt):
    """(wall, CPU) seconds per frame of the world ``cfg``'s physics, scene and queries."""
    world = World.from_config(cfg, seed=0)
    start, cpu = time.perf_counter(), time.process_time()
    for k in range(frames):
        world.set_wheel_dps(300 + 200 * math.sin(k / 20), 300 + 200 * math.cos(k / 30))
        for _ in range(steps_per_frame):
            world.step(dt)
        world.scene()
        world.robot_pose()
        world.robot_velocity()
        world.commanded_twist()
        world.target_position()
        world.people_states()
        world.drain_events()
    return (time.perf_counter() - start) / frames, (time.process_time() - cpu) / frames


def time_terrain_and_noise(frames, steps_per_frame, dt):
    """(wall, CPU) seconds per frame of the terrain lookup and the drive noise alone (what the terrain
    world adds to every physics step), timed on the robot positions of a drive through the
    terrain world. The physics of the two worlds differ with the path taken, so comparing
    their whole frames would not isolate this."""
    world = World.from_config(_TERRAIN, seed=0)
    positions = []
    for k in range(frames):
        world.set_wheel_dps(300 + 200 * math.sin(k / 20), 300 + 200 * math.cos(k / 30))
        for _ in range(steps_per_frame):
            world.step(dt)
        positions.append(tuple(world.robot_body.position))
    unc = world.uncertainty
    start, cpu = time.perf_counter(), time.process_time()
    for k, position in enumerate(positions):
        for i in range(steps_per_frame):
            _, _, slip = unc.step(dt, 1.0, 1.0, (k * steps_per_frame + i) * dt)
            world._apply_terrain(slip, *position)
    return (time.perf_counter() - start) / frames, (time.process_time() - cpu) / frames


def _rate(name, value, hi):
    if not (math.isfinite(value) and 0 < value <= hi):
        raise UsageError(f"{name} must be a number of hertz in (0, {hi:g}], got {value}")
    return value


def _options(parser):
    parser.add_argument(
        "--physics-hz",
        type=float,
        default=240.0,
        help="physics steps per second (default 240, the closed loop's)",
    )
    parser.add_argument("--fps", type=float, default=30.0, help="camera frames per second")


def _check(args):
    _rate("--physics-hz", args.physics_hz, 1e5)
    _rate("--fps", args.fps, args.physics_hz)


def run(args):
    steps = math.ceil(args.physics_hz / args.fps)
    dt = 1.0 / args.physics_hz
    print(
        f"{steps} steps of {dt * 1e3:.2f} ms per frame, {args.frames} frames, "
        f"median of {args.repeats} runs"
    )
    figures = []
    for name, cfg in WORLDS.items():
        runs = [time_frames(cfg, args.frames, steps, dt) for _ in range(args.repeats)]
        per_frame, cpu = _medians(runs)
        figures.append({"world": name, "frame_ms": per_frame * 1e3, "cpu_ms": cpu * 1e3})
        print(
            f"  {name:32s} {per_frame * 1e3:7.3f} ms/frame (CPU {cpu * 1e3:.3f})  "
            f"{per_frame / steps * 1e6:6.1f} us/step (incl. scene and queries)",
            flush=True,
        )
    runs = [time_terrain_and_noise(args.frames, steps, dt) for _ in range(args.repeats)]
    extra, cpu = _medians(runs)
    figures.append(
        {"world": "terrain and noise alone", "frame_ms": extra * 1e3, "cpu_ms": cpu * 1e3}
    )
    print(
        f"  {'of which terrain and noise alone':32s} {extra * 1e3:7.3f} ms/frame "
        f"(CPU {cpu * 1e3:.3f})  {extra / steps * 1e6:6.1f} us/step (4 patches, every "
        "imperfection on)"
    )
    return {"worlds": figures}


def _medians(runs):
    """(median wall, median CPU) of ``(wall, CPU)`` runs."""
    return tuple(statistics.median(column) for column in zip(*runs, strict=True))


main = scaffold.command(
    run, __doc__, name="world", options=_options, check=_check, repeats=5, frames=900
)
