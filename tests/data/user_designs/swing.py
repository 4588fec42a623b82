"""FollowTarget with a swinging steering: ``amp`` DPS of turn added to its command, to the left
for ``period`` frames, then to the right for as many. The robot swings about the person, so
far that the person leaves the image centre at each swing."""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.top import FollowTarget, follow_target_signature


class Swing(wiring.Component):
    """FollowTarget's outputs, its wheels plus and minus a turn that flips every period frames."""

    def __init__(self, amp: int = 400, period: int = 20):
        self.amp, self.period = amp, period
        self.p = FollowTargetParams()
        super().__init__(follow_target_signature(self.p))

    def elaborate(self, platform):
        m = Module()
        m.submodules.ft = ft = FollowTarget(self.p)
        wiring.connect(m, wiring.flipped(self.pixels), ft.pixels)
        wiring.connect(m, ft.filtered, wiring.flipped(self.filtered))
        m.d.comb += [
            ft.color_sel.eq(self.color_sel),
            self.frame_done.eq(ft.frame_done),
            self.found.eq(ft.found),
            self.proximity.eq(ft.proximity),
            self.centroid_x.eq(ft.centroid_x),
            self.centroid_leds.eq(ft.centroid_leds),
        ]
        frames = Signal(range(self.period))
        right = Signal()
        with m.If(ft.frame_done):
            m.d.sync += frames.eq(Mux(frames == self.period - 1, 0, frames + 1))
            with m.If(frames == self.period - 1):
                m.d.sync += right.eq(~right)
        turn = Mux(right, self.amp, -self.amp)
        m.d.comb += [
            self.motor_left.eq(ft.motor_left + turn),
            self.motor_right.eq(ft.motor_right - turn),
        ]
        return m
