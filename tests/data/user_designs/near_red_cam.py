"""NearRed (near_red.py) with ports of its own names, bound by declaration: the camera's
stream is ``cam`` and its colour select ``sel``, the wheels ``wheel_l``/``wheel_r``."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature


class NearRedCam(wiring.Component):
    """Drives at red until it is near (its own port names)."""

    connectors = {
        "camera": {"pixels": "cam", "color_sel": "sel"},
        "wheels": {"motor_left": "wheel_l", "motor_right": "wheel_r"},
    }

    def __init__(self, speed: int = 200, near_pixels: int = 60, stream: str = "cam"):
        self.speed, self.near_pixels = speed, near_pixels
        if stream != "cam":  # a declaration naming a port that is no stream (refused)
            self.connectors = {"camera": {"pixels": stream}}
        super().__init__({
            "cam": In(pixel_stream_signature()),
            "sel": In(3),
            "wheel_l": Out(signed(16)),
            "wheel_r": Out(signed(16)),
            "near": Out(1),
            "red_count": Out(16),
        })

    def elaborate(self, platform):
        m = Module()
        p = self.cam.payload.pixel
        red = (p.r >= 8) & (p.g < 5) & (p.b < 5)
        count = Signal(16)
        with m.If(self.cam.valid):
            with m.If(self.cam.payload.first):  # a new frame: the last one's count out
                m.d.sync += [self.red_count.eq(count), count.eq(red),
                             self.near.eq(count > self.near_pixels)]
            with m.Else():
                m.d.sync += count.eq(count + red)
        speed = Mux(self.near, 0, self.speed)
        m.d.comb += [self.wheel_l.eq(speed), self.wheel_r.eq(speed)]
        return m
