"""A purely combinational design of one's own, given the clock the simulators drive."""

from amaranth import Module, Signal
from amaranth.lib import wiring

__all__ = ["ClockedCombinational"]


class ClockedCombinational(wiring.Component):
    """``inner`` (nothing in its sync domain) with the same ports, and the ``clk`` and
    ``rst`` ports the simulators here clock a design through: Amaranth gives a component
    those only when something is in its sync domain, so one register of this wrapper's own
    puts it there. The design's outputs stay combinational: each follows its inputs in the
    same cycle, as the design itself would."""

    def __init__(self, inner):
        self._inner = inner
        super().__init__(inner.signature)

    def elaborate(self, platform):
        m = Module()
        m.submodules.design = self._inner
        wiring.connect(m, wiring.flipped(self), self._inner)
        tick = Signal()
        m.d.sync += tick.eq(~tick)
        return m
