"""Elaboration parameters of the turret channel of ``TurretTracker`` (``TurretParams``):
the pan camera's resolution and the proportional law that turns its centroid error into a
servo angle.

Plain Python (no Amaranth import), like ``params.py``: the gateware, the numpy model
(``sim/models/turret.py``) and the scenarios share these objects.
"""

from dataclasses import dataclass

from .params import FollowTargetParams
from .params_base import ParamsBase

__all__ = ["ANGLE_BITS", "TurretParams"]

#: Width of the servo command: the published system's 10-bit signed angle (+-500 = +-90 deg).
ANGLE_BITS = 10


@dataclass(frozen=True)
class TurretParams(ParamsBase):
    """The turret channel: a colour filter and tracker on the pan camera's frames, then the
    servo angle ``a`` updated once a found frame as ``a -= sign * ((kp_num * e) >>
    kp_shift)``, ``e = centroid_x - width // 2`` (pixels, right positive), saturating at
    ``+-angle_limit``. ``a`` grows to the left (the servo's convention), so a target right of
    the image centre turns the camera right. A found frame also remembers the side the target
    was on (``e < 0``: left; ``e = 0`` keeps the side).

    A lost frame holds the angle until ``lost_frames`` frames in a row have missed the target;
    from that frame on each lost frame sweeps the angle ``search_step`` units towards the
    remembered side, and at ``+-angle_limit`` the sweep stops there and turns back, so the
    camera scans its whole range at ``search_step`` units a frame until it finds the target
    again. ``search_step = 0`` holds the angle for ever."""

    #: The pan camera's resolution (its frames' size; the filter's thresholds are the
    #: defaults of ``FollowTargetParams``).
    width: int = 160
    height: int = 120
    #: The gain: ``kp_num / 2**kp_shift`` command units per pixel of error. At 160 px over
    #: 60 degrees a pixel near the centre is 0.41 deg = 2.3 units: 5/4 corrects about half
    #: the error a frame, which stays stable with the frame of delay the loop has.
    kp_num: int = 5
    kp_shift: int = 2
    #: The largest angle commanded (500: 90 degrees either way).
    angle_limit: int = 500
    #: Consecutive lost frames after which the camera searches (20: 1.3 s at 15 fps, long
    #: enough to ride out the person the body follows passing in front of the target; the
    #: shipped ``turret`` fails its centred check at 20 s with 8, and at 120 s with 30).
    lost_frames: int = 20
    #: The search's rate, command units a frame: 16 units (2.9 degrees) at 15 fps is 43
    #: degrees a second, well inside the field of view per frame (60 degrees = 333 units), so
    #: the sweep cannot skip over the target; a full 180-degree sweep takes 4.2 s.
    search_step: int = 16
    #: True turns the camera away from the target (a seeded bug: ``hw/variants.py``).
    inverted: bool = False

    def __post_init__(self):
        for name, lo, hi in (
            ("width", 16, 4096),
            ("height", 16, 4096),
            ("kp_num", 0, 255),
            ("kp_shift", 0, 15),
            ("angle_limit", 0, (1 << (ANGLE_BITS - 1)) - 1),
            ("lost_frames", 1, 255),
            ("search_step", 0, 255),
        ):
            self._check(name, lo, hi)
        if not isinstance(self.inverted, bool):
            raise TypeError(f"inverted must be True or False, not {self.inverted!r}")
        _ = self.tracker_params  # the frame geometry must suit the tracker (window of 8 bins)

    @property
    def tracker_params(self):
        """The ``FollowTargetParams`` of the channel's colour filter and tracker."""
        return FollowTargetParams(width=self.width, height=self.height)
