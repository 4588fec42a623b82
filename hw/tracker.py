"""Per-frame target tracker: counts matching pixels in the window, in 8 bins, and their centroid.

Pipeline (one pixel per cycle at most, never stalls):

1. framing: the position of each pixel from its ``first``/``last`` flags, geometry checks,
   window and bin membership (registered);
2. accumulate ``N``, ``h0..h7`` and ``SX`` (a ``first`` reloads them instead of adding);
3. at the end of a well-formed frame, snapshot the counts and start the divider, so the next
   frame can start accumulating on the very next cycle;
4. after the divider, all per-frame outputs load together with the one-cycle ``frame_done``.

Malformed framing: a frame is abandoned (no ``frame_done``, counts discarded) as soon as a line
ends early (``last`` before column ``width - 1``) or runs long (no ``last`` at column
``width - 1``). A frame ends at the ``last`` of line ``height - 1``; pixels after that, and
pixels before the first ``first`` after reset or after an abandoned frame, are ignored until
the next ``first``. A ``first`` always restarts the frame. A frame with too few lines never
reaches its end, so it produces nothing and is discarded by the next ``first``.
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .color_filter import MatchStream
from .divider import SequentialDivider
from .params import FollowTargetParams

__all__ = ["LEDS_CENTRED", "FrameTracker"]

#: ``centroid_leds`` when the target is centred: the two middle LEDs.
LEDS_CENTRED = 0b0001_1000

#: Cycles of stages 1-3 above, from a pixel sampled on ``matches`` to the divider's start edge.
_STAGES_BEFORE_DIVIDER = 2


class FrameTracker(wiring.Component):
    """Target tracker of ``FollowTarget``.

    Parameters
    ----------
    params : FollowTargetParams
        Geometry, margins, ``min_pixels`` and ``proximity_thresholds``.

    Members
    -------
    matches : ``In(MatchStream())``
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
        ``N``, ``h0..h7`` and ``SX`` of the last complete frame, for inspection. They load
        ``params.divider_cycles + 1`` cycles before ``frame_done`` and hold until the next
        frame's end.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        p = params
        super().__init__({
            "matches": In(MatchStream()),
            "frame_done": Out(1),
            "found": Out(1),
            "proximity": Out(3),
            "centroid_x": Out(p.x_bits),
            "centroid_leds": Out(8),
            "count": Out(p.count_bits),
            "bins": Out(data.ArrayLayout(p.count_bits, 8)),
            "sum_x": Out(p.sum_x_bits),
        })

    @property
    def latency(self):
        """Last pixel of a frame sampled on ``matches`` at edge P: ``frame_done`` and the
        results show right after edge P + ``latency``."""
        return _STAGES_BEFORE_DIVIDER + 1 + self.params.divider_cycles

    def elaborate(self, platform):
        m = Module()
        p = self.params
        W, H = p.width, p.height
        mx, my, bw = p.margin_x, p.margin_y, p.bin_width

        # --- Stage 1: framing and window -----------------------------------------------------
        valid = self.matches.valid
        first = self.matches.payload.first
        last = self.matches.payload.last

        x = Signal(p.x_bits)  # position of the next pixel of the frame in progress
        y = Signal(p.y_bits)
        active = Signal()  # a well-formed frame is in progress
        px = Mux(first, 0, x)
        py = Mux(first, 0, y)
        in_frame = valid & (first | active)
        line_end = px == W - 1
        shape_ok = line_end == last  # neither a short nor a long line
        frame_end = in_frame & shape_ok & last & (py == H - 1)

        with m.If(in_frame):
            with m.If(~shape_ok):
                m.d.sync += active.eq(0)  # abandon the frame until the next `first`
            with m.Elif(last):
                m.d.sync += [x.eq(0), y.eq(py + 1), active.eq(py != H - 1)]
            with m.Else():
                m.d.sync += [x.eq(px + 1), y.eq(py), active.eq(1)]

        in_rows = (py >= my) & (py < H - my)
        in_bin = Cat(
            (px >= mx + k * bw) & (px < mx + (k + 1) * bw) for k in range(8)
        )
        a_restart = Signal()  # this pixel starts a frame: reload the counts
        a_count = Signal()  # this pixel counts
        a_bin = Signal(8)  # one-hot bin of a counted pixel
        a_x = Signal(p.x_bits)
        a_end = Signal()  # last pixel of a well-formed frame
        m.d.sync += [
            a_restart.eq(valid & first),
            a_count.eq(in_frame & shape_ok & self.matches.payload.match & in_rows
                       & in_bin.any()),
            a_end.eq(frame_end),
        ]
        with m.If(valid):
            m.d.sync += [a_bin.eq(in_bin), a_x.eq(px)]

        # --- Stage 2: accumulate -------------------------------------------------------------
        n = Signal(p.count_bits)
        h = [Signal(p.count_bits, name=f"h{k}") for k in range(8)]
        sx = Signal(p.sum_x_bits)
        b_end = Signal()
        m.d.sync += b_end.eq(a_end)
        with m.If(a_restart):
            m.d.sync += [
                n.eq(a_count),
                sx.eq(Mux(a_count, a_x, 0)),
                *(h[k].eq(a_count & a_bin[k]) for k in range(8)),
            ]
        with m.Elif(a_count):
            m.d.sync += [n.eq(n + 1), sx.eq(sx + a_x)]
            for k in range(8):
                with m.If(a_bin[k]):
                    m.d.sync += h[k].eq(h[k] + 1)

        # --- Stage 3: snapshot and divide ----------------------------------------------------
        m.submodules.divider = div = SequentialDivider(p.sum_x_bits, p.count_bits, p.x_bits)
        m.d.comb += [div.start.eq(b_end), div.dividend.eq(sx), div.divisor.eq(n)]
        with m.If(b_end):
            m.d.sync += [
                self.count.eq(n),
                self.sum_x.eq(sx),
                *(self.bins[k].eq(h[k]) for k in range(8)),
            ]

        # --- Stage 4: results from the snapshot, loaded when the divider is done ------------
        count = self.count
        bins = [self.bins[k] for k in range(8)]
        found = count >= p.min_pixels
        proximity = sum(
            (count >= t if t > 0 else Const(1, 1)) for t in p.proximity_thresholds
        )
        left = bins[0] + bins[1] + bins[2] + bins[3]
        right = bins[4] + bins[5] + bins[6] + bins[7]
        half = count >> 1
        centred = Mux(left > right, left - right, right - left) < (count >> 4)
        leds = Signal(8)
        with m.If(~found):
            m.d.comb += leds.eq(0)
        with m.Elif(centred):
            m.d.comb += leds.eq(LEDS_CENTRED)
        with m.Elif(left > right):
            m.d.comb += leds.eq(_edge_led(bins[0:3], half, leds_from_edge=(0, 1, 2, 3)))
        with m.Else():
            m.d.comb += leds.eq(_edge_led(bins[7:4:-1], half, leds_from_edge=(7, 6, 5, 4)))

        m.d.sync += self.frame_done.eq(div.done)
        with m.If(div.done):
            m.d.sync += [
                self.found.eq(found),
                self.proximity.eq(proximity),
                self.centroid_x.eq(Mux(found, div.quotient, 0)),
                self.centroid_leds.eq(leds),
            ]
        return m


def _edge_led(bins_from_edge, half, leds_from_edge):
    """One-hot LED: the first of the three bins from the edge whose running sum reaches
    ``half``, else the fourth LED (the one next to the centre)."""
    value = Const(1 << leds_from_edge[3], 8)
    acc = None
    sums = []
    for b in bins_from_edge:
        acc = b if acc is None else acc + b
        sums.append(acc)
    # Build from the innermost choice outwards so the outermost bin has priority.
    for led, s in reversed(list(zip(leds_from_edge[:3], sums))):
        value = Mux(s >= half, 1 << led, value)
    return value
