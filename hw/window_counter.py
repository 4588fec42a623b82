"""Per-pixel half of the target tracker: framing, window, and the running counts of a frame."""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .color_filter import match_stream_signature
from .fit import fit
from .params import FollowTargetParams

__all__ = ["WindowCounter", "frame_counts_signature"]


def edge_bits(params):
    """Bits of a bin's last-column count: at most one pixel a window row."""
    return max(1, params.window_height.bit_length())


def frame_counts_signature(params):
    """Signature of a frame's counts (source side): ``end`` is a one-cycle strobe when
    ``bins`` (``h0..h7``) and ``sum_x`` (``SX``) are those of a complete, well-formed frame.
    ``N`` is the sum of the bins (every window column is in exactly one bin).

    With ``group_column_offset = 1`` also ``edges``: the matches in the last column of each
    bin, from which the tracker moves each bin's last column into the next group."""
    members = {
        "end": Out(1),
        "bins": Out(data.ArrayLayout(params.count_bits, 8)),
        "sum_x": Out(params.sum_x_bits),
    }
    if params.group_column_offset:
        members["edges"] = Out(data.ArrayLayout(edge_bits(params), 8))
    return wiring.Signature(members)


class WindowCounter(wiring.Component):
    """Counts the matching pixels of each frame inside the window, per bin, and their columns.

    One register stage, one pixel per cycle at most, never stalls: the position of each
    pixel from its ``first``/``last`` flags, the geometry checks, and the counts ``h0..h7``
    and ``SX``; a ``first`` reloads the counts instead of adding, so nothing of an earlier
    (complete, abandoned or cut short) frame leaks into a frame.

    Little logic per pixel: one equality of the column with the next bin boundary (a
    register, not eight pairs of constant comparisons), one add into a per-bin
    accumulator and one add into ``SX``. The accumulator is added into a bin only at
    the bin's last column; the bins then rotate by one place, so the bin being filled is
    always the first and after the eight bins of a line they are back in order. Whether the
    row is inside the window is a register updated at line ends. With
    ``group_column_offset = 1`` the last column of each bin is also counted on its own
    (``edges``, rotating with the bins).

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
    matches : ``In(match_stream_signature())``
    counts : ``Out(frame_counts_signature(params))``
        The counts. ``counts.end`` shows right after edge P + ``latency`` when the frame's
        last pixel was sampled at edge P; the counts are only meaningful while ``end`` is high
        (in between, the bins are rotated and the current bin's count is still in the
        accumulator), and may change from the next edge on (a next frame's ``first``).
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        super().__init__(
            {
                "matches": In(match_stream_signature()),
                "counts": Out(frame_counts_signature(params)),
            }
        )

    @property
    def latency(self):
        """The frame's last pixel sampled on ``matches`` at edge P: ``counts.end`` and the
        final counts show right after edge P + 0 (the same edge)."""
        return 0

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

        def in_window_columns(x):
            # mx <= x <= last_boundary without an ordered comparison, on every pixel: with a
            # power-of-two window width ww, x - mx (wrapping below 0) has no bit at or above
            # log2(ww) set, an OR of the high bits; otherwise the borrow bits of two
            # subtractions.
            ww = last_boundary - mx + 1
            if ww & (ww - 1) == 0:
                return ~(x - mx)[ww.bit_length() - 1 :].any()
            below = (x - mx)[-1] if mx > 0 else Const(0, 1)
            return ~below & ~(last_boundary - x)[-1]

        def rows_window(y):  # is row y inside margin_y (only at line starts)
            return at_least(y, my) & (y < H - my)

        valid = self.matches.valid
        first = self.matches.payload.first
        last = self.matches.payload.last

        # Registers without a reset where the value does not matter until the next `first`
        # reloads it (no reset logic for a value nobody reads); the framing position, which
        # always loads whole, is one register (see `fit`).
        active = Signal()  # a well-formed frame is in progress
        # Framing state for the next pixel of the frame in progress: column, row, and
        # whether the row is inside margin_y.
        position = Signal(p.x_bits + p.y_bits + 1, reset_less=True)
        x, y = position[: p.x_bits], position[p.x_bits : -1]
        row_in = position[-1]
        # Counts: the bins (rotated during a line) and SX; the current bin's accumulator (the
        # matches so far in this bin and line) and the next bin boundary (the last column of a
        # bin). Two plain registers, each with its own add (docs/hardware.md).
        cb = p.count_bits
        bins = Signal(8 * cb, reset_less=True)
        sx = Signal(p.sum_x_bits, reset_less=True)
        acc = Signal(range(bw + 1), reset_less=True)
        boundary = Signal(p.x_bits, reset_less=True)
        end = Signal()  # the last pixel of a well-formed frame was just counted
        m.d.comb += [
            self.counts.bins.eq(bins),
            self.counts.sum_x.eq(sx),
            self.counts.end.eq(end),
        ]
        edges = None
        if p.group_column_offset:  # nothing of this at the default
            eb = edge_bits(p)
            edges = Signal(8 * eb, reset_less=True)
            m.d.comb += self.counts.edges.eq(edges)

        # Named signals, not expressions: each is one net, shared by every use.
        px = Signal(p.x_bits)  # position of the pixel on the input now
        py = Mux(first, 0, y)  # an expression: only the rare line-end branch reads it
        row = Signal()  # row py is inside margin_y
        in_frame = Signal()  # the pixel belongs to a frame in progress
        shape_ok = Signal()  # neither a short nor a long line
        reload = Signal()  # a `first`: reload the counts
        advance = Signal()  # any other pixel of a frame in progress, line shape fine
        count = Signal()  # the pixel matches and is inside the window
        m.d.comb += [
            px.eq(Mux(first, 0, x)),
            row.eq(Mux(first, int(my == 0), row_in)),
            in_frame.eq(valid & (first | active)),
            shape_ok.eq((px == W - 1) == last),
            reload.eq(valid & first),
            advance.eq(valid & active & ~first & shape_ok),
            count.eq(self.matches.payload.match & row & in_window_columns(px)),
        ]

        m.d.sync += end.eq(0)
        with m.If(in_frame):
            with m.If(~shape_ok):
                m.d.sync += active.eq(0)  # abandon the frame until the next `first`
            with m.Elif(last):
                m.d.sync += [
                    position.eq(
                        Cat(Const(0, p.x_bits), fit(py + 1, p.y_bits), rows_window(py + 1))
                    ),
                    active.eq(py != H - 1),
                    end.eq(py == H - 1),
                ]
            with m.Else():
                # The next column: one add (the column never carries into the row here), or
                # column 1 of row 0 after a `first`.
                first_position = Cat(Const(1, p.x_bits), Const(0, p.y_bits), Const(int(my == 0), 1))
                m.d.sync += [
                    position.eq(Mux(first, first_position, position + 1)),
                    active.eq(1),
                ]

        with m.If(reload):
            # A `first` is column 0: never a bin's last column, and adds 0 to SX.
            m.d.sync += [
                bins.eq(0),
                sx.eq(0),
                acc.eq(count & shape_ok),
                boundary.eq(first_boundary),
            ]
            if edges is not None:
                m.d.sync += edges.eq(0)
        with m.Elif(advance):
            with m.If(count):  # SX grows by the column only for a counted pixel
                m.d.sync += sx.eq(sx + px)
            with m.If(px == boundary):
                # After bin 7 the next boundary is bin 0's of the next line.
                next_boundary = Mux(boundary == last_boundary, first_boundary, boundary + bw)
                m.d.sync += [
                    bins.eq(Cat(bins[cb:], fit(bins[:cb] + acc + count, cb))),
                    acc.eq(0),
                    boundary.eq(next_boundary),
                ]
                if edges is not None:
                    m.d.sync += edges.eq(Cat(edges[eb:], fit(edges[:eb] + count, eb)))
            with m.Else():
                m.d.sync += acc.eq(acc + count)
        return m
