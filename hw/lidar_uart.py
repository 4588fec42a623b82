"""The RPLIDAR's serial link in gateware: ``UartRx`` (8N1 bytes off a pin) and
``RplidarDecoder`` (the standard scan's bytes to a stream of samples)."""

from amaranth import Cat, Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from .lidar_params import UartParams
from .nearest_obstacle import sample_stream
from .validate import CheckedArguments

__all__ = ["DESCRIPTOR", "RplidarDecoder", "UartRx"]

#: The standard scan's response descriptor (``sim/world/lidar.py``).
DESCRIPTOR = (0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81)


class UartRx(CheckedArguments, wiring.Component):
    """An 8N1 receiver (Verilog module ``uart_rx``).

    ``rx`` passes two flops. In idle a low level starts a byte: the receiver waits half a bit
    (``bit_cycles // 2``), checks the start bit is still low (else back to idle: a glitch),
    then samples the 8 data bits, least significant first, and the stop bit a bit apart
    each. A stop bit high gives the byte on ``bytes`` (``valid`` one cycle); a low one is a
    framing error (``framing_error`` one cycle) and no byte; either way the receiver waits
    for the line to be high before the next start bit.
    """

    @staticmethod
    def check_arguments(params=None):
        if params is not None and not isinstance(params, UartParams):
            raise TypeError(f"params must be a UartParams, not {params!r}")

    def __init__(self, params=None):
        self.params = UartParams() if params is None else params
        super().__init__(
            {
                "rx": In(1, init=1),
                "bytes": Out(stream.Signature(8, always_ready=True)),
                "framing_error": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        n = self.params.bit_cycles
        sync1 = Signal(init=1)
        line = Signal(init=1)
        m.d.sync += [sync1.eq(self.rx), line.eq(sync1)]
        timer = Signal(range(n + 1))
        bit = Signal(range(10))
        shift = Signal(8)
        m.d.sync += [self.bytes.valid.eq(0), self.framing_error.eq(0)]
        with m.FSM():
            with m.State("idle"), m.If(~line):
                m.d.sync += timer.eq(n // 2 - 1)
                m.next = "start"
            with m.State("start"):
                with m.If(timer != 0):
                    m.d.sync += timer.eq(timer - 1)
                with m.Elif(line):
                    m.next = "idle"  # a glitch, not a start bit
                with m.Else():
                    m.d.sync += [timer.eq(n - 1), bit.eq(0)]
                    m.next = "data"
            with m.State("data"):
                with m.If(timer != 0):
                    m.d.sync += timer.eq(timer - 1)
                with m.Else():
                    m.d.sync += [timer.eq(n - 1), shift.eq(Cat(shift[1:], line)), bit.eq(bit + 1)]
                    with m.If(bit == 7):
                        m.next = "stop"
            with m.State("stop"):
                with m.If(timer != 0):
                    m.d.sync += timer.eq(timer - 1)
                with m.Elif(line):
                    m.d.sync += [self.bytes.payload.eq(shift), self.bytes.valid.eq(1)]
                    m.next = "idle"
                with m.Else():
                    m.d.sync += self.framing_error.eq(1)
                    m.next = "wait_high"
            with m.State("wait_high"), m.If(line):
                m.next = "idle"
        return m


class RplidarDecoder(wiring.Component):
    """The standard scan's answer to samples (Verilog module ``rplidar_decoder``).

    It waits for the response descriptor ``A5 5A 05 00 00 40 81``, then reads 5-byte
    packets: a first byte whose S and !S bits are equal, or a second byte whose check bit is
    0, is dropped and the packet begun again with the next byte (resynchronisation); the
    fifth byte gives the sample on ``samples`` (``valid`` one cycle, the cycle after it
    arrives): ``quality = byte0 >> 2``, ``start = S``, ``angle_q6 = byte1 >> 1 | byte2 << 7``,
    ``distance_q2 = byte3 | byte4 << 8``. ``resyncs`` counts the dropped bytes (wrapping).
    """

    bytes: In(stream.Signature(8, always_ready=True))
    samples: Out(sample_stream())
    synced: Out(1)
    resyncs: Out(8)

    def elaborate(self, platform):
        m = Module()
        b = self.bytes.payload
        matched = Signal(range(len(DESCRIPTOR) + 1))
        index = Signal(range(5))
        packet = Signal(32)  # bytes 0..3
        s = self.samples.payload
        m.d.sync += self.samples.valid.eq(0)
        with m.If(self.bytes.valid):
            with m.If(~self.synced), m.Switch(matched):
                for k, value in enumerate(DESCRIPTOR):
                    with m.Case(k):
                        with m.If(b == value):
                            if k == len(DESCRIPTOR) - 1:
                                m.d.sync += [self.synced.eq(1), index.eq(0)]
                            else:
                                m.d.sync += matched.eq(k + 1)
                        with m.Else():
                            m.d.sync += matched.eq(b == DESCRIPTOR[0])
            with m.Else(), m.Switch(index):
                with m.Case(0):
                    with m.If(b[0] == b[1]):
                        m.d.sync += self.resyncs.eq(self.resyncs + 1)
                    with m.Else():
                        m.d.sync += [packet[0:8].eq(b), index.eq(1)]
                with m.Case(1):
                    with m.If(~b[0]):
                        m.d.sync += [self.resyncs.eq(self.resyncs + 1), index.eq(0)]
                    with m.Else():
                        m.d.sync += [packet[8:16].eq(b), index.eq(2)]
                with m.Case(2):
                    m.d.sync += [packet[16:24].eq(b), index.eq(3)]
                with m.Case(3):
                    m.d.sync += [packet[24:32].eq(b), index.eq(4)]
                with m.Case(4):
                    m.d.sync += [
                        s.quality.eq(packet[2:8]),
                        s.start.eq(packet[0]),
                        s.angle_q6.eq(packet[9:24]),
                        s.distance_q2.eq(Cat(packet[24:32], b)),
                        self.samples.valid.eq(1),
                        index.eq(0),
                    ]
        return m
