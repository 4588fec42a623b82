"""``TurretTracker``: FollowTarget on the body camera, and a pan camera on a servo that keeps a
second target centred (the published turret application).

The turret channel (``TurretAim``) reuses FollowTarget's colour filter and tracker on the pan
camera's own pixel stream and colour select, then ``ServoAim`` turns the tracker's centroid
error into the servo's 10-bit signed angle (``TurretParams``), and sweeps it in search of the
target once the target has been lost for ``lost_frames`` frames. The two channels share
nothing but the clock: the body camera's frames steer the wheels as in ``FollowTarget``.
"""

from typing import ClassVar

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .color_filter import ColorFilter
from .pixel import TargetColor, pixel_stream_signature
from .top import FollowTarget, follow_target_signature
from .tracker import FrameTracker
from .turret_params import ANGLE_BITS, TurretParams

__all__ = ["ServoAim", "TurretAim", "TurretTracker"]


class ServoAim(wiring.Component):
    """The proportional pan law of ``TurretParams``, once a frame, and its search: after
    ``lost_frames`` lost frames in a row the angle sweeps ``search_step`` a frame towards the
    side the target was last seen on, turning back at the limits.

    Members
    -------
    update : ``In(1)``
        The tracker's ``frame_done``: a frame's results are on the inputs.
    found : ``In(1)``
    centroid_x : ``In(x_bits)``
    angle : ``Out(signed(10))``
        The servo command, registered: it shows a frame's update one cycle after ``update``.
    lost_count : ``Out(range(lost_frames + 1))``
        Consecutive lost frames, saturating at ``lost_frames`` (the camera is searching).
    """

    def __init__(self, params):
        if not isinstance(params, TurretParams):
            raise TypeError(f"params must be a TurretParams, not {params!r}")
        self.params = params
        x_bits = params.tracker_params.x_bits
        super().__init__(
            {
                "update": In(1),
                "found": In(1),
                "centroid_x": In(x_bits),
                "angle": Out(signed(ANGLE_BITS)),
                "lost_count": Out(range(params.lost_frames + 1)),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        error = Signal(signed(p.tracker_params.x_bits + 2))
        step = Signal(signed(error.shape().width + 9))
        wide = Signal(signed(ANGLE_BITS + step.shape().width))
        m.d.comb += [
            error.eq(self.centroid_x - p.width // 2),
            step.eq((error * p.kp_num) >> p.kp_shift),  # arithmetic shift: floor division
            wide.eq(self.angle + step if p.inverted else self.angle - step),
        ]
        # The side the target was last seen on (1: left, the reset value) sets the search's
        # direction.
        left = Signal(init=1)
        lost_next = Signal.like(self.lost_count)
        sweep = Signal(signed(ANGLE_BITS + 2))
        m.d.comb += [
            lost_next.eq(Mux(self.lost_count == p.lost_frames, p.lost_frames, self.lost_count + 1)),
            sweep.eq(Mux(left, self.angle + p.search_step, self.angle - p.search_step)),
        ]
        with m.If(self.update & self.found):
            m.d.sync += self.lost_count.eq(0)
            with m.If(error < 0):
                m.d.sync += left.eq(1)
            with m.Elif(error > 0):
                m.d.sync += left.eq(0)
            with m.If(wide > p.angle_limit):
                m.d.sync += self.angle.eq(p.angle_limit)
            with m.Elif(wide < -p.angle_limit):
                m.d.sync += self.angle.eq(-p.angle_limit)
            with m.Else():
                m.d.sync += self.angle.eq(wide)
        with m.Elif(self.update):
            m.d.sync += self.lost_count.eq(lost_next)
            with m.If(lost_next == p.lost_frames):
                with m.If(sweep >= p.angle_limit):
                    m.d.sync += [self.angle.eq(p.angle_limit), left.eq(0)]
                with m.Elif(sweep <= -p.angle_limit):
                    m.d.sync += [self.angle.eq(-p.angle_limit), left.eq(1)]
                with m.Else():
                    m.d.sync += self.angle.eq(sweep)
        return m


def turret_aim_signature(params):
    return wiring.Signature(
        {
            "pixels": In(pixel_stream_signature()),
            "color_sel": In(TargetColor),
            "frame_done": Out(1),
            "found": Out(1),
            "centroid_x": Out(params.tracker_params.x_bits),
            "angle": Out(signed(ANGLE_BITS)),
        }
    )


class TurretAim(wiring.Component):
    """The turret channel: ``ColorFilter`` -> ``FrameTracker`` -> ``ServoAim`` on one pixel
    stream. ``frame_done``, ``found`` and ``centroid_x`` are the tracker's; ``angle`` shows
    the frame's update one cycle after ``frame_done``."""

    def __init__(self, params=None):
        params = TurretParams() if params is None else params
        if not isinstance(params, TurretParams):
            raise TypeError(f"params must be a TurretParams, not {params!r}")
        self.params = params
        tp = params.tracker_params
        self.color_filter = ColorFilter(tp)
        self.tracker = FrameTracker(tp, inspect=False)
        self.aim = ServoAim(params)
        super().__init__(turret_aim_signature(params))

    def elaborate(self, platform):
        m = Module()
        m.submodules.color_filter = cf = self.color_filter
        m.submodules.tracker = tracker = self.tracker
        m.submodules.aim = aim = self.aim
        wiring.connect(m, wiring.flipped(self.pixels), cf.pixels)
        wiring.connect(m, cf.matches, tracker.matches)
        m.d.comb += [
            cf.color_sel.eq(self.color_sel),
            aim.update.eq(tracker.frame_done),
            aim.found.eq(tracker.found),
            aim.centroid_x.eq(tracker.centroid_x),
            self.frame_done.eq(tracker.frame_done),
            self.found.eq(tracker.found),
            self.centroid_x.eq(tracker.centroid_x),
            self.angle.eq(aim.angle),
        ]
        return m


class TurretTracker(wiring.Component):
    """FollowTarget's ports, plus the pan camera's ``turret_pixels`` and ``turret_color_sel``
    in and ``turret_frame_done``, ``turret_found``, ``turret_centroid_x`` and
    ``servo_angle`` (signed 10 bits, +-500 = +-90 degrees) out.

    Parameters
    ----------
    params : FollowTargetParams
        The body camera's channel (FollowTarget).
    turret : TurretParams
        The pan camera's channel.
    """

    #: The ports the connectors bind (designs/reference.py): the pan camera and the servo.
    connectors: ClassVar[dict] = {"servo": {"angle": "servo_angle"}}

    def __init__(self, params=None, turret=None):
        self.follow = FollowTarget(params)
        self.params = self.follow.params
        self.turret = TurretParams() if turret is None else turret
        self.aim = TurretAim(self.turret)
        members = dict(follow_target_signature(self.params).members)
        aim = turret_aim_signature(self.turret).members
        members.update(
            {
                "turret_pixels": aim["pixels"],
                "turret_color_sel": aim["color_sel"],
                "turret_frame_done": aim["frame_done"],
                "turret_found": aim["found"],
                "turret_centroid_x": aim["centroid_x"],
                "servo_angle": aim["angle"],
            }
        )
        super().__init__(wiring.Signature(members))

    def elaborate(self, platform):
        m = Module()
        m.submodules.follow = follow = self.follow
        m.submodules.aim = aim = self.aim
        for name in follow_target_signature(self.params).members:
            if name in ("pixels", "filtered"):
                continue
            port, inner = getattr(self, name), getattr(follow, name)
            m.d.comb += inner.eq(port) if name == "color_sel" else port.eq(inner)
        wiring.connect(m, wiring.flipped(self.pixels), follow.pixels)
        wiring.connect(m, follow.filtered, wiring.flipped(self.filtered))
        wiring.connect(m, wiring.flipped(self.turret_pixels), aim.pixels)
        m.d.comb += [
            aim.color_sel.eq(self.turret_color_sel),
            self.turret_frame_done.eq(aim.frame_done),
            self.turret_found.eq(aim.found),
            self.turret_centroid_x.eq(aim.centroid_x),
            self.servo_angle.eq(aim.angle),
        ]
        return m
