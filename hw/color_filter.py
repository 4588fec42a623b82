"""Per-pixel colour filter: keeps the pixels of the selected colour, blacks out the others."""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from .params import FollowTargetParams
from .pixel import PixelStream

__all__ = ["ColorFilter", "MatchFlags", "MatchStream", "color_match_value"]

#: What the tracker needs of each filtered pixel: the match bit and the framing flags.
MatchFlags = data.StructLayout({"match": 1, "first": 1, "last": 1})


def MatchStream():
    """Signature of the per-pixel match stream from the filter to the tracker."""
    return stream.Signature(MatchFlags, always_ready=True)


def _max(a, b):
    return Mux(a > b, a, b)


def _min(a, b):
    return Mux(a < b, a, b)


def color_match_value(m, pixel, color_sel, params):
    """Return a 1-bit signal: does RGB444 ``pixel`` match ``color_sel`` (hw-spec colour table)?

    Differences of unsigned values are signed in Amaranth, so a negative difference never
    reaches ``diff_min`` -- exactly the contract's "differences are signed" rule.
    """
    r, g, b = pixel.r, pixel.g, pixel.b
    d, s, wm = params.diff_min, params.similar_max, params.white_min

    def similar(a, c):  # abs(a - c) <= S, without a signed absolute value
        return (a - c <= s) & (c - a <= s)

    match = Signal()
    with m.Switch(color_sel):
        with m.Case(0b000):  # none: every pixel
            m.d.comb += match.eq(1)
        with m.Case(0b100):  # red
            m.d.comb += match.eq(r - _max(g, b) >= d)
        with m.Case(0b010):  # green
            m.d.comb += match.eq(g - _max(r, b) >= d)
        with m.Case(0b001):  # blue
            m.d.comb += match.eq(b - _max(r, g) >= d)
        with m.Case(0b110):  # yellow
            m.d.comb += match.eq(similar(r, g) & (_min(r, g) - b >= d))
        with m.Case(0b101):  # magenta
            m.d.comb += match.eq(similar(r, b) & (_min(r, b) - g >= d))
        with m.Case(0b011):  # cyan
            m.d.comb += match.eq(similar(g, b) & (_min(g, b) - r >= d))
        with m.Case(0b111):  # white
            hi = _max(_max(r, g), b)
            lo = _min(_min(r, g), b)
            m.d.comb += match.eq((hi - lo <= s) & (lo >= wm))
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
    pixels : ``In(PixelStream())``
        Camera pixels (cannot be stalled).
    color_sel : ``In(3)``
        Colour select, sampled with each pixel: bit 2 red, bit 1 green, bit 0 blue.
    filtered : ``Out(PixelStream())``
        Filtered pixels, ``latency`` cycles after the input.
    matches : ``Out(MatchStream())``
        Match bit and framing flags, aligned with ``filtered``.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        super().__init__({
            "pixels": In(PixelStream()),
            "color_sel": In(3),
            "filtered": Out(PixelStream()),
            "matches": Out(MatchStream()),
        })

    @property
    def latency(self):
        """A pixel sampled at edge k is sampled on ``filtered``/``matches`` at edge k + 1."""
        return 1

    def elaborate(self, platform):
        m = Module()
        pix = self.pixels.payload
        match = color_match_value(m, pix.pixel, self.color_sel, self.params)

        m.d.sync += [
            self.filtered.valid.eq(self.pixels.valid),
            self.matches.valid.eq(self.pixels.valid),
        ]
        # Payloads only load on a transfer: fewer toggles (and a quieter waveform) in blanking.
        with m.If(self.pixels.valid):
            m.d.sync += [
                self.filtered.payload.pixel.eq(Mux(match, pix.pixel, 0)),
                self.filtered.payload.first.eq(pix.first),
                self.filtered.payload.last.eq(pix.last),
                self.matches.payload.match.eq(match),
                self.matches.payload.first.eq(pix.first),
                self.matches.payload.last.eq(pix.last),
            ]
        return m
