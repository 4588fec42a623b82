"""Three phases in turn, one a clock: an FSM whose state a mutant may touch."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Phases(wiring.Component):
    """Steps through three phases while ``go`` is high."""

    go: In(1)
    phase: Out(2)

    def elaborate(self, platform):
        m = Module()
        with m.FSM():
            with m.State("A"):
                m.d.comb += self.phase.eq(0)
                with m.If(self.go):
                    m.next = "B"
            with m.State("B"):
                m.d.comb += self.phase.eq(1)
                m.next = "C"
            with m.State("C"):
                m.d.comb += self.phase.eq(2)
                m.next = "A"
        return m
