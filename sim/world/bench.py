"""Benchmark: physics cost per camera frame.

For each world it runs the physics for many 30 fps frame periods (7 steps of 1/200 s each,
plus ``scene()`` and the state queries the closed loop makes per frame) with a changing wheel
command; the command line (``python -m fpga_robotics.world_bench``, or this module with
``-m``) prints the median over several repeats of the time per frame and per step.
"""

import math
import time

from .world import World

_BUSY = {
    "room": {"furniture": [
        {"center": [2.0, 1.0]}, {"center": [6.0, 1.0], "angle_deg": 20},
        {"center": [2.0, 5.0], "size": [1.5, 0.5]}, {"center": [7.0, 5.0]},
        {"type": "divider", "center": [5.0, 5.2], "name": "divider"},
        {"center": [0.8, 0.8], "size": [0.5, 0.5]},
    ]},
    "people": [
        {"waypoints": [[4, 3], [6, 4.5], [6.5, 1.5]], "pause": 1.0, "speed_jitter": 0.2},
        {"waypoints": [[1, 3], [7, 3]], "speed": 1.0},
        {"waypoints": [[3, 1.8], [3, 4.2]], "speed": 0.7},
        {"waypoints": [[5, 2], [7, 2], [7, 4], [5, 4]], "speed": 0.5, "pause": 0.5},
        {"waypoints": [[4, 4.5]]},
    ],
}
WORLDS = {"default": {}, "busy (6 furniture, 5 people)": _BUSY}

__all__ = ["WORLDS", "time_frames"]


def time_frames(cfg, frames, steps_per_frame, dt):
    world = World.from_config(cfg, seed=0)
    start = time.perf_counter()
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
    return (time.perf_counter() - start) / frames


if __name__ == "__main__":  # the command line lives in the application layer
    from ...world_bench import cli

    cli()
