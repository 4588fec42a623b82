"""The RPLIDAR's serial link in gateware: ``UartRx`` (8N1 bytes off a pin) and
``RplidarDecoder`` (the standard scan's bytes to a stream of samples)."""

from amaranth import Cat, Module, Signal
from amaranth.lib import enum, stream, wiring
from amaranth.lib.wiring import In, Out

from .lidar_params import UartParams
from .nearest_obstacle import sample_stream
from .validate import CheckedArguments

__all__ = ["DESCRIPTOR", "RplidarDecoder", "UartRx"]

#: The standard scan's response descriptor (``sim/world/lidar.py``).
DESCRIPTOR = (0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81)


class _Rx(enum.Enum, shape=3):
    # From 1: a state compared with 0 becomes a multi-bit "!" that Verilator warns about.
    IDLE = 1
    START = 2
    DATA = 3
    STOP = 4
    WAIT_HIGH = 5


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
        state = Signal(_Rx, init=_Rx.IDLE)
        with m.If(state == _Rx.IDLE), m.If(~line):
            m.d.sync += [timer.eq(n // 2 - 1), state.eq(_Rx.START)]
        with m.Elif(state == _Rx.START):
            with m.If(timer != 0):
                m.d.sync += timer.eq(timer - 1)
            with m.Elif(line):
                m.d.sync += state.eq(_Rx.IDLE)  # a glitch, not a start bit
            with m.Else():
                m.d.sync += [timer.eq(n - 1), bit.eq(0), state.eq(_Rx.DATA)]
        with m.Elif(state == _Rx.DATA):
            with m.If(timer != 0):
                m.d.sync += timer.eq(timer - 1)
            with m.Else():
                m.d.sync += [timer.eq(n - 1), shift.eq(Cat(shift[1:], line)), bit.eq(bit + 1)]
                with m.If(bit == 7):
                    m.d.sync += state.eq(_Rx.STOP)
        with m.Elif(state == _Rx.STOP):
            with m.If(timer != 0):
                m.d.sync += timer.eq(timer - 1)
            with m.Elif(line):
                m.d.sync += [
                    self.bytes.payload.eq(shift),
                    self.bytes.valid.eq(1),
                    state.eq(_Rx.IDLE),
                ]
            with m.Else():
                m.d.sync += [self.framing_error.eq(1), state.eq(_Rx.WAIT_HIGH)]
        with m.Else(), m.If(line):  # WAIT_HIGH: the line high again
            m.d.sync += state.eq(_Rx.IDLE)
        return m


def _equals(value, const):
    # "== 0" written as "not any": Amaranth emits it as a multi-bit "!" otherwise.
    return value == const if const else ~value.any()


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
        with m.If(self.bytes.valid & ~self.synced):
            # Matching the descriptor: one more byte right, or start again (at 1 on an A5).
            for k, value in enumerate(DESCRIPTOR):
                with m.If(_equals(matched, k)):
                    with m.If(_equals(b, value)):
                        if k == len(DESCRIPTOR) - 1:
                            m.d.sync += [self.synced.eq(1), index.eq(0)]
                        else:
                            m.d.sync += matched.eq(k + 1)
                    with m.Else():
                        m.d.sync += matched.eq(_equals(b, DESCRIPTOR[0]))
        with m.Elif(self.bytes.valid):
            with m.If(~index.any()):  # index 0
                with m.If(b[0] == b[1]):  # S = !S: not a first byte
                    m.d.sync += self.resyncs.eq(self.resyncs + 1)
                with m.Else():
                    m.d.sync += [packet[0:8].eq(b), index.eq(1)]
            with m.Elif(index == 1):
                with m.If(~b[0]):  # check bit C = 0: begin again
                    m.d.sync += [self.resyncs.eq(self.resyncs + 1), index.eq(0)]
                with m.Else():
                    m.d.sync += [packet[8:16].eq(b), index.eq(2)]
            with m.Elif(index == 2):
                m.d.sync += [packet[16:24].eq(b), index.eq(3)]
            with m.Elif(index == 3):
                m.d.sync += [packet[24:32].eq(b), index.eq(4)]
            with m.Else():  # byte 4
                m.d.sync += [
                    s.quality.eq(packet[2:8]),
                    s.start.eq(packet[0]),
                    s.angle_q6.eq(packet[9:24]),
                    s.distance_q2.eq(Cat(packet[24:32], b)),
                    self.samples.valid.eq(1),
                    index.eq(0),
                ]
        return m
