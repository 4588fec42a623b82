"""The colour filter's promises: it keeps exactly the pixels the contract's colour table
matches (for every pixel and every ``color_sel``, by proof rather than enumeration), blacks
out the others, and passes every transfer on one cycle later with its ``first``/``last``
flags: same transfers, same order, nothing added or dropped."""

from amaranth.asserts import AnySeq
from amaranth.hdl import Assert, Cover, Mux, Signal, signed

from ..color_filter import ColorFilter
from ..pixel import TargetColor
from .harness import Harness, delayed
from .sizes import FULL_SIZES

__all__ = ["ColorFilterHarness", "contract_match"]


def contract_match(m, p, r, g, b, color_sel):
    """The contract's colour table (docs/contract.md, Colour filter) for channels ``r``,
    ``g``, ``b``: plain signed integers (6 bits: differences of 4-bit values cannot wrap)."""
    sr, sg, sb = (Signal(signed(6), name=f"contract_{n}") for n in "rgb")
    m.d.comb += [sr.eq(r), sg.eq(g), sb.eq(b)]

    def mx(x, y):
        return Mux(x > y, x, y)

    def mn(x, y):
        return Mux(x < y, x, y)

    def absdiff(x, y):
        return Mux(x > y, x - y, y - x)

    d, sim, wm = p.diff_min, p.similar_max, p.white_min
    table = {
        TargetColor.NONE: 1,
        TargetColor.RED: sr - mx(sg, sb) >= d,
        TargetColor.GREEN: sg - mx(sr, sb) >= d,
        TargetColor.BLUE: sb - mx(sr, sg) >= d,
        TargetColor.YELLOW: (absdiff(sr, sg) <= sim) & (mn(sr, sg) - sb >= d),
        TargetColor.MAGENTA: (absdiff(sr, sb) <= sim) & (mn(sr, sb) - sg >= d),
        TargetColor.CYAN: (absdiff(sg, sb) <= sim) & (mn(sg, sb) - sr >= d),
        TargetColor.WHITE: (
            (mx(sr, mx(sg, sb)) - mn(sr, mn(sg, sb)) <= sim) & (mn(sr, mn(sg, sb)) >= wm)
        ),
    }
    result = 0
    for color, test in table.items():
        result = Mux(color_sel == color.value, test, result)
    return result


class ColorFilterHarness(Harness):
    """``ColorFilter`` with a free pixel, flags, ``valid`` and ``color_sel`` every cycle."""

    def __init__(self, dut=None, params=FULL_SIZES["160x120"]):
        super().__init__()
        self.dut = ColorFilter(params) if dut is None else dut

    def check(self, m):
        dut, p = self.dut, self.dut.params
        m.submodules.dut = dut
        width = len(dut.pixels.payload.as_value())
        valid, payload, color_sel = AnySeq(1), AnySeq(width), AnySeq(3)
        m.d.comb += [
            dut.pixels.valid.eq(valid),
            dut.pixels.payload.eq(payload),
            dut.color_sel.eq(color_sel),
        ]
        pix = dut.pixels.payload
        match = contract_match(m, p, pix.pixel.r, pix.pixel.g, pix.pixel.b, color_sel)
        expected = Signal.like(dut.pixels.payload)
        m.d.comb += [expected.eq(pix), expected.pixel.eq(Mux(match, pix.pixel, 0))]
        # The transfer on the input now is the one on the outputs after the next edge.
        was_valid = delayed(m, valid, 1)
        was = delayed(m, expected.as_value(), 1)
        was_match = delayed(m, match, 1)
        m.d.comb += Assert(dut.filtered.valid == was_valid, "filtered.valid is not valid")
        m.d.comb += Assert(dut.matches.valid == was_valid, "matches.valid is not valid")
        with m.If(was_valid):
            out = dut.filtered.payload
            m.d.comb += [
                Assert(out.as_value() == was, "filtered pixel or flags differ from the table"),
                Assert(dut.matches.payload.match == was_match, "match bit differs"),
                Assert(
                    (dut.matches.payload.first == out.first)
                    & (dut.matches.payload.last == out.last),
                    "match flags differ",
                ),
            ]
        m.d.comb += [
            Cover(
                dut.filtered.valid
                & dut.matches.payload.match
                & (delayed(m, color_sel, 1) == color.value)
            )
            for color in TargetColor
        ]
