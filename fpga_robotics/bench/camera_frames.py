"""Benchmark of the camera renderer: median milliseconds per frame at several resolutions.

The command line is ``python -m fpga_robotics.bench.camera`` (the application layer, which
reports bad arguments as usage errors); ``fpga-robotics bench camera`` runs the
same command.

The scene is a typical room: 8 m x 6 m walls (2.5 m), four pieces of furniture made of four
walls each (a 1.2 m wooden divider among them) and three people. The camera drives a loop
through the room turning as it goes, so every frame sees a different view; each repeat renders
the whole loop and the figures reported are medians over every frame of every repeat: wall
clock, and CPU time of the process (which a busy machine does not inflate). With ``--noise``
(default 2.0) the same again with sensor noise.
"""

import math
import time

import numpy as np

from fpga_robotics.sim.camera.raster import DEFAULT_HFOV, CameraRenderer
from fpga_robotics.sim.camera.scene import Band, CameraPose, Cylinder, Lighting, Scene, Wall

__all__ = ["DEFAULT_SIZES", "benchmark", "camera_loop", "typical_scene"]

DEFAULT_SIZES = ((160, 120), (320, 240), (640, 480))


def _box(cx, cy, length, width, angle, height, color):
    c, s = math.cos(angle), math.sin(angle)
    pts = [(-length / 2, -width / 2), (length / 2, -width / 2), (length / 2, width / 2),
           (-length / 2, width / 2)]
    pts = [(cx + c * x - s * y, cy + s * x + c * y) for x, y in pts]
    return [Wall(*pts[i], *pts[(i + 1) % 4], height, color) for i in range(4)]


def _person(x, y, shirt):
    return Cylinder(x, y, 0.2, (Band(0.0, 0.85, (0.15, 0.15, 0.22)), Band(0.85, 1.45, shirt),
                                Band(1.5, 1.75, (0.87, 0.68, 0.56))))


def typical_scene():
    """The benchmark room as a :class:`~fpga_robotics.sim.camera.scene.Scene`."""
    walls = _box(4.0, 3.0, 8.0, 6.0, 0.0, 2.5, (0.8, 0.78, 0.72))
    walls += _box(5.5, 4.2, 1.6, 0.05, 0.3, 1.2, (0.55, 0.27, 0.15))  # wooden divider
    walls += _box(1.2, 5.2, 1.2, 0.6, 0.0, 0.9, (0.45, 0.42, 0.38))  # cupboard
    walls += _box(6.8, 1.0, 1.0, 1.0, 0.0, 0.75, (0.35, 0.3, 0.25))  # table
    walls += _box(3.0, 1.2, 0.5, 0.5, 0.6, 0.45, (0.3, 0.35, 0.6))  # stool
    people = (_person(4.5, 3.5, (0.85, 0.1, 0.1)), _person(6.5, 4.8, (0.2, 0.5, 0.25)),
              _person(2.0, 2.8, (0.25, 0.3, 0.7)))
    return Scene(walls=tuple(walls), cylinders=people,
                 lighting=Lighting(ambient=0.6, intensity=0.5, direction=(1.0, 0.5, -1.0)))


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
