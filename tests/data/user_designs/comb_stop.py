"""Purely combinational bumper stop: wheels at speed until the bumper is pressed."""
from amaranth import Module, Mux, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class CombStop(wiring.Component):
    pressed: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    pressed_seen: Out(1)

    def __init__(self, speed: int = 150):
        self.speed = speed
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        speed = Mux(self.pressed, 0, self.speed)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed),
                     self.pressed_seen.eq(self.pressed)]
        return m
