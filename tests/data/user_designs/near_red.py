"""A camera design of one's own: counts the strongly red pixels of each frame and drives
towards them until they fill more than ``near_pixels`` of the frame.

``pixels`` (a framed RGB444 stream) and ``color_sel`` bind to the camera by name,
``motor_left``/``motor_right`` to the wheels. ``near`` and ``red_count`` are read by no
connector: the run records them under their own names.
"""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature


class NearRed(wiring.Component):
    """Drives at red until it is near."""

    def __init__(self, speed: int = 200, near_pixels: int = 60):
        self.speed, self.near_pixels = speed, near_pixels
        super().__init__({
            "pixels": In(pixel_stream_signature()),
            "color_sel": In(3),
            "motor_left": Out(signed(16)),
            "motor_right": Out(signed(16)),
            "near": Out(1),
            "red_count": Out(16),
        })

    def elaborate(self, platform):
        m = Module()
        p = self.pixels.payload.pixel
        red = (p.r >= 8) & (p.g < 5) & (p.b < 5)
        count = Signal(16)
        with m.If(self.pixels.valid):
            with m.If(self.pixels.payload.first):  # a new frame: the last one's count out
                m.d.sync += [self.red_count.eq(count), count.eq(red),
                             self.near.eq(count > self.near_pixels)]
            with m.Else():
                m.d.sync += count.eq(count + red)
        speed = Mux(self.near, 0, self.speed)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m
