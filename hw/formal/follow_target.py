"""``FollowTarget``'s frame promises: ``frame_done`` is a one-cycle strobe that comes exactly
``result_latency`` edges after the last pixel of a well-formed frame, and never otherwise.

The pixels, their flags, ``valid`` and ``color_sel`` are free on every cycle: any mix of
well-formed, malformed and cut-short frames and blanking. The contract's framing rules
(``FramingMonitor``) say which pixels end a well-formed frame.
"""

from amaranth.asserts import AnySeq
from amaranth.hdl import Assert, Cover, Signal

from ..top import FollowTarget
from .framing import FramingMonitor
from .harness import Harness, delayed
from .sizes import SMALL

__all__ = ["FollowTargetCovers", "FrameDoneHarness"]


class _FreeInputs(Harness):
    """``FollowTarget`` fed free inputs, with the framing monitor on its pixel input."""

    def __init__(self, dut=None):
        super().__init__()
        self.dut = FollowTarget(SMALL) if dut is None else dut

    def drive(self, m):
        dut, p = self.dut, self.dut.params
        m.submodules.dut = dut
        pixel = AnySeq(len(dut.pixels.payload.as_value()))
        m.d.comb += [
            dut.pixels.valid.eq(AnySeq(1)),
            dut.pixels.payload.eq(pixel),
            dut.color_sel.eq(AnySeq(3)),
        ]
        payload = dut.pixels.payload
        return FramingMonitor(m, p.width, p.height, dut.pixels.valid, payload.first, payload.last)


class FrameDoneHarness(_FreeInputs):
    """One of the ``frame_done`` promises, chosen by ``promise``:

    ``strobe``
        never high on two cycles in a row;
    ``well_formed_only``
        high only ``result_latency`` edges after a well-formed frame's last pixel (so never
        for a malformed frame, and at most once per frame);
    ``latency``
        high whenever a well-formed frame's last pixel was ``result_latency`` edges ago.
    """

    PROMISES = ("strobe", "well_formed_only", "latency")

    def __init__(self, promise, dut=None):
        super().__init__(dut)
        if promise not in self.PROMISES:
            raise ValueError(f"promise must be one of {', '.join(self.PROMISES)}")
        self.promise = promise

    def check(self, m):
        monitor = self.drive(m)
        done = self.dut.frame_done
        if self.promise == "strobe":
            m.d.comb += Assert(~(done & delayed(m, done, 1)), "frame_done high two cycles")
            return
        due = Signal()  # a well-formed frame's last pixel was result_latency edges ago
        # The last pixel is sampled at edge P; frame_done shows right after P + latency,
        # i.e. latency + 1 registers after the cycle in which the pixel is on the input.
        m.d.comb += due.eq(delayed(m, monitor.ends, self.dut.params.result_latency + 1))
        if self.promise == "well_formed_only":
            m.d.comb += Assert(~done | due, "frame_done without a well-formed frame")
        else:
            m.d.comb += Assert(~due | done, "frame_done late or missing")


class FollowTargetCovers(_FreeInputs):
    """The interesting results are reachable from pixels: proximity 7, the centroid on the
    window's first and last columns (the search is covered on the motor controller: three
    whole frames are too deep a search here)."""

    def check(self, m):
        self.drive(m)
        dut, p = self.dut, self.dut.params
        new = dut.frame_done  # a frame's values show
        m.d.comb += [
            Cover(new & (dut.proximity == 7)),
            Cover(new & dut.found & (dut.centroid_x == p.margin_x)),
            Cover(new & dut.found & (dut.centroid_x == p.width - p.margin_x - 1)),
        ]
