"""The camera capture's promise: its clock-crossing FIFO never overflows at the camera's
pixel rate (two bytes a pixel), whatever the camera sends.

The camera clock is modelled as the design clock gated by a free enable: PCLK ticks on any
subset of the design clock's edges, so every PCLK up to the design clock's frequency (the
board runs PCLK at a quarter of it or less) and any jitter between them is covered. What
this does not model is metastability, which the FIFO's synchronisers are there for.
"""

from amaranth.asserts import AnySeq
from amaranth.hdl import Assert, ClockDomain, ClockSignal, Cover, EnableInserter

from ..board.ov7670_capture import OV7670Capture
from .harness import Harness

__all__ = ["CaptureHarness"]


class CaptureHarness(Harness):
    """``OV7670Capture`` fed free camera data, HREF and VSYNC on free PCLK ticks."""

    def __init__(self, dut=None, fifo_depth=16):
        super().__init__()
        self.dut = OV7670Capture(fifo_depth=fifo_depth) if dut is None else dut

    def check(self, m):
        dut = self.dut
        m.domains.pclk = ClockDomain("pclk", reset_less=True)
        m.d.comb += ClockSignal("pclk").eq(ClockSignal("sync"))
        tick = AnySeq(1)
        m.submodules.dut = EnableInserter({dut.pclk_domain: tick})(dut)
        m.d.comb += [dut.data.eq(AnySeq(8)), dut.href.eq(AnySeq(1)), dut.vsync.eq(AnySeq(1))]
        m.d.comb += [
            Assert(~dut.overflow, "the capture FIFO overflowed"),
            Cover(dut.pixels.valid & dut.pixels.payload.last),
        ]
