"""Designs that build but do not elaborate, have no clock or instantiate a module they do not
define, or forget super().__init__(): each is one clear line (tests/test_user_designs.py)."""

import sys

from amaranth import ClockSignal, Instance, Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class _Wheels(wiring.Component):
    line: In(2)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))


class ElaborateRaises(_Wheels):
    def elaborate(self, platform):
        raise ValueError("no such speed table")


class ElaborateExits(_Wheels):
    def elaborate(self, platform):
        sys.exit(0)  # a helper giving up: still a design that does not elaborate


class DrivenTwice(_Wheels):
    def elaborate(self, platform):
        m = Module()
        m.d.comb += self.motor_left.eq(1)
        m.d.sync += self.motor_left.eq(2)
        return m


class LoopsBack(_Wheels):
    def elaborate(self, platform):
        m = Module()
        a = Signal()
        b = Signal()
        m.d.comb += [a.eq(~b), b.eq(a)]  # a combinational loop through a and b
        m.d.comb += self.motor_left.eq(a)
        return m


class NoReturn(_Wheels):
    def elaborate(self, platform):
        Module()


class NoClock(_Wheels):
    def elaborate(self, platform):
        m = Module()
        m.d.comb += [self.motor_left.eq(self.line * 100), self.motor_right.eq(100)]
        return m


class BlackBox(_Wheels):
    """A vendor or Verilog module by Instance: hardware for the board, unknown to simulators."""

    def elaborate(self, platform):
        m = Module()
        speed, toggle = Signal(16), Signal()
        m.d.sync += toggle.eq(~toggle)
        m.submodules.ip = Instance("my_ip", i_clk=ClockSignal(), i_a=self.line, o_y=speed)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m


class DrivesItsInput(_Wheels):
    """A port declared In that the design drives, in a submodule's m.If."""

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = Module()
        tick = Signal()
        m.d.sync += tick.eq(~tick)
        with inner.If(tick):
            inner.d.comb += self.line.eq(3)
        return m


class DrivesItsInputByInstance(_Wheels):
    def elaborate(self, platform):
        m = Module()
        tick = Signal()
        m.d.sync += tick.eq(~tick)
        m.submodules.ip = Instance("my_ip", i_clk=ClockSignal(), o_y=self.line)
        return m


class NoSuperInit(_Wheels):
    """Its __init__ keeps a parameter and forgets super().__init__()."""

    def __init__(self, speed: int = 300):
        self.speed = speed

    def elaborate(self, platform):
        return Module()


class NoPlatform(_Wheels):
    """Its elaborate forgets the platform argument."""

    def elaborate(self):
        return Module()
