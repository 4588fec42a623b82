"""A camera design that never follows: it turns in place at ``dps`` whatever it sees, and
reports ``found`` truthfully (at least ``min_pixels`` strongly red pixels in the frame). It
loses a standing person and finds them again every turn: a search check alone passes it."""

from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature


class Spinner(wiring.Component):
    """Turns in place; ``found`` when the frame holds at least min_pixels red pixels."""

    pixels: In(pixel_stream_signature())
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    frame_done: Out(1)
    found: Out(1)

    def __init__(self, dps: int = 350, height: int = 120, min_pixels: int = 50):
        self.dps, self.height, self.min_pixels = dps, height, min_pixels
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
                m.d.sync += rows.eq(rows + 1)
                with m.If(rows == self.height - 1):
                    m.d.sync += [
                        self.frame_done.eq(1),
                        self.found.eq(count + red >= self.min_pixels),
                    ]
        m.d.comb += [self.motor_left.eq(self.dps), self.motor_right.eq(-self.dps)]
        return m
