"""The closed loop: the design, its connectors and the world stepped together.

``compressed.py`` runs a camera frame's pixels back to back (the default for FollowTarget);
``real_clock.py`` runs every design cycle at its instant of world time; ``connectors/`` are
what the design's pins see of the world and do to it; ``shadow.py`` runs a second design on
the same frames; ``checkpoint.py`` saves and restores a loop's world at a frame boundary,
``fork.py`` (frames) and ``pin_fork.py`` (real clock, with ``pin_journal.py``: a pin design's
calls, replayed) run design variants from a reference run's recordings and checkpoints,
``continuation.py`` lets a shadow design drive from where it parts (``run --shadow-continue``);
``sources.py`` feeds frames from outside the simulation.
"""

# Registers real-clock timing with run_scenario (compressed.TIMINGS).
from fpga_robotics.loop import real_clock  # noqa: F401
from fpga_robotics.loop.compressed import (
    TRAJECTORY_FIELDS,
    ClosedLoop,
    RunResult,
    frame_count,
    make_backend,
    run_scenario,
)

__all__ = [
    "TRAJECTORY_FIELDS",
    "ClosedLoop",
    "RunResult",
    "frame_count",
    "make_backend",
    "run_scenario",
]
