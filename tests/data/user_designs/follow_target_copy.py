"""FollowTarget unchanged, as a design of one's own: a camera-only design that raises
frame_done, run frame by frame in compressed timing like the built-in ``follow_target``."""

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.top import FollowTarget


def follow_target_copy(width: int = 160, height: int = 120):
    """FollowTarget at its default parameters for frames of width x height."""
    return FollowTarget(FollowTargetParams(width=width, height=height))
