"""OV7670 byte capture: camera pins (PCLK domain) -> framed RGB444 pixel stream (``sync``).

What the camera sends (RGB444, COM7=0x04, RGB444=0x02, sampled on PCLK rising edges):

- VSYNC is high between frames (vertical blanking); no line is output while it is high.
- HREF is high while the bytes of one line are output, low in horizontal blanking.
- Two bytes make a pixel, "xR GB" order: first ``xxxxRRRR``, then ``GGGGBBBB``.

What it produces (``hw.pixel.FramedPixel``): ``pixel.r/g/b`` of every pixel, ``first`` on the
first pixel after a VSYNC, ``last`` on the last pixel of each line. A pixel is held back until
the next one arrives (``last`` = 0) or HREF falls (``last`` = 1), so the stream runs one pixel
behind the camera. This needs PCLK to keep running in horizontal blanking (the OV7670 default,
COM10 bit 5 clear).

Clock-domain crossing: pixels are written into an ``AsyncFIFO`` (14 bits wide) in the PCLK
domain and read out in ``sync`` whenever one is there; the output stream cannot be stalled.
A pixel arrives at most every other PCLK edge, so with the design clock faster than PCLK / 2
the FIFO never holds more than a few pixels. If it ever were full, the pixel is dropped and the
sticky ``overflow`` flag goes high (until reset); the design then sees a short line, which it
tolerates (a malformed frame, the next ``first`` restarts it).
"""

from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.wiring import In, Out

from ..pixel import FramedPixel, pixel_stream_signature
from ..validate import CheckedArguments, check_int

__all__ = ["OV7670Capture"]


class OV7670Capture(CheckedArguments, wiring.Component):
    """Camera bytes in the ``pclk_domain`` to a framed RGB444 stream in ``sync``.

    Parameters
    ----------
    pclk_domain : str
        Clock domain driven by the camera's PCLK (reset from the board reset).
    fifo_depth : int
        Depth of the clock-crossing FIFO (pixels).

    Members
    -------
    data : In(8)
        Camera data D[7:0] (PCLK domain).
    href, vsync : In(1)
        Camera line and frame syncs (PCLK domain).
    pixels : Out(pixel_stream_signature())
        Framed pixels in ``sync``, always ready.
    overflow : Out(1)
        Sticky (until reset), in ``sync``: a pixel was dropped because the FIFO was full.
    """

    @staticmethod
    def check_arguments(*, pclk_domain="pclk", fifo_depth=16):
        """Raise ``TypeError``/``ValueError`` unless ``OV7670Capture`` accepts the arguments."""
        check_int("fifo_depth", fifo_depth, 4)

    def __init__(self, *, pclk_domain="pclk", fifo_depth=16):
        self.pclk_domain = pclk_domain
        self.fifo_depth = int(fifo_depth)
        super().__init__(
            {
                "data": In(8),
                "href": In(1),
                "vsync": In(1),
                "pixels": Out(pixel_stream_signature()),
                "overflow": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        pclk = m.d[self.pclk_domain]

        m.submodules.fifo = fifo = AsyncFIFO(
            width=FramedPixel.size,
            depth=self.fifo_depth,
            r_domain="sync",
            w_domain=self.pclk_domain,
        )

        # Input registers: everything is sampled on the same PCLK edge.
        data = Signal(8)
        href = Signal()
        vsync = Signal()
        pclk += [data.eq(self.data), href.eq(self.href), vsync.eq(self.vsync)]

        high_byte = Signal(4)  # red, from the first byte of the pixel
        second = Signal()  # the next byte in the line is a pixel's second byte
        frame_start = Signal()  # no pixel yet since the last VSYNC
        held = Signal(FramedPixel)  # the previous pixel, not yet written
        held_valid = Signal()

        write = Signal()
        out = Signal(FramedPixel)

        with m.If(vsync):
            pclk += [frame_start.eq(1), second.eq(0), held_valid.eq(0)]
        with m.Elif(href):
            pclk += second.eq(~second)
            with m.If(~second):
                pclk += high_byte.eq(data[0:4])
            with m.Else():
                new = Signal(FramedPixel)
                m.d.comb += [
                    new.pixel.r.eq(high_byte),
                    new.pixel.g.eq(data[4:8]),
                    new.pixel.b.eq(data[0:4]),
                    new.first.eq(frame_start),
                    new.last.eq(0),
                ]
                pclk += [held.eq(new), held_valid.eq(1), frame_start.eq(0)]
                # The previous pixel was not the line's last: write it now.
                m.d.comb += [write.eq(held_valid), out.eq(held)]
        with m.Else():
            # HREF low: end of line (or blanking). The held pixel was the line's last.
            pclk += [second.eq(0), held_valid.eq(0)]
            m.d.comb += [write.eq(held_valid), out.eq(held), out.last.eq(1)]

        overflow_pclk = Signal()
        m.d.comb += [fifo.w_data.eq(out), fifo.w_en.eq(write)]
        with m.If(write & ~fifo.w_rdy):
            pclk += overflow_pclk.eq(1)
        m.submodules.overflow_sync = FFSynchronizer(overflow_pclk, self.overflow, o_domain="sync")

        # Read side: the design takes every pixel as soon as it is there.
        m.d.comb += [
            self.pixels.valid.eq(fifo.r_rdy),
            self.pixels.payload.eq(fifo.r_data),
            fifo.r_en.eq(1),
        ]
        return m
