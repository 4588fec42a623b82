"""Designs that define their own sync domain (an asynchronous reset), itself or in a
submodule: every command refuses them in one line (tests/test_user_designs.py)."""

from amaranth import ClockDomain, Module, Mux, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class OwnSync(wiring.Component):
    pressed: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    stopped: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = ClockDomain(async_reset=True)
        with m.If(self.pressed):
            m.d.sync += self.stopped.eq(1)
        speed = Mux(self.stopped, 0, 300)
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m


class _Latch(wiring.Component):
    pressed: In(1)
    stopped: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = ClockDomain()
        with m.If(self.pressed):
            m.d.sync += self.stopped.eq(1)
        return m


class OwnSyncBelow(OwnSync):
    def elaborate(self, platform):
        m = Module()
        m.submodules.latch = latch = _Latch()
        speed = Mux(latch.stopped, 0, 300)
        m.d.comb += [latch.pressed.eq(self.pressed), self.stopped.eq(latch.stopped)]
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m

