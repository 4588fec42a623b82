"""The frames the design benchmarks time: seeded synthetic camera frames of a target sweeping
across a noisy background."""

import numpy as np

from fpga_robotics.sim.camera import synthetic

__all__ = ["bench_frames"]


def bench_frames(width, height, count, seed):
    """Frames a robot would see: a target sweeping across a noisy background (RGB888, as a
    camera or the renderer gives them)."""
    rng = np.random.default_rng(seed)
    states = synthetic.scenario_states("sweep", width, height, n_frames=count)
    return [np.ascontiguousarray(f) for f in synthetic.sequence(width, height, states, rng=rng)]
