"""``FollowTarget``: colour filter, target tracker and motor controller in one component."""

from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .color_filter import ColorFilter
from .motor import DPS_BITS, MotorController
from .params import FollowTargetParams
from .pixel import TargetColor, pixel_stream_signature
from .tracker import FrameTracker

__all__ = ["FollowTarget", "follow_target_signature"]


def follow_target_signature(params):
    """The ports of ``follow_target`` (docs/contract.md, Ports) for ``params``; shared with the
    simulation flows' trivial stand-in design, so both drive the same harness."""
    return wiring.Signature(
        {
            "pixels": In(pixel_stream_signature()),
            "color_sel": In(TargetColor),
            "filtered": Out(pixel_stream_signature()),
            "frame_done": Out(1),
            "found": Out(1),
            "proximity": Out(3),
            "centroid_x": Out(params.x_bits),
            "centroid_leds": Out(8),
            "motor_left": Out(signed(DPS_BITS)),
            "motor_right": Out(signed(DPS_BITS)),
        }
    )


class FollowTarget(wiring.Component):
    """The follow-target design of docs/contract.md (Verilog module ``follow_target``).

    Parameters
    ----------
    params : FollowTargetParams, optional
        Every elaboration-time parameter; defaults to ``FollowTargetParams()`` (160x120).

    Members
    -------
    pixels : ``In(pixel_stream_signature())``
        Camera pixels: RGB444 plus ``first`` (start of frame) and ``last`` (end of line).
    color_sel : ``In(TargetColor)``
        Colour to follow, 3 bits: bit 2 red, bit 1 green, bit 0 blue.
    filtered : ``Out(pixel_stream_signature())``
        Every pixel, black where it does not match; ``params.filter_latency`` cycles later.
    frame_done : ``Out(1)``
        One-cycle strobe: the per-frame outputs below show a new frame's values.
    found, proximity, centroid_x, centroid_leds : ``Out``
        Per-frame tracker results, ``params.result_latency`` cycles after the frame's last
        pixel; held until the next frame's.
    motor_left, motor_right : ``Out(signed(16))``
        Wheel speeds in DPS, ``params.motor_latency`` cycles after ``frame_done``.
    """

    def __init__(self, params=None):
        params = FollowTargetParams() if params is None else params
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        # Built here rather than in elaborate() so that tests and waveforms can reach them.
        self.color_filter = ColorFilter(params)
        # Without the tracker's inspection outputs: three wide registers nothing here reads.
        self.tracker = FrameTracker(params, inspect=False)
        self.motor = MotorController(params)
        super().__init__(follow_target_signature(params))

    def elaborate(self, platform):
        m = Module()
        p = self.params
        m.submodules.color_filter = cf = self.color_filter
        m.submodules.tracker = tracker = self.tracker
        m.submodules.motor = motor = self.motor
        # The params' latency figures are what the host side relies on: keep them honest.
        assert cf.latency == p.filter_latency
        assert cf.latency + tracker.latency == p.result_latency
        assert motor.latency == p.motor_latency

        wiring.connect(m, wiring.flipped(self.pixels), cf.pixels)
        wiring.connect(m, cf.filtered, wiring.flipped(self.filtered))
        wiring.connect(m, cf.matches, tracker.matches)
        m.d.comb += [
            cf.color_sel.eq(self.color_sel),
            motor.update.eq(tracker.frame_done),
            motor.found.eq(tracker.found),
            motor.proximity.eq(tracker.proximity),
            motor.centroid_x.eq(tracker.centroid_x),
            self.frame_done.eq(tracker.frame_done),
            self.found.eq(tracker.found),
            self.proximity.eq(tracker.proximity),
            self.centroid_x.eq(tracker.centroid_x),
            self.centroid_leds.eq(tracker.centroid_leds),
            self.motor_left.eq(motor.left),
            self.motor_right.eq(motor.right),
        ]
        if p.motor_uses_leds:  # the table law and the search side from the LEDs only
            m.d.comb += motor.leds.eq(tracker.centroid_leds)
        return m
