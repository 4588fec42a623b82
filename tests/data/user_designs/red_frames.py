"""A camera-only design of one's own, run frame by frame in compressed timing: it raises
``frame_done`` at each frame's last pixel, with ``found`` and the frame's count of strongly red
pixels, and drives at red while it is found and not near.

``red_sum``, the sum of the last four frames' counts, is added up one count a clock after
``frame_done``: it shows the frame's value a few edges later, as the wheels of a design that
computes them over several cycles would.
"""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature


class RedFrames(wiring.Component):
    """Counts each frame's red pixels; drives at red until it is near."""

    pixels: In(pixel_stream_signature())
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    frame_done: Out(1)
    found: Out(1)
    red_count: Out(16)
    red_sum: Out(18)

    def __init__(self, speed: int = 300, height: int = 30, min_pixels: int = 3,
                 near_pixels: int = 300):
        self.speed, self.height = speed, height
        self.min_pixels, self.near_pixels = min_pixels, near_pixels
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        p = self.pixels.payload
        red = (p.pixel.r >= 8) & (p.pixel.g < 5) & (p.pixel.b < 5)
        count = Signal(16)
        rows = Signal(range(self.height + 1))
        m.d.sync += self.frame_done.eq(0)
        with m.If(self.pixels.valid):
            with m.If(p.first):
                m.d.sync += [count.eq(red), rows.eq(0)]
            with m.Else():
                m.d.sync += count.eq(count + red)
            with m.If(p.last):
                m.d.sync += rows.eq(Mux(p.first, 1, rows + 1))
                with m.If(rows == self.height - 1):
                    total = count + red
                    m.d.sync += [self.frame_done.eq(1), self.red_count.eq(total),
                                 self.found.eq(total >= self.min_pixels)]
        # The last four counts, summed one a clock after frame_done.
        history = [Signal(16, name=f"history{i}") for i in range(4)]
        acc = Signal(18)
        step = Signal(range(5))
        with m.If(self.frame_done):
            m.d.sync += [history[0].eq(self.red_count), acc.eq(0), step.eq(1)]
            m.d.sync += [history[i].eq(history[i - 1]) for i in range(1, 4)]
        with m.Elif(step != 0):
            for i in range(4):
                with m.If(step == i + 1):
                    m.d.sync += acc.eq(acc + history[i])
            with m.If(step == 4):
                m.d.sync += [self.red_sum.eq(acc + history[3]), step.eq(0)]
            with m.Else():
                m.d.sync += step.eq(step + 1)
        drive = self.found & (self.red_count <= self.near_pixels)
        m.d.comb += [self.motor_left.eq(Mux(drive, self.speed, 0)),
                     self.motor_right.eq(Mux(drive, self.speed, 0))]
        return m
