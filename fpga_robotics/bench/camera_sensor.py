"""Benchmark of the OV7670 sensor model: median time of each stage per frame.

The command line is ``python -m fpga_robotics.bench.camera --sensor``. The frames are the
camera benchmark's room (``fpga_robotics.bench.camera_frames``) rendered from its loop of poses
(rendering is not timed); the robot turns at ``turn_rate`` so that the motion blur runs. Each
repeat takes every frame through the sensor with every stage timed on its own (wall clock), and
the whole frame's wall clock and CPU time of the process.
"""

import time

import numpy as np

from fpga_robotics.sim.camera.raster import DEFAULT_HFOV, CameraRenderer, focal_length
from fpga_robotics.bench.camera_frames import camera_loop, typical_scene
from fpga_robotics.sim.camera.sensor.params import OV7670Params
from fpga_robotics.sim.camera.sensor.pipeline import OV7670Sensor

__all__ = ["STAGES", "stage_times"]

#: The stages in the order a frame meets them (``OV7670Sensor._frame``).
STAGES = ("light", "expose", "noise", "amplify", "demosaic", "tone", "adapt")


def stage_times(width, height, *, frames=60, repeats=5, turn_rate=0.5, hfov=DEFAULT_HFOV):
    """``{stage: [ms, ...], "frame": [...], "frame_cpu": [...]}``, ``frames * repeats`` each."""
    renderer = CameraRenderer(width, height, hfov)
    scene = typical_scene()
    images = [renderer.render(scene, pose) for pose in camera_loop(frames)]
    cam = OV7670Sensor(width, height, OV7670Params(), rng=np.random.default_rng(0),
                       focal_px=focal_length(width, hfov))
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
