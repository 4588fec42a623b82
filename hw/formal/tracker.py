"""The tracker's promises: nothing of an abandoned frame leaks into the next frame's results
(a miter of two window counters), and the per-frame results are the contract's formulas of the
counts, for every count (``found``, ``proximity``, ``centroid_x``, the LED code)."""

from amaranth.asserts import AnyConst, AnySeq
from amaranth.hdl import Assert, Assume, Const, Cover, Mux, Signal, Value

from ..tracker import TrackerResults
from ..window_counter import WindowCounter
from .harness import Harness, delayed
from .sizes import FULL_SIZES, SMALL

__all__ = ["NoLeakMiter", "ProximityMonotonic", "ResultsFormulas", "contract_leds"]


class NoLeakMiter(Harness):
    """Two window counters (the tracker's per-pixel half, which turns pixels into a frame's
    counts): one fed free inputs for ``prefix`` cycles, the other blanking; then both get
    the same ``first`` and the same free pixels, one a cycle. From the next cycle on their counts
    registers agree on every cycle, so they agree at every ``end``: whatever the prefix held
    (abandoned, cut-short or complete frames, blanking) does not reach the frames after it.

    The results are a function of the counts at ``end`` alone (``results.*`` proves them
    the contract's formulas of those counts), so the tracker's results agree too. The
    shared ``first`` comes at a fixed cycle: with a free one the search grew too slow to
    reach a whole frame after it."""

    def __init__(self, dut=None, twin=None, params=SMALL, prefix=20):
        super().__init__()
        self.dut = WindowCounter(params) if dut is None else dut
        self.twin = type(self.dut)(self.dut.params) if twin is None else twin  # a copy
        self.prefix = prefix

    def check(self, m):
        m.submodules.a = a = self.dut
        m.submodules.b = b = self.twin
        width = len(a.matches.payload.as_value())
        cycle = Signal(range(self.prefix + 2))
        with m.If(cycle <= self.prefix):
            m.d.sync += cycle.eq(cycle + 1)
        go = Signal()  # the shared inputs, from the `first` on
        m.d.comb += go.eq(cycle >= self.prefix)
        shared_valid, shared = AnySeq(1), AnySeq(width)
        m.d.comb += [
            a.matches.valid.eq(Mux(go, shared_valid, AnySeq(1))),
            a.matches.payload.eq(Mux(go, shared, AnySeq(width))),
            b.matches.valid.eq(go & shared_valid),
            b.matches.payload.eq(shared),
        ]
        with m.If(cycle == self.prefix):  # the shared input starts with a `first`
            m.d.comb += Assume(a.matches.payload.first)
        # No blanking after it: blanking is the frame_done checks' business, and without it
        # the search reaches the end of the frame after the `first` (with it, it did not).
        with m.If(go):
            m.d.comb += Assume(shared_valid)
        with m.If(cycle > self.prefix):
            m.d.comb += [
                Assert(a.counts.end == b.counts.end, "end differs"),
                Assert(Value.cast(a.counts.bins) == Value.cast(b.counts.bins), "bins differ"),
                Assert(a.counts.sum_x == b.counts.sum_x, "SX differs"),
            ]
            if a.params.group_column_offset:
                m.d.comb += Assert(
                    Value.cast(a.counts.edges) == Value.cast(b.counts.edges), "edges differ"
                )


def _tree(values):
    """The sum of ``values`` (Amaranth widens each add: no wrap)."""
    total = values[0]
    for v in values[1:]:
        total = total + v
    return total


def contract_leds(p, bins, count, found):
    """The contract's LED code (docs/contract.md, Per-frame outputs) of ``bins``."""
    half = count >> 1
    left, right = _tree(bins[:4]), _tree(bins[4:])
    centred = Mux(left > right, left - right, right - left) < (count >> 4)

    def from_edge(order, leds):
        code = Const(1 << leds[3], 8)
        sums = [_tree([bins[k] for k in order[:n]]) for n in (1, 2, 3)]
        for led, s in reversed(list(zip(leds[:3], sums))):
            code = Mux(s >= half, 1 << led, code)
        return code

    return Mux(
        ~found,
        0,
        Mux(
            centred,
            0b0001_1000,
            Mux(
                left > right, from_edge((0, 1, 2), (0, 1, 2, 3)), from_edge((7, 6, 5), (7, 6, 5, 4))
            ),
        ),
    )


class _FreeCounts(Harness):
    """``TrackerResults`` given free counts of one frame (``AnyConst``: every value at once)
    and one ``end`` at a free time. The counts are those a frame can have: each bin at most
    its columns times the window's rows, and ``SX`` at most ``(width - 1) * N``."""

    def __init__(self, dut=None, params=FULL_SIZES["160x120"]):
        super().__init__()
        self.dut = TrackerResults(params) if dut is None else dut

    def feed(self, m, dut, end):
        p = dut.params
        bins = [AnyConst(p.count_bits) for _ in range(8)]
        sum_x = AnyConst(p.sum_x_bits)
        count = _tree(bins)
        for b in bins:
            m.d.comb += Assume(b <= p.bin_width * p.window_height)
        m.d.comb += Assume(sum_x <= count * (p.width - 1))
        m.d.comb += [dut.counts.end.eq(end), dut.counts.sum_x.eq(sum_x)]
        m.d.comb += [dut.counts.bins[k].eq(bins[k]) for k in range(8)]
        return bins, sum_x, count

    def one_end(self, m):
        """``end`` in the first cycle only: the results of any counts from the reset state
        (the outputs depend on nothing but the counts sampled with ``end``; a bounded run of
        ``latency + 2`` cycles is then the whole story)."""
        end = Signal(init=1)
        m.d.sync += end.eq(0)
        return end


class ResultsFormulas(_FreeCounts):
    """Right after ``latency`` edges from ``end``: ``frame_done`` (at no other time) and the
    contract's ``found``, ``proximity`` and LED code (``which="counts"``), or ``centroid_x``,
    ``SX // N`` when found, else 0 (``which="centroid"``: a division, which the solver finds
    far harder, so it is a check of its own, at sizes it can reach)."""

    def __init__(self, which, dut=None, params=FULL_SIZES["160x120"]):
        super().__init__(dut, params)
        if which not in ("counts", "centroid"):
            raise ValueError("which must be 'counts' or 'centroid'")
        self.which = which

    def check(self, m):
        dut, p = self.dut, self.dut.params
        m.submodules.dut = dut
        end = self.one_end(m)
        bins, sum_x, count = self.feed(m, dut, end)
        # `end` on the input now shows right after the coming edge E; frame_done shows
        # right after edge E + latency: `latency` registers after this cycle.
        due = delayed(m, end, dut.latency)
        m.d.comb += Assert(dut.frame_done == due, "frame_done not latency edges after end")
        found = count >= p.min_pixels if p.found_rule == "ge" else count > p.min_pixels
        done = dut.frame_done
        if self.which == "centroid":
            q = dut.centroid_x
            with m.If(done):
                m.d.comb += Assert(
                    Mux(found, (q * count <= sum_x) & (sum_x < (q + 1) * count), q == 0),
                    "centroid_x is not SX // N (0 when not found)",
                )
            m.d.comb += [
                Cover(done & dut.found & (dut.centroid_x == p.margin_x)),
                Cover(done & dut.found & (dut.centroid_x == p.width - p.margin_x - 1)),
            ]
            return
        proximity = _tree([(count >= t).as_unsigned() for t in p.proximity_thresholds])
        with m.If(done):
            m.d.comb += [
                Assert(dut.found == found, "found is not N >= min_pixels"),
                Assert(dut.proximity == proximity, "proximity is not #thresholds <= N"),
                Assert(
                    dut.centroid_leds == contract_leds(p, bins, count, found),
                    "centroid_leds is not the contract's LED code",
                ),
            ]
        m.d.comb += [
            Cover(done & (dut.proximity == 7)),
            Cover(done & (dut.centroid_leds == 0b0001_1000)),
            *[Cover(done & (dut.centroid_leds == 1 << k)) for k in range(8)],
        ]


class ProximityMonotonic(_FreeCounts):
    """Two copies given free counts with ``N1 <= N2``, ending together: ``proximity`` of the
    first is never above the second's, and ``found`` of the first implies the second's."""

    def __init__(self, dut=None, twin=None, params=FULL_SIZES["160x120"]):
        super().__init__(dut, params)
        self.twin = type(self.dut)(self.dut.params) if twin is None else twin  # a copy

    def check(self, m):
        m.submodules.a = a = self.dut
        m.submodules.b = b = self.twin
        end = self.one_end(m)
        _, _, n1 = self.feed(m, a, end)
        _, _, n2 = self.feed(m, b, end)
        m.d.comb += Assume(n1 <= n2)
        with m.If(a.frame_done):
            m.d.comb += [
                Assert(a.proximity <= b.proximity, "proximity not monotonic in N"),
                Assert(~a.found | b.found, "found not monotonic in N"),
            ]
        m.d.comb += Cover(a.frame_done & (a.proximity < b.proximity))
