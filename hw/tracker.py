"""Per-frame target tracker: counts matching pixels in the window, in 8 bins, and their centroid.

Pipeline (one pixel per cycle at most, never stalls):

1. ``WindowCounter``: framing, window, bins and the counts ``h0..h7`` and ``SX`` in one
   register stage (see there for malformed framing: such a frame never ends, so it
   produces no ``frame_done`` and its counts are reloaded at the next ``first``);
2. at the end of a well-formed frame the divider (``SX // N``) starts, and every other
   result is computed into the divider's tag, which travels with the division, so the next
   frame can start accumulating on the very next cycle;
3. after the divider, all per-frame outputs load together with the one-cycle ``frame_done``.

Every stage is small and registered: the per-pixel path is one register stage, and the
per-frame arithmetic has a whole frame's worth of cycles to finish.

The per-pixel and per-frame halves are separate modules: they change at different rates (every
pixel, once a frame), and the per-frame half only reads the counts at a frame's end
(docs/hardware.md).
"""

from amaranth import Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .color_filter import match_stream_signature
from .divider import SequentialDivider
from .fit import load
from .params import FollowTargetParams
from .window_counter import WindowCounter, frame_counts_signature

__all__ = ["LEDS_CENTRED", "FrameTracker", "TrackerResults"]

#: ``centroid_leds`` when the target is centred: the two middle LEDs.
LEDS_CENTRED = 0b0001_1000


class FrameTracker(wiring.Component):
    """Target tracker of ``FollowTarget``: ``WindowCounter`` followed by ``TrackerResults``.

    Parameters
    ----------
    params : FollowTargetParams
        Geometry, margins, ``min_pixels`` and ``proximity_thresholds``.
    inspect : bool, optional
        Also output ``count``, ``bins`` and ``sum_x`` (default). ``FollowTarget`` leaves
        them out: three wide registers that nothing reads.

    Members
    -------
    matches : ``In(match_stream_signature())``
        Match bit and framing flags of every pixel (from ``ColorFilter``).
    frame_done : ``Out(1)``
        High for one cycle, the first cycle in which a frame's results show.
    found : ``Out(1)``
    proximity : ``Out(3)``
    centroid_x : ``Out(params.x_bits)``
    centroid_leds : ``Out(8)``
        Per-frame results, held until the next well-formed frame's ``frame_done``.
    count : ``Out(params.count_bits)``
    bins : ``Out(data.ArrayLayout(params.count_bits, 8))``
    sum_x : ``Out(params.sum_x_bits)``
        ``N``, ``h0..h7`` and ``SX`` of the last complete frame, for inspection (only with
        ``inspect``). They load ``params.x_bits + 2`` cycles before ``frame_done``
        and hold until the next frame's end.
    """

    def __init__(self, params, *, inspect=True):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        self.inspect = bool(inspect)
        self.counter = WindowCounter(params)
        self.results = TrackerResults(params, inspect=inspect)
        super().__init__(
            {
                "matches": In(match_stream_signature()),
                **_result_members(params, self.inspect),
            }
        )

    @property
    def latency(self):
        """Last pixel of a frame sampled on ``matches`` at edge P: ``frame_done`` and the
        results show right after edge P + ``latency``."""
        return self.counter.latency + self.results.latency

    def elaborate(self, platform):
        m = Module()
        m.submodules.counter = counter = self.counter
        m.submodules.results = results = self.results
        wiring.connect(m, wiring.flipped(self.matches), counter.matches)
        wiring.connect(m, counter.counts, results.counts)
        for name in _result_members(self.params, self.inspect):
            m.d.comb += getattr(self, name).eq(getattr(results, name))
        return m


def _result_members(p, inspect):
    members = {
        "frame_done": Out(1),
        "found": Out(1),
        "proximity": Out(3),
        "centroid_x": Out(p.x_bits),
        "centroid_leds": Out(8),
    }
    if inspect:
        members.update(
            {
                "count": Out(p.count_bits),
                "bins": Out(data.ArrayLayout(p.count_bits, 8)),
                "sum_x": Out(p.sum_x_bits),
            }
        )
    return members


class TrackerResults(wiring.Component):
    """Per-frame results from a frame's counts: divider, LED code, proximity.

    Everything is decided at ``counts.end``, so the next frame may start counting on the very
    next cycle: the divider starts from the counts, and ``found``, ``proximity`` and the LED
    code go into its tag (loaded with the start, held through the division). When the
    divider is done, every output loads at once with the one-cycle ``frame_done``.

    The per-frame arithmetic is written under the ``end`` condition, each use its own
    expression (``N``, the sum of the bins, too): it is read in that cycle only, and its
    results load registers with one enable each (docs/hardware.md).

    Parameters
    ----------
    params : FollowTargetParams
    inspect : bool, optional
        As in ``FrameTracker``.

    Members
    -------
    counts : ``In(frame_counts_signature(params))``
    frame_done, found, proximity, centroid_x, centroid_leds, count, bins, sum_x : ``Out``
        As in ``FrameTracker``.
    """

    def __init__(self, params, *, inspect=True):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        self.inspect = bool(inspect)
        super().__init__(
            {
                "counts": In(frame_counts_signature(params)),
                **_result_members(params, self.inspect),
            }
        )

    @property
    def latency(self):
        """``counts.end`` shows right after edge E: ``frame_done`` right after edge
        E + ``latency``: the divider's start at E + 1, its ``x_bits + 1`` steps, the output
        register."""
        return 3 + self.params.x_bits

    def elaborate(self, platform):
        m = Module()
        p = self.params
        counts = self.counts
        bins = [counts.bins[k] for k in range(8)]

        def frame_count():  # N, as a balanced tree: this is all computed in one clock cycle
            return _tree_sum(bins)

        # --- Divide, and everything else of the frame at its end -----------------------------
        # One quotient bit more than SX // N needs (it is always 0): the extra step is the one
        # cycle the outputs wait for, without a delay register of its own. The other results
        # (found, proximity, LED code) travel with the division as its tag: no register of
        # their own, and the next frame may start counting on the very next cycle.
        pending_layout = data.StructLayout({"found": 1, "proximity": 3, "leds": 8})
        m.submodules.divider = div = SequentialDivider(
            p.sum_x_bits, p.count_bits, p.x_bits + 1, tag_bits=pending_layout.size
        )

        def found():  # N >= min_pixels, or N > min_pixels (the published rule)
            if p.found_rule == "gt":
                return frame_count() > p.min_pixels
            return frame_count() >= p.min_pixels

        # The counts the halves and the 2- and 3-bin sums are taken from.
        groups = _Groups(
            bins, [counts.edges[k] for k in range(8)] if p.group_column_offset else None
        )
        m.d.comb += [
            div.start.eq(counts.end),
            div.dividend.eq(counts.sum_x),
            div.divisor.eq(frame_count()),
            load(
                data.View(pending_layout, div.tag_in),
                found=found(),
                proximity=sum(
                    (frame_count() >= t if t > 0 else Const(1, 1)) for t in p.proximity_thresholds
                ),
                leds=_led_code(m, groups, frame_count(), found()),
            ),
        ]
        pending = data.View(pending_layout, div.tag)
        with m.If(counts.end):
            if self.inspect:
                m.d.sync += [
                    self.count.eq(frame_count()),
                    self.sum_x.eq(counts.sum_x),
                    self.bins.eq(counts.bins),
                ]

        # --- Outputs, loaded together ----------------------------------------------------------
        # One register, loaded whole (see `fit`): `frame_done` drops after one cycle, the
        # results hold until the next frame's.
        outputs = Signal(
            data.StructLayout(
                {
                    "frame_done": 1,
                    "found": 1,
                    "proximity": 3,
                    "centroid_x": p.x_bits,
                    "centroid_leds": 8,
                }
            )
        )
        m.d.comb += [
            getattr(self, name).eq(getattr(outputs, name))
            for name in ("frame_done", "found", "proximity", "centroid_x", "centroid_leds")
        ]
        with m.If(div.done):
            m.d.sync += load(
                outputs,
                frame_done=1,
                found=pending.found,
                proximity=pending.proximity,
                centroid_x=Mux(pending.found, div.quotient[: p.x_bits], 0),
                centroid_leds=pending.leds,
            )
        with m.Else():
            m.d.sync += load(outputs, frame_done=0)
        return m


def _tree_sum(values):
    """Sum as a balanced tree of adders (a short logic path: log2(n) adders deep)."""
    values = list(values)
    while len(values) > 1:
        pairs = [a + b for a, b in zip(values[0::2], values[1::2])]
        values = pairs + values[len(pairs) * 2 :]
    return values[0]


class _Groups:
    """Sums of the counts the LED code compares: the halves and the 2- and 3-bin sums from
    the left and right edges.

    Without ``edges`` they are sums of the bins. With them (``group_column_offset = 1``) each
    bin's last column belongs to the next group and bin 7's to group 0: group k is
    ``h[k] - e[k] + e[k-1]``, so the groups of a run of bins ``a..b`` add up to the bins
    minus ``e[b]`` plus ``e[a-1]`` (``e[7]`` for ``a = 0``).
    """

    def __init__(self, bins, edges=None):
        self.bins, self.edges = bins, edges

    def _shifted(self, total, a, b):
        if self.edges is None:
            return total
        return total + self.edges[(a - 1) % 8] - self.edges[b]

    def half(self, a):
        """Groups ``a..a+3``: a balanced tree of the bins."""
        return self._shifted(_tree_sum(self.bins[a : a + 4]), a, a + 3)

    def from_edge(self, order):
        """Groups ``order[0]``, ``order[0..1]``, ``order[0..2]`` (bins from an edge inwards);
        the single outermost bin is a bin, not a group."""
        sums, acc = [self.bins[order[0]]], self.bins[order[0]]
        for n in (2, 3):
            acc = acc + self.bins[order[n - 1]]
            run = order[:n]
            sums.append(self._shifted(acc, min(run), max(run)))
        return sums


def _led_code(m, groups, count, found):
    """The contract's LED code (a comb signal) from the eight bins, the groups and ``N``."""
    left = groups.half(0)
    right = groups.half(4)
    half = count >> 1
    centred = Mux(left > right, left - right, right - left) < (count >> 4)
    leds = Signal(8)
    with m.If(~found):
        m.d.comb += leds.eq(0)
    with m.Elif(centred):
        m.d.comb += leds.eq(LEDS_CENTRED)
    with m.Elif(left > right):
        sums = groups.from_edge((0, 1, 2))
        m.d.comb += leds.eq(_edge_led(sums, half, leds_from_edge=(0, 1, 2, 3)))
    with m.Else():
        sums = groups.from_edge((7, 6, 5))
        m.d.comb += leds.eq(_edge_led(sums, half, leds_from_edge=(7, 6, 5, 4)))
    return leds


def _edge_led(sums_from_edge, half, leds_from_edge):
    """One-hot LED: the first of the three sums from the edge (one, two, three bins) that
    reaches ``half``, else the fourth LED (the one next to the centre)."""
    value = Const(1 << leds_from_edge[3], 8)
    # Build from the innermost choice outwards so the outermost bin has priority.
    for led, s in reversed(list(zip(leds_from_edge[:3], sums_from_edge))):
        value = Mux(s >= half, 1 << led, value)
    return value
