"""Designs that declare formal properties of their ports (docs/formal.md): ``Saturating``
keeps its promise, ``OffByOne`` (the same promise, one comparison wrong) breaks it."""

from amaranth import Module
from amaranth.hdl import Assert, Assume, Cover
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Saturating(wiring.Component):
    """Counts the cycles ``up`` is high, up to ``limit``, and holds there until ``clear``."""

    up: In(1)
    clear: In(1)
    count: Out(8)
    full: Out(1)

    formal_mode = "prove"
    formal_depth = 3          # the induction's length
    formal_cover_depth = 12   # the counter is full after limit (10) cycles of up

    def __init__(self, limit: int = 10):
        self.limit = limit
        super().__init__()

    def _counts_up(self):
        return self.count < self.limit

    def elaborate(self, platform):
        m = Module()
        with m.If(self.clear):
            m.d.sync += self.count.eq(0)
        with m.Elif(self.up & self._counts_up()):
            m.d.sync += self.count.eq(self.count + 1)
        m.d.comb += self.full.eq(self.count == self.limit)
        return m

    def formal_properties(self, m):
        """count never passes limit; full exactly at the limit"""
        m.d.comb += [Assert(self.count <= self.limit, "count passed the limit"),
                     Assert(self.full == (self.count == self.limit), "full is wrong")]

    def formal_covers(self, m):
        """the counter reaches full"""
        m.d.comb += [Assume(~self.clear), Cover(self.full)]


class OffByOne(Saturating):
    """Saturating with ``<=`` for ``<``: it counts one past the limit."""

    formal_mode = "bmc"
    formal_depth = 15

    def _counts_up(self):
        return self.count <= self.limit
