"""Colour selection from the ULX3S DIP switches.

SW1, SW2, SW3 are the red, green and blue bits of ``color_sel`` (``hw.pixel.TargetColor``):
the switch positions read as the colour followed (SW1+SW2 = yellow, all three = white, ...).
With all three off the robot follows red, the published default, so a board with untouched
switches does what the published robot did. (``color_sel`` = 0, "match everything", is not
selectable on the board: it would make the robot chase the whole picture.) SW4 is unused.

The switches are synchronised into ``sync`` (two flip-flops); a switch being flipped may show
an intermediate colour for one frame, which is harmless.
"""

from amaranth.hdl import Cat, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from ..pixel import TargetColor

__all__ = ["SwitchColorSelect"]


class SwitchColorSelect(wiring.Component):
    """DIP switches -> ``color_sel``.

    Members
    -------
    switches : In(3)
        SW1 (bit 0), SW2 (bit 1), SW3 (bit 2), high when on; asynchronous.
    color_sel : Out(TargetColor)
        ``{SW1, SW2, SW3}`` as red, green, blue; red when all are off.
    """

    switches: In(3)
    color_sel: Out(TargetColor)

    def elaborate(self, platform):
        m = Module()
        sw = Signal(3)
        m.submodules.sync = FFSynchronizer(self.switches, sw)
        rgb = Cat(sw[2], sw[1], sw[0])  # color_sel bit 2 = red = SW1
        m.d.comb += self.color_sel.eq(Mux(sw == 0, TargetColor.RED, rgb))
        return m
