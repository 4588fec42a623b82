"""An obstacle avoider: drives straight on at ``speed`` DPS and, while its front ultrasound
measures anything nearer than ``turn_mm``, turns on the spot (left wheel back, right wheel
forward) until the way ahead is clear again.

Its ports bind by name: ``trig``/``echo`` are the ultrasound connector's pins,
``motor_left``/``motor_right`` the wheels'. ``distance_mm`` and ``turning`` are read by no
connector: a run records them as ``design.distance_mm`` and ``design.turning``.
"""

from amaranth import Module, Mux, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.sensor_params import UltrasoundParams
from fpga_robotics.hw.ultrasound import UltrasoundDriver


class Avoider(wiring.Component):
    """Drives on; turns on the spot while the ultrasound sees something nearer than turn_mm."""

    trig: Out(1)
    echo: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    distance_mm: Out(16)
    turning: Out(1)

    def __init__(
        self, speed: int = 300, turn_speed: int = 150, turn_mm: int = 400, clock_hz: int = 1_000_000
    ):
        self.speed, self.turn_speed, self.turn_mm = speed, turn_speed, turn_mm
        # A measurement every 20 ms, echoes up to 2 m (farther is "no echo": the way is clear).
        self.us = UltrasoundParams(
            clock_hz=clock_hz, period_us=20_000, wait_us=2_000, max_range_mm=2000
        )
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.submodules.us = us = UltrasoundDriver(self.us)
        m.d.comb += [
            self.trig.eq(us.trig),
            us.echo.eq(self.echo),
            self.distance_mm.eq(us.distance_mm),
        ]
        # Decided once per measurement: the wheels hold their command between two.
        with m.If(us.measured):
            m.d.sync += self.turning.eq(~us.no_echo & (us.distance_mm < self.turn_mm))
        m.d.comb += [
            self.motor_left.eq(Mux(self.turning, -self.turn_speed, self.speed)),
            self.motor_right.eq(Mux(self.turning, self.turn_speed, self.speed)),
        ]
        return m
