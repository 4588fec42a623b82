"""This machine's calibration frame time (``fpga-robotics bench calibrate``, ``--calibrate`` on
a benchmark): the published FPGA-Robotics design as a preset of this project's gateware at
160x120 on the fastest compiled backend here, milliseconds per frame of seeded synthetic
frames. An absolute time divided by it, both measured in one run, compares across machines."""

import time

from fpga_robotics.bench.frames import bench_frames
from fpga_robotics.bench.timing import Spread, gc_paused, stopwatch
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import (
    BACKEND_NAMES,
    BackendError,
    fastest_backend_name,
    get_backend,
)

__all__ = ["CALIBRATION_SIZE", "calibration_backend", "measure_calibration"]

CALIBRATION_SIZE = (160, 120)


def calibration_backend(name="auto"):
    if name == "auto":
        return fastest_backend_name()
    if name not in BACKEND_NAMES:
        raise UsageError(f"unknown backend {name!r}; choose from auto, {', '.join(BACKEND_NAMES)}")
    return name


def measure_calibration(*, repeats=5, frames=30, backend="auto", seed=0):
    """``{"what", "backend", "frame_ms": Spread, "cpu_ms": Spread}``: the published preset's
    median ms per frame in each of ``repeats`` passes over ``frames`` frames (wall clock, and
    CPU time of this thread), after one warm-up frame; the build (or cache load) untimed."""
    name = calibration_backend(backend)
    w, h = CALIBRATION_SIZE
    params = FollowTargetParams.published(width=w, height=h)
    images = bench_frames(w, h, frames, seed)
    walls, cpus = [], []
    try:
        design = get_backend(name, params)
    except BackendError as exc:
        raise UsageError(f"the {name} backend cannot run here: {exc}") from None
    with design:
        design.process_frame(images[0])
        with gc_paused():
            for _ in range(repeats):
                wall, cpu = [], []
                for image in images:
                    with stopwatch(time.thread_time) as t:
                        design.process_frame(image)
                    wall.append(t.wall * 1e3)
                    cpu.append(t.cpu * 1e3)
                walls.append(Spread.of(wall).median)
                cpus.append(Spread.of(cpu).median)
    return {
        "what": f"published preset, {name}, {w}x{h}",
        "backend": name,
        "frame_ms": Spread.of(walls),
        "cpu_ms": Spread.of(cpus),
    }
