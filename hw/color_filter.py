"""Per-pixel colour filter: keeps the pixels of the selected colour, blacks out the others."""

from amaranth import Cat, Const, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from .fit import load
from .params import FollowTargetParams
from .pixel import TargetColor, pixel_stream_signature

__all__ = ["ColorFilter", "MatchFlags", "color_match_value", "match_stream_signature"]

#: What the tracker needs of each filtered pixel: the framing flags and the match bit (in the
#: order they sit in the filter's output register, right after the pixel).
MatchFlags = data.StructLayout({"first": 1, "last": 1, "match": 1})


def match_stream_signature():
    """Signature of the per-pixel match stream from the filter to the tracker."""
    return stream.Signature(MatchFlags, always_ready=True)


def color_match_value(m, pixel, color_sel, params):
    """Return a 1-bit signal: does RGB444 ``pixel`` match ``color_sel`` (the colour table of
    docs/contract.md)?

    Every row of the table is written as an AND of differences compared with constants:
    ``a - max(b, c) >= D`` is ``a - b >= D and a - c >= D``; ``abs(a - b) <= S`` is
    ``a - b >= -S and b - a >= -S``; ``max - min <= S`` is every pair within ``S``. Each
    ``a - c >= k`` is the sign bit of the signed ``a - c - k`` (6 bits, cannot overflow for
    4-bit channels and ``|k| <= 15``), which is the contract's signed-difference rule
    exactly. No multiplexer depends on the pixel data: each test is a short carry chain and
    the colour select picks one AND of them (why this form and not max/min multiplexers or
    ``>=`` comparisons: docs/hardware.md).
    """
    r, g, b = pixel.r, pixel.g, pixel.b
    d, s, wm = params.diff_min, params.similar_max, params.white_min

    def at_least(a, c, k):  # a - c >= k: the sign bit of the signed difference a - c - k
        # One subtraction of zero-extended sums: no sign extension, one carry chain.
        return ~(a - (c + k))[-1] if k >= 0 else ~((a + -k) - c)[-1]

    def dominates(a, c):  # a - c >= D
        return at_least(a, c, d)

    def similar(a, c):  # abs(a - c) <= S
        return at_least(a, c, -s) & at_least(c, a, -s)

    def bright(a):  # a >= white_min
        return at_least(a, Const(0, 4), wm)

    by_color = {
        TargetColor.NONE: Const(1, 1),  # every pixel
        TargetColor.RED: dominates(r, g) & dominates(r, b),  # r - max(g, b) >= D
        TargetColor.GREEN: dominates(g, r) & dominates(g, b),
        TargetColor.BLUE: dominates(b, r) & dominates(b, g),
        TargetColor.YELLOW: similar(r, g) & dominates(r, b) & dominates(g, b),  # min(r, g) - b >= D
        TargetColor.MAGENTA: similar(r, b) & dominates(r, g) & dominates(b, g),
        TargetColor.CYAN: similar(g, b) & dominates(g, r) & dominates(b, r),
        # max - min <= S and min >= white_min
        TargetColor.WHITE: (
            similar(r, g) & similar(r, b) & similar(g, b) & bright(r) & bright(g) & bright(b)
        ),
    }
    # A plain case statement on the colour select: one row of the table per colour.
    match = Signal()
    with m.Switch(color_sel):
        for color, test in by_color.items():
            with m.Case(color):
                m.d.comb += match.eq(test)
    return match


class ColorFilter(wiring.Component):
    """Colour filter of ``FollowTarget``: one register stage after the colour comparison.

    Every input pixel leaves on ``filtered`` with the same ``first``/``last`` flags: the pixel
    itself where it matches the colour chosen by ``color_sel``, black (0) where it does not.
    ``matches`` carries the same transfers with the match bit, for the tracker.

    Parameters
    ----------
    params : FollowTargetParams
        Uses ``diff_min``, ``similar_max`` and ``white_min``.

    Members
    -------
    pixels : ``In(pixel_stream_signature())``
        Camera pixels (cannot be stalled).
    color_sel : ``In(TargetColor)``
        Colour select, sampled with each pixel: bit 2 red, bit 1 green, bit 0 blue.
    filtered : ``Out(pixel_stream_signature())``
        Filtered pixels, ``latency`` cycles after the input.
    matches : ``Out(match_stream_signature())``
        Match bit and framing flags, aligned with ``filtered``.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        super().__init__(
            {
                "pixels": In(pixel_stream_signature()),
                "color_sel": In(TargetColor),
                "filtered": Out(pixel_stream_signature()),
                "matches": Out(match_stream_signature()),
            }
        )

    @property
    def latency(self):
        """A pixel sampled at edge k is sampled on ``filtered``/``matches`` at edge k + 1."""
        return 1

    def elaborate(self, platform):
        m = Module()
        pix = self.pixels.payload
        match = color_match_value(m, pix.pixel, self.color_sel, self.params)

        # The whole output stage is one register, laid out so that both streams are plain
        # slices of it: `filtered.payload` = bits 0-13 (pixel, first, last), `matches.payload`
        # = bits 12-14 (first, last, match), then the valid bit (one register with one enable,
        # and no bit-by-bit assembly of the outputs).
        flags_at = len(pix.pixel.as_value())
        stage = Signal(
            data.StructLayout(
                {
                    "payload": len(pix.as_value()),
                    "match": 1,
                    "valid": 1,
                }
            )
        )
        m.d.comb += [
            self.filtered.valid.eq(stage.valid),
            self.filtered.payload.eq(stage.payload),
            self.matches.valid.eq(stage.valid),
            self.matches.payload.eq(stage.as_value()[flags_at : flags_at + 3]),
        ]
        # Payloads only load on a transfer: fewer toggles (and a quieter waveform) in blanking.
        # Blacking out is an AND with the replicated match bit rather than a multiplexer, so
        # the generated C++ has no branch that depends on the pixel data.
        with m.If(self.pixels.valid):
            keep = Cat(match.replicate(flags_at), Const(0b11, 2))
            m.d.sync += load(stage, payload=pix.as_value() & keep, match=match, valid=1)
        with m.Else():
            m.d.sync += load(stage, valid=0)
        return m
