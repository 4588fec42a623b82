"""The SCCB master's promises: SIOD changes while SIOC is high (or rising) only as a START (falling,
with the bus free) or a STOP (rising, after the 27 bits of a write), and each write carries
the device ID, register and value of its table entry MSB first, with SIOD released on the
three don't-care bits. The master has no inputs: one bounded run through the whole table
(and past it) is the complete behaviour for the parameters checked."""

from amaranth.hdl import Assert, Cover, Mux, Signal

from ..board.sccb import RegisterWrite, SCCBInit
from .harness import Harness, delayed

__all__ = ["SCCB_TABLE", "SCCBHarness", "write_bits"]

#: Two writes, the first with the reset wait after it: every path of the sequencer.
SCCB_TABLE = (
    RegisterWrite(0x12, 0x80, "reset", wait_after=True),
    RegisterWrite(0x8C, 0x02, "RGB444"),
)


def write_bits(device_id, entry):
    """The 27 bits of one write, in the order sent; ``None`` for a don't-care bit."""
    bits = []
    for byte in (device_id, entry.reg, entry.value):
        bits += [(byte >> (7 - k)) & 1 for k in range(8)] + [None]
    return bits


class SCCBHarness(Harness):
    """``SCCBInit`` with a short table and short waits, watched bit by bit."""

    def __init__(self, dut=None):
        super().__init__()
        self.dut = (
            SCCBInit(SCCB_TABLE, quarter_period=1, reset_wait=6, startup_wait=2)
            if dut is None
            else dut
        )

    def check(self, m):
        dut = self.dut
        m.submodules.dut = dut
        line = Signal()  # what the master puts on SIOD (released: the pull-up's 1)
        m.d.comb += line.eq(Mux(dut.siod_oe, dut.siod_o, 1))
        was_line, was_sioc = delayed(m, line, 1, init=1), delayed(m, dut.sioc, 1, init=1)
        held_high = dut.sioc & was_sioc
        start = held_high & was_line & ~line
        stop = held_high & ~was_line & line
        rising = dut.sioc & ~was_sioc

        busy = Signal()  # between a START and its STOP
        edges = Signal(range(29))  # SIOC rising edges since the START
        index = Signal(range(len(dut.table) + 1))  # writes completed
        m.d.comb += Assert(
            ~dut.sioc | (line == was_line) | start | stop,
            "SIOD changed with SIOC high, not as a START or STOP",
        )
        with m.If(start):
            m.d.comb += Assert(~busy, "START inside a write")
            m.d.sync += [busy.eq(1), edges.eq(0)]
        with m.If(stop):
            m.d.comb += Assert(busy & (edges == 28), "STOP not after the 27 bits of a write")
            m.d.sync += [busy.eq(0), index.eq(index + 1)]
        with m.If(rising & busy):
            m.d.sync += edges.eq(edges + 1)
            # Bit `edges` of write `index` is on SIOD now (the 28th edge is the STOP's).
            for i, entry in enumerate(dut.table):
                for k, bit in enumerate(write_bits(dut.device_id, entry)):
                    with m.If((index == i) & (edges == k)):
                        if bit is None:
                            m.d.comb += Assert(~dut.siod_oe, "SIOD driven on a don't-care bit")
                        else:
                            m.d.comb += Assert(
                                dut.siod_oe & (dut.siod_o == bit), f"write {i} bit {k} is not {bit}"
                            )
        m.d.comb += [
            Assert(~rising | busy, "SIOC pulse outside a write"),
            Assert(
                ~dut.done | (~busy & (index == len(dut.table))), "done before every write has ended"
            ),
            Cover(dut.done),
        ]
