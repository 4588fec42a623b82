"""Golden model of the turret channel of ``TurretTracker`` in numpy, from ``TurretParams``'
law (hw/turret_params.py): FollowTarget's colour filter and tracker (``follow_target``'s
model) on the pan camera's frame, then the servo angle updated once a found frame."""

from dataclasses import dataclass

from fpga_robotics.hw.turret_params import TurretParams

from ..camera.frames import to_rgb444
from .follow_target import TrackerResult, match_table, track_frame

__all__ = ["TurretAimModel", "TurretChannel", "TurretFrame", "aim_step"]


def aim_step(angle, tracker, params):
    """The angle after a frame whose tracker outputs are ``tracker``: unchanged when the
    target is not found, else ``angle -+ ((kp_num * e) >> kp_shift)`` (``e = centroid_x -
    width // 2``; Python's ``>>`` floors, as the gateware's arithmetic shift), saturated."""
    if not tracker.found:
        return angle
    step = (params.kp_num * (tracker.centroid_x - params.width // 2)) >> params.kp_shift
    new = angle + step if params.inverted else angle - step
    return max(-params.angle_limit, min(params.angle_limit, new))


@dataclass(frozen=True)
class TurretFrame:
    """What the turret channel produced for one frame."""

    tracker: TrackerResult
    angle: int


class TurretAimModel:
    """The turret channel frame by frame, with its one piece of state: the angle (0 after
    reset)."""

    def __init__(self, params=None):
        self.params = TurretParams() if params is None else params
        self.angle = 0

    def reset(self):
        self.angle = 0

    def process(self, frame, color_sel):
        """One frame (packed RGB444 (H, W) or RGB888 (H, W, 3)) with colour select code
        ``color_sel``; returns a ``TurretFrame``."""
        tp = self.params.tracker_params
        packed = to_rgb444(frame, tp.width, tp.height)
        tracker = track_frame(match_table(color_sel, tp)[packed], tp)
        self.angle = aim_step(self.angle, tracker, self.params)
        return TurretFrame(tracker, self.angle)


class TurretChannel:
    """``TurretTracker``'s turret channel as the closed loop's compressed timing runs it: one
    pan-camera frame in, the design's ports out (``{port: value}``), by the numpy model.

    Parameters
    ----------
    tables : dict
        The scenario's design tables (``turret``: a ``TurretParams``; absent: the defaults).
    """

    #: The colour select port of the channel's pixel bundle.
    color_port = "turret_color_sel"
    #: The outputs the viewer shows with the camera's image: found, centroid column.
    view_ports = ("turret_found", "turret_centroid_x")

    def __init__(self, tables):
        self.model = TurretAimModel(tables.get("turret"))
        tp = self.model.params
        self.frame_size = (tp.width, tp.height)

    def reset(self):
        self.model.reset()

    def process(self, frame, color_sel):
        out = self.model.process(frame, color_sel)
        return {
            "turret_found": int(out.tracker.found),
            "turret_centroid_x": out.tracker.centroid_x,
            "servo_angle": out.angle,
        }
