"""A design of one's own without wheels: it only counts the bumper's closings. ``pressed``
binds to the bumper by name; ``presses`` is recorded under its own name."""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class BumpWatch(wiring.Component):
    """Counts the bumper's closings (no wheels: the robot stands)."""

    pressed: In(1)
    presses: Out(8)

    def elaborate(self, platform):
        m = Module()
        last = Signal()
        m.d.sync += last.eq(self.pressed)
        with m.If(self.pressed & ~last):
            m.d.sync += self.presses.eq(self.presses + 1)
        return m
