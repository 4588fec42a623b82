"""The GoPiGo3 SPI master's promises (mode 0): COPI never changes while SCLK is high nor as
it rises, SCLK only pulses inside chip select, and every byte queued goes out as exactly
eight SCLK pulses carrying its bits MSB first; chip select drops only after a byte marked
``end`` has gone out in full."""

from amaranth.asserts import AnySeq
from amaranth.hdl import Assert, Assume, Cover, Signal

from ..board.gopigo3_spi import SPIByteMaster
from .harness import Harness, delayed

__all__ = ["SPIHarness"]


class SPIHarness(Harness):
    """``SPIByteMaster`` fed free bytes under the stream rules (a byte offered stays offered,
    unchanged, until taken)."""

    def __init__(self, dut=None, half_period=1):
        super().__init__()
        self.dut = SPIByteMaster(half_period=half_period) if dut is None else dut

    def check(self, m):
        dut = self.dut
        m.submodules.dut = dut
        valid, payload = AnySeq(1), AnySeq(len(dut.bytes.payload.as_value()))
        m.d.comb += [dut.bytes.valid.eq(valid), dut.bytes.payload.eq(payload)]
        waiting = delayed(m, valid & ~dut.bytes.ready, 1)
        with m.If(waiting):  # stream rule, on the inputs only
            m.d.comb += Assume(valid & (payload == delayed(m, payload, 1)))

        sclk, copi, cs = dut.sclk, dut.copi, dut.cs
        was_sclk, was_copi, was_cs = (delayed(m, s, 1) for s in (sclk, copi, cs))
        rising = sclk & ~was_sclk
        m.d.comb += [
            Assert((copi == was_copi) | ~sclk, "COPI changed while SCLK high or rising"),
            Assert(~sclk | cs, "SCLK pulse outside chip select"),
        ]

        # The byte in flight: what was queued, and what the pulses carried so far.
        taken = valid & dut.bytes.ready
        expect = Signal(8)
        expect_end = Signal()
        pending = Signal()  # a byte was taken and its pulses are not all out yet
        got = Signal(8)
        pulses = Signal(range(9))
        with m.If(taken):
            m.d.comb += Assert(~pending, "byte taken before the last one went out")
            m.d.sync += [
                expect.eq(dut.bytes.payload.data),
                expect_end.eq(dut.bytes.payload.end),
                pending.eq(1),
                pulses.eq(0),
            ]
        with m.Elif(rising):
            m.d.comb += Assert(pending, "SCLK pulse with no byte to send")
            m.d.sync += [got.eq(got << 1 | copi), pulses.eq(pulses + 1)]
            with m.If(pulses == 7):
                m.d.sync += pending.eq(0)
        out = Signal()  # all eight pulses of the byte in flight are out
        m.d.comb += out.eq(~pending & (pulses == 8))
        with m.If(out & ~delayed(m, out, 1)):
            m.d.comb += Assert(got == expect, "the bits sent are not the byte queued")
        with m.If(was_cs & ~cs):
            m.d.comb += Assert(out & expect_end, "chip select dropped inside a message")
        with m.If(cs & ~was_cs):
            m.d.comb += Assert(taken | pending, "chip select without a byte")
        m.d.comb += [
            Cover(out & ~delayed(m, out, 1) & (expect == 0xA5)),
            Cover(taken & cs),  # a second byte of the same message
            Cover(was_cs & ~cs),  # a whole message
        ]
