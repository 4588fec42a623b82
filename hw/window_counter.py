"""Per-pixel half of the target tracker: framing, window, and the running counts of a frame."""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .color_filter import MatchStream
from .params import FollowTargetParams

__all__ = ["FrameCounts", "WindowCounter"]


def FrameCounts(params):
    """Signature of a frame's running counts (source side): ``end`` is a one-cycle strobe
    when ``count`` (``N``), ``bins`` (``h0..h7``) and ``sum_x`` (``SX``) are those of a
    complete, well-formed frame."""
    return wiring.Signature({
        "end": Out(1),
        "count": Out(params.count_bits),
        "bins": Out(data.ArrayLayout(params.count_bits, 8)),
        "sum_x": Out(params.sum_x_bits),
    })


class WindowCounter(wiring.Component):
    """Counts the matching pixels of each frame inside the window, per bin, and their columns.

    Two register stages, one pixel per cycle at most, never stalls:

    1. framing: the position of each pixel from its ``first``/``last`` flags, the geometry
       checks, window and bin membership;
    2. accumulate ``N``, ``h0..h7`` and ``SX``; a ``first`` reloads them instead of adding,
       so nothing of an earlier (complete, abandoned or cut short) frame leaks into a frame.

    Malformed framing: a frame is abandoned (no ``end``) as soon as a line ends early
    (``last`` before column ``width - 1``) or runs long (no ``last`` at column
    ``width - 1``). A frame ends at the ``last`` of line ``height - 1``; pixels after that, and
    pixels before the first ``first`` (after reset or after an abandoned frame), are ignored
    until the next ``first``. A frame with too few lines never ends.

    Parameters
    ----------
    params : FollowTargetParams

    Members
    -------
    matches : ``In(MatchStream())``
    counts : ``Out(FrameCounts(params))``
        The running counts. ``counts.end`` shows right after edge P + ``latency`` when the
        frame's last pixel was sampled at edge P; the counts change again from the next
        frame's first counted pixel on.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        super().__init__({
            "matches": In(MatchStream()),
            "counts": Out(FrameCounts(params)),
        })

    @property
    def latency(self):
        """The frame's last pixel sampled on ``matches`` at edge P (by the first stage):
        ``counts.end`` and the final counts show right after edge P + 1 (the second)."""
        return 1

    def elaborate(self, platform):
        m = Module()
        p = self.params
        W, H = p.width, p.height
        mx, my, bw = p.margin_x, p.margin_y, p.bin_width

        # --- Stage 1: framing and window -------------------------------------------------
        valid = self.matches.valid
        first = self.matches.payload.first
        last = self.matches.payload.last

        x = Signal(p.x_bits)  # position of the next pixel of the frame in progress
        y = Signal(p.y_bits)
        active = Signal()  # a well-formed frame is in progress
        px = Signal(p.x_bits)  # position of the pixel on the input now
        py = Signal(p.y_bits)
        m.d.comb += [px.eq(Mux(first, 0, x)), py.eq(Mux(first, 0, y))]
        in_frame = valid & (first | active)
        shape_ok = (px == W - 1) == last  # neither a short nor a long line

        with m.If(in_frame):
            with m.If(~shape_ok):
                m.d.sync += active.eq(0)  # abandon the frame until the next `first`
            with m.Elif(last):
                m.d.sync += [x.eq(0), y.eq(py + 1), active.eq(py != H - 1)]
            with m.Else():
                m.d.sync += [x.eq(px + 1), y.eq(py), active.eq(1)]

        a_restart = Signal()  # this pixel starts a frame: reload the counts
        a_count = Signal()  # this pixel counts
        a_bin = Signal(8)  # one-hot bin of a counted pixel
        a_x = Signal(p.x_bits)
        a_end = Signal()  # last pixel of a well-formed frame
        m.d.sync += [a_restart.eq(0), a_count.eq(0), a_end.eq(0)]
        with m.If(valid):
            in_bin = Cat((px >= mx + k * bw) & (px < mx + (k + 1) * bw) for k in range(8))
            in_rows = (py >= my) & (py < H - my)
            counted = in_frame & shape_ok
            m.d.sync += [
                a_restart.eq(first),
                a_count.eq(counted & self.matches.payload.match & in_rows & in_bin.any()),
                a_end.eq(counted & last & (py == H - 1)),
                a_bin.eq(in_bin),
                a_x.eq(px),
            ]

        # --- Stage 2: accumulate ---------------------------------------------------------
        counts = self.counts
        n, sx = counts.count, counts.sum_x
        h = [counts.bins[k] for k in range(8)]
        m.d.sync += counts.end.eq(a_end)
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
        return m
