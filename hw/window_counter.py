"""Per-pixel half of the target tracker: framing, window, and the running counts of a frame."""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .color_filter import MatchStream
from .params import FollowTargetParams

__all__ = ["FrameCounts", "WindowCounter"]


def FrameCounts(params):
    """Signature of a frame's counts (source side): ``end`` is a one-cycle strobe when
    ``bins`` (``h0..h7``) and ``sum_x`` (``SX``) are those of a complete, well-formed frame.
    ``N`` is the sum of the bins (every window column is in exactly one bin)."""
    return wiring.Signature({
        "end": Out(1),
        "bins": Out(data.ArrayLayout(params.count_bits, 8)),
        "sum_x": Out(params.sum_x_bits),
    })


class WindowCounter(wiring.Component):
    """Counts the matching pixels of each frame inside the window, per bin, and their columns.

    Two register stages, one pixel per cycle at most, never stalls:

    1. framing: the position of each pixel from its ``first``/``last`` flags, the geometry
       checks, window membership and the bin boundaries;
    2. accumulate ``h0..h7`` and ``SX``; a ``first`` reloads them instead of adding,
       so nothing of an earlier (complete, abandoned or cut short) frame leaks into a frame.

    Built for simulation speed (the compiled simulators evaluate all of it every clock):
    per pixel there is one comparison of the column with the next bin boundary (a register,
    not eight pairs of constants), one add into a per-bin accumulator and one masked add
    into ``SX``. The accumulator is added into a bin only at the bin's last column; the
    bins then rotate by one place, so the bin being filled is always the first and after
    the eight bins of a line they are back in order. The row's window membership is a
    register updated at line ends.

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
        The counts. ``counts.end`` shows right after edge P + ``latency`` when the frame's
        last pixel was sampled at edge P; the counts are only meaningful while ``end`` is high
        (in between, the bins are rotated and the current bin's count is still in the
        accumulator).
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
        first_boundary = mx + bw - 1  # last column of bin 0
        last_boundary = W - mx - 1  # last column of bin 7
        # Column 0 (a `first`) is never a bin's last column (width >= 16 makes bw >= 2 when
        # margin_x is 0), so a reload never has to add into a bin at the same time.
        assert first_boundary > 0

        def at_least(v, low):  # no constant-true comparison in the Verilog (lint)
            return v >= low if low > 0 else Const(1, 1)

        def rows_window(y):  # is row y inside margin_y (only at line starts)
            return at_least(y, my) & (y < H - my)

        # --- Stage 1: framing and window -------------------------------------------------
        valid = self.matches.valid
        first = self.matches.payload.first
        last = self.matches.payload.last

        x = Signal(p.x_bits)  # position of the next pixel of the frame in progress
        y = Signal(p.y_bits)
        row_in = Signal()  # row y is inside margin_y
        boundary = Signal(p.x_bits, init=first_boundary)  # next bin's last column in row y
        active = Signal()  # a well-formed frame is in progress
        px = Signal(p.x_bits)  # position of the pixel on the input now
        py = Signal(p.y_bits)
        m.d.comb += [px.eq(Mux(first, 0, x)), py.eq(Mux(first, 0, y))]
        row = Mux(first, int(my == 0), row_in)
        in_frame = valid & (first | active)
        shape_ok = (px == W - 1) == last  # neither a short nor a long line
        at_boundary = px == boundary  # never at a `first` (column 0)

        with m.If(in_frame):
            with m.If(~shape_ok):
                m.d.sync += active.eq(0)  # abandon the frame until the next `first`
            with m.Elif(last):
                m.d.sync += [
                    x.eq(0), y.eq(py + 1), active.eq(py != H - 1),
                    row_in.eq(rows_window(py + 1)),
                ]
            with m.Else():
                m.d.sync += [x.eq(px + 1), y.eq(py), active.eq(1), row_in.eq(row)]
            with m.If(first):
                m.d.sync += boundary.eq(first_boundary)
            with m.Elif(at_boundary):
                # After bin 7 the next boundary is bin 0's of the next line.
                m.d.sync += boundary.eq(
                    Mux(boundary == last_boundary, first_boundary, boundary + bw))

        a_restart = Signal()  # this pixel starts a frame: reload the counts
        a_count = Signal()  # this pixel counts
        a_flush = Signal()  # this pixel is the last column of a bin
        a_x = Signal(p.x_bits)
        a_end = Signal()  # last pixel of a well-formed frame
        m.d.sync += [a_restart.eq(0), a_count.eq(0), a_flush.eq(0), a_end.eq(0)]
        with m.If(valid):
            counted = in_frame & shape_ok
            in_cols = at_least(px, mx) & (px <= last_boundary)
            m.d.sync += [
                a_restart.eq(first),
                a_count.eq(counted & self.matches.payload.match & row & in_cols),
                a_flush.eq(counted & at_boundary),
                a_end.eq(counted & last & (py == H - 1)),
                a_x.eq(px),
            ]

        # --- Stage 2: accumulate ---------------------------------------------------------
        counts = self.counts
        cb = p.count_bits
        bins, sx = counts.bins.as_value(), counts.sum_x
        acc = Signal(range(bw + 1))  # matching pixels so far in the current bin and line
        m.d.sync += counts.end.eq(a_end)
        with m.If(a_restart):
            m.d.sync += [bins.eq(0), acc.eq(a_count), sx.eq(0)]  # a `first` is at column 0
        with m.Else():
            # A masked add rather than a conditional one: no branch on the pixel data.
            m.d.sync += sx.eq(sx + (a_x & a_count.replicate(p.x_bits)))
            with m.If(a_flush):
                m.d.sync += [
                    bins.eq(Cat(bins[cb:], (bins[:cb] + acc + a_count)[:cb])),
                    acc.eq(0),
                ]
            with m.Else():
                m.d.sync += acc.eq(acc + a_count)
        return m
