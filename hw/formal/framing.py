"""The contract's framing rules as a monitor: which pixel ends a well-formed frame.

Written from docs/contract.md ("Pixel stream and framing"), not from the window counter: a
``first`` is column 0 of line 0; each further pixel is the next column; the pixel after a
``last`` is column 0 of the next line. A frame is abandoned by a ``last`` anywhere but
column ``width - 1`` or a pixel in that column without ``last``; it ends well-formed at the
``last`` of line ``height - 1``. Pixels outside a frame in progress are ignored.
"""

from amaranth.hdl import Module, Mux, Signal

__all__ = ["FramingMonitor"]


class FramingMonitor:
    """Add the monitor of ``valid``/``first``/``last`` to ``m``.

    Attributes
    ----------
    ends : Signal
        The pixel now on the input ends a well-formed frame (combinational).
    column, row : Signal
        Position of the pixel now on the input, while ``in_frame``.
    in_frame : Signal
        The pixel now on the input belongs to a frame in progress.
    """

    def __init__(self, m: Module, width, height, valid, first, last):
        active = Signal()  # a frame is in progress
        next_x = Signal(range(width))
        next_y = Signal(range(height))
        self.column = column = Signal(range(width))
        self.row = row = Signal(range(height))
        self.in_frame = in_frame = Signal()
        self.ends = ends = Signal()
        m.d.comb += [
            column.eq(Mux(first, 0, next_x)),
            row.eq(Mux(first, 0, next_y)),
            in_frame.eq(valid & (first | active)),
        ]
        line_ok = (column == width - 1) == last
        m.d.comb += ends.eq(in_frame & line_ok & last & (row == height - 1))
        with m.If(in_frame):
            with m.If(~line_ok | ends):
                m.d.sync += active.eq(0)
            with m.Elif(last):
                m.d.sync += [active.eq(1), next_x.eq(0), next_y.eq(row + 1)]
            with m.Else():
                m.d.sync += [active.eq(1), next_x.eq(column + 1), next_y.eq(row)]
