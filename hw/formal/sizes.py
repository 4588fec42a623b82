"""The parameters the formal checks elaborate the design with.

A frame's promises (``frame_done``, latency, no leaks) need whole frames inside the bounded
search, so they are checked on ``SMALL``: the smallest frames the parameters allow in width
(16 columns), 2 lines, with margins on both sides of the window so the window test is
exercised, and thresholds scaled down so that every proximity level and both window edges
are reachable. Per-frame arithmetic (``TrackerResults``), the colour filter and the motor
controller do not depend on the frame length and are checked at the full sizes.
"""

from ..params import FollowTargetParams

__all__ = ["FULL_SIZES", "SMALL"]

#: 16x2 frames, an 8-column window (4 columns of margin each side, bins 1 column wide).
SMALL = FollowTargetParams(
    width=16,
    height=2,
    margin_x=4,
    margin_y=0,
    min_pixels=2,
    proximity_thresholds=(2, 3, 4, 6, 8, 10, 12),
    lost_frames=2,
)

#: The resolutions the project runs, with their default parameters.
FULL_SIZES = {
    "160x120": FollowTargetParams(),
    "640x480": FollowTargetParams(width=640, height=480),
}
