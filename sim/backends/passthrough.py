"""A trivial one-pixel-per-clock design with the ports of ``FollowTarget``.

It registers every pixel to ``filtered`` (latency 1) and counts the pixels of the frame; after
the last pixel of the last line it strobes ``frame_done`` and shows the count's low bits on the
result outputs. It exists to measure what the compiled simulation flows can do at best on this
machine (the benchmark's reference), and to exercise the harness before the real design lands.
It is gateware: it imports nothing from the host side.
"""

from amaranth import Module, Mux, Signal, unsigned
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ...hw.pixel import PixelStream

__all__ = ["PassThrough"]


class PassThrough(wiring.Component):
    """Registers pixels and counts them; same members as ``FollowTarget``.

    Parameters
    ----------
    params : FollowTargetParams
        Only ``width``, ``height`` and ``x_bits`` are used.

    Members
    -------
    pixels : In(PixelStream)
    color_sel : In(3)
    filtered : Out(PixelStream)
        ``pixels`` one cycle later, unchanged.
    frame_done, found, proximity, centroid_x, centroid_leds, motor_left, motor_right : Out
        ``frame_done`` pulses two cycles after the frame's last pixel (so that the last
        filtered pixel is out before the results, as the frame driver requires); the others show the
        pixel count's low bits (``found`` when the count is non-zero).
    """

    #: Latencies in the sense of ``FollowTargetParams`` (see docs/backends.md).
    filter_latency = 1
    result_latency = 1
    motor_latency = 0

    def __init__(self, params):
        self.params = params
        super().__init__(
            {
                "pixels": In(PixelStream()),
                "color_sel": In(3),
                "filtered": Out(PixelStream()),
                "frame_done": Out(1),
                "found": Out(1),
                "proximity": Out(3),
                "centroid_x": Out(params.x_bits),
                "centroid_leds": Out(8),
                "motor_left": Out(16),
                "motor_right": Out(16),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        count = Signal(unsigned((p.pixels_per_frame).bit_length()))
        line = Signal(range(p.height + 1))

        total = Signal.like(count)
        ended = Signal()  # the frame's last pixel was sampled at the previous edge
        m.d.sync += [
            self.filtered.valid.eq(self.pixels.valid),
            self.filtered.payload.eq(self.pixels.payload),
            ended.eq(0),
            self.frame_done.eq(ended),
        ]
        with m.If(ended):
            m.d.sync += [
                self.found.eq(total != 0),
                self.proximity.eq(total[:3]),
                self.centroid_x.eq(total[: p.x_bits]),
                self.centroid_leds.eq(total[:8]),
                self.motor_left.eq(total[:16]),
                self.motor_right.eq(~total[:16]),
            ]
        with m.If(self.pixels.valid):
            pix = self.pixels.payload
            with m.If(pix.first):
                m.d.sync += [count.eq(1), line.eq(0)]
            with m.Else():
                m.d.sync += count.eq(count + 1)
            with m.If(pix.last):
                last_line = Signal(range(p.height + 1))
                m.d.comb += last_line.eq(line + 1)
                m.d.sync += line.eq(last_line)
                with m.If(last_line == p.height):
                    # The count including the pixel being sampled.
                    m.d.sync += [ended.eq(1), total.eq(Mux(pix.first, 1, count + 1))]
        return m
