"""A trivial one-pixel-per-clock design with the ports of ``FollowTarget``.

It registers every pixel to ``filtered`` (latency 1) and counts the pixels of the frame; after
the last pixel of the last line it strobes ``frame_done`` and shows the count's low bits on the
result outputs. It exists to measure what the compiled simulation flows can do at best on this
machine (the benchmark's reference), and to exercise the harness before the real design lands.
It is gateware: it imports nothing from the host side.
"""

from amaranth import Module, Mux, ResetSignal, Signal, unsigned
from amaranth.lib import wiring

from ...hw.top import follow_target_signature

__all__ = ["PassThrough"]


class PassThrough(wiring.Component):
    """Registers pixels and counts them; same members as ``FollowTarget``.

    Parameters
    ----------
    params : FollowTargetParams
        Only ``width``, ``height`` and ``x_bits`` are used.
    registered_outputs : bool
        False makes every output combinational (through logic that also reads ``rst``), with
        the same values in every frame: it exercises the harnesses' general two-evaluation loop.

    Members
    -------
    pixels : In(pixel_stream_signature())
    color_sel : In(3)
    filtered : Out(pixel_stream_signature())
        ``pixels`` one cycle later, unchanged.
    frame_done, found, proximity, centroid_x, centroid_leds, motor_left, motor_right : Out
        ``frame_done`` pulses two cycles after the frame's last pixel (so that the last
        filtered pixel is out before the results, as the frame driver requires); the others
        show the pixel count's low bits (``found`` when the count is non-zero).
    """

    #: Latencies in the sense of ``FollowTargetParams`` (see docs/backends.md).
    filter_latency = 1
    result_latency = 1
    motor_latency = 0

    def __init__(self, params, *, registered_outputs=True):
        self.params = params
        self.registered_outputs = registered_outputs
        super().__init__(follow_target_signature(params))

    def elaborate(self, platform):
        m = Module()
        p = self.params
        ports = {
            "filtered_valid": self.filtered.valid,
            "filtered_payload": self.filtered.payload.as_value(),
            "frame_done": self.frame_done,
            "found": self.found,
            "proximity": self.proximity,
            "centroid_x": self.centroid_x,
            "centroid_leds": self.centroid_leds,
            "motor_left": self.motor_left,
            "motor_right": self.motor_right,
        }
        if self.registered_outputs:
            out = ports
        else:
            # Test variant: every output goes through logic that also reads the `rst` input,
            # so the outputs are combinational (and 0 during reset, which no frame observes).
            out = {name: Signal.like(port, name=f"{name}_q") for name, port in ports.items()}
            m.d.comb += [ports[n].eq(Mux(ResetSignal(), 0, out[n])) for n in ports]

        count = Signal(unsigned((p.pixels_per_frame).bit_length()))
        line = Signal(range(p.height + 1))
        total = Signal.like(count)
        ended = Signal()  # the frame's last pixel was sampled at the previous edge
        m.d.sync += [
            out["filtered_valid"].eq(self.pixels.valid),
            out["filtered_payload"].eq(self.pixels.payload),
            ended.eq(0),
            out["frame_done"].eq(ended),
        ]
        with m.If(ended):
            m.d.sync += [
                out["found"].eq(total != 0),
                out["proximity"].eq(total[:3]),
                out["centroid_x"].eq(total[: p.x_bits]),
                out["centroid_leds"].eq(total[:8]),
                out["motor_left"].eq(total[:16]),
                out["motor_right"].eq(~total[:16]),
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
