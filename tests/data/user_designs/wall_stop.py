"""A design of one's own with pin sensors and no camera: drives straight on at ``speed`` DPS
and stops while an HC-SR04 measures an obstacle nearer than ``stop_mm``.

Its ports bind by name: ``trig``/``echo`` are the ultrasound connector's pins,
``motor_left``/``motor_right`` the wheels'. ``distance_mm`` and ``stopped`` are read by no
connector: the run records them under their own names.
"""

from amaranth import Module, Mux, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.sensor_params import UltrasoundParams
from fpga_robotics.hw.ultrasound import UltrasoundDriver


class WallStop(wiring.Component):
    """Drives on until the ultrasound sees a wall nearer than stop_mm."""

    trig: Out(1)
    echo: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    distance_mm: Out(16)
    stopped: Out(1)

    def __init__(self, speed: int = 300, stop_mm: int = 250, clock_hz: int = 1_000_000):
        self.speed, self.stop_mm = speed, stop_mm
        self.us = UltrasoundParams(clock_hz=clock_hz, period_us=20_000, wait_us=2_000,
                                   max_range_mm=2000)
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.submodules.us = us = UltrasoundDriver(self.us)
        m.d.comb += [self.trig.eq(us.trig), us.echo.eq(self.echo),
                     self.distance_mm.eq(us.distance_mm)]
        with m.If(us.measured):
            m.d.sync += self.stopped.eq(~us.no_echo & (us.distance_mm < self.stop_mm))
        speed = Mux(self.stopped, 0, self.speed)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m


def wall_stop(speed: int = 300):
    """WallStop built by a function (a design reference may name either)."""
    return WallStop(speed=speed)
