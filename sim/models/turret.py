"""Golden model of the turret channel of ``TurretTracker`` in numpy, from ``TurretParams``'
law (hw/turret_params.py): FollowTarget's colour filter and tracker (``follow_target``'s
model) on the pan camera's frame, then the servo angle updated once a found frame, and swept
in search of the target once it has been lost for ``lost_frames`` frames."""

from dataclasses import dataclass

from fpga_robotics.hw.turret_params import TurretParams

from ..camera.frames import to_rgb444
from .follow_target import TrackerResult, match_table, track_frame

__all__ = ["AimState", "TurretAimModel", "TurretChannel", "TurretFrame", "aim_step"]


@dataclass(frozen=True)
class AimState:
    """The aim's state: the angle, the consecutive lost frames (saturating at
    ``lost_frames``) and the side the target was last seen on (True: left, the reset
    value)."""

    angle: int = 0
    lost: int = 0
    left: bool = True


def aim_step(state, tracker, params):
    """The ``AimState`` after a frame whose tracker outputs are ``tracker``.

    Found: ``angle -+ ((kp_num * e) >> kp_shift)`` (``e = centroid_x - width // 2``;
    Python's ``>>`` floors, as the gateware's arithmetic shift), saturated; the lost count
    returns to 0 and the side becomes ``e < 0`` (left; ``e = 0`` keeps it). Lost: the count
    goes up (saturating at ``lost_frames``); once it reaches ``lost_frames`` the angle moves
    ``search_step`` towards the side, and at a limit it stops there and the side turns."""
    p = params
    if tracker.found:
        e = tracker.centroid_x - p.width // 2
        step = (p.kp_num * e) >> p.kp_shift
        new = state.angle + step if p.inverted else state.angle - step
        angle = max(-p.angle_limit, min(p.angle_limit, new))
        return AimState(angle, 0, state.left if e == 0 else e < 0)
    lost = min(state.lost + 1, p.lost_frames)
    if lost < p.lost_frames:
        return AimState(state.angle, lost, state.left)
    new = state.angle + p.search_step if state.left else state.angle - p.search_step
    if new >= p.angle_limit:
        return AimState(p.angle_limit, lost, False)
    if new <= -p.angle_limit:
        return AimState(-p.angle_limit, lost, True)
    return AimState(new, lost, state.left)


@dataclass(frozen=True)
class TurretFrame:
    """What the turret channel produced for one frame."""

    tracker: TrackerResult
    angle: int


class TurretAimModel:
    """The turret channel frame by frame, with its state (``AimState``; its reset value
    after reset)."""

    def __init__(self, params=None):
        self.params = TurretParams() if params is None else params
        self.state = AimState()

    @property
    def angle(self):
        return self.state.angle

    def reset(self):
        self.state = AimState()

    def process(self, frame, color_sel):
        """One frame (packed RGB444 (H, W) or RGB888 (H, W, 3)) with colour select code
        ``color_sel``; returns a ``TurretFrame``."""
        tp = self.params.tracker_params
        packed = to_rgb444(frame, tp.width, tp.height)
        tracker = track_frame(match_table(color_sel, tp)[packed], tp)
        self.state = aim_step(self.state, tracker, self.params)
        return TurretFrame(tracker, self.state.angle)


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
    #: The design's pulse at a frame's results and the outputs ``process`` returns: what a
    #: clocked backend reads off the design instead (fpga_robotics.loop.pin_channel).
    done_port = "turret_frame_done"
    output_ports = ("turret_found", "turret_centroid_x", "servo_angle")

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
