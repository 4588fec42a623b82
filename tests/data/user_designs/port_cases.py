"""Designs whose ports an export must keep as declared: outputs never driven, a port named
after the clock, wheels under names of their own (bound by a ``connectors`` declaration), an
output wider than the simulators' 64 bits."""

from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Nothing(wiring.Component):
    """Wheel outputs declared and never driven (constant 0), an input never read."""

    go: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        r = Signal()
        m.d.sync += r.eq(r)
        return m


class ClkPort(wiring.Component):
    """An input named ``clk``, the name of the clock domain's own clock."""

    clk: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.motor_left.eq(self.clk), self.motor_right.eq(self.clk)]
        return m


class OwnWheelNames(wiring.Component):
    """Its wheels are ``wheel_l``/``wheel_r``, declared as the wheels connector's pins."""

    connectors = {"wheels": {"motor_left": "wheel_l", "motor_right": "wheel_r"}}

    wheel_l: Out(signed(16))
    wheel_r: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.wheel_l.eq(300), self.wheel_r.eq(-300)]
        return m


class WidePort(wiring.Component):
    """A 128-bit debug output beside the wheels."""

    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    huge: Out(128)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.huge.eq(self.huge + 1)
        return m
