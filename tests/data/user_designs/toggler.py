"""A design of one's own whose wheel outputs change at every clock edge: ``low`` on even
cycles, ``high`` on odd ones (as a faulty PWM stage or a mutant might drive them)."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Toggler(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def __init__(self, low: int = 200, high: int = 400):
        self.low, self.high = low, high
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        odd = Signal()
        m.d.sync += odd.eq(~odd)
        value = Mux(odd, self.high, self.low)
        m.d.comb += [self.motor_left.eq(value), self.motor_right.eq(value)]
        return m
