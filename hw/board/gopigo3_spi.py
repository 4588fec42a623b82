"""GoPiGo3 motor commands over SPI: a byte-level SPI master and the message sequencer.

The GoPiGo3's motor controller is an SPI peripheral at address 0x08 (SPI mode 0, 500 kHz in
Dexter Industries' own driver). Every message starts with the address and a message type; this
design only writes, and ignores MISO. The messages used, with their byte layouts (from the
GoPiGo3 Python driver's ``set_motor_limits``, ``set_motor_dps`` and ``set_servo``):

===============  ====================================================================
SET_MOTOR_LIMITS ``0x08, 0x0F, port mask, power limit (%), dps hi, dps lo``
SET_MOTOR_DPS    ``0x08, 0x0E, port mask, speed hi, speed lo``
SET_SERVO        ``0x08, 0x09, servo port mask, pulse width (us) hi, lo``
===============  ====================================================================

Port masks: left motor 0x01, right motor 0x02. Speeds and the speed limit are in encoder ticks
per second: the driver multiplies degrees per second by ``MOTOR_TICKS_PER_DEGREE`` = 2 (gear
ratio 120 x 6 encoder ticks per motor turn / 360), and sends a signed 16-bit big-endian value
(two's complement). A power limit of 0 means "no power limit" to the firmware.

After reset the sequencer waits ``startup_wait`` cycles (the GoPiGo3 may power up with us), sends
SET_MOTOR_LIMITS once per motor, then, for every ``update`` strobe, SET_MOTOR_DPS for the left
then the right wheel with the values latched at the strobe. Chip select goes high between
messages. An update that arrives during a transfer is kept (the latest one) and sent next.

With ``servo=True`` every update also latches ``servo_angle`` (the published 10-bit signed
command, +-500 for +-90 degrees) and sends SET_SERVO to servo port 1 after the right wheel:
pulse width 1500 + angle microseconds, the angle clamped to +-500 (1000..2000 us), as the
simulated servo stops at its end stops beyond +-500.
"""

import enum

from amaranth.hdl import Const, Module, Mux, Signal, signed
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from ..validate import CheckedArguments, check_int

__all__ = [
    "GOPIGO3_ADDRESS",
    "MOTOR_LEFT",
    "MOTOR_RIGHT",
    "SERVO_1",
    "TICKS_PER_DEGREE",
    "GoPiGo3Message",
    "GoPiGo3Motors",
    "SPIByte",
    "SPIByteMaster",
    "dps_to_ticks",
    "servo_pulse_us",
]

GOPIGO3_ADDRESS = 0x08
#: The largest speed limit SET_MOTOR_LIMITS carries: DPS x 2 ticks in a signed 16-bit field.
GOPIGO3_MAX_DPS_LIMIT = (1 << 14) - 1
MOTOR_LEFT = 0x01
MOTOR_RIGHT = 0x02
TICKS_PER_DEGREE = 2
SERVO_1 = 0x01
#: The servo pulse for command 0 (centred) and the largest command (+-90 degrees), microseconds.
SERVO_CENTRE_US = 1500
SERVO_FULL_COMMAND = 500


class GoPiGo3Message(enum.IntEnum):
    """GoPiGo3 SPI message types used here."""

    SET_LED = 0x06
    SET_SERVO = 0x09
    SET_MOTOR_DPS = 0x0E
    SET_MOTOR_LIMITS = 0x0F


def dps_to_ticks(dps):
    """Host reference: degrees per second -> the signed 16-bit ticks/s the GoPiGo3 is sent."""
    return max(-(1 << 15), min((1 << 15) - 1, dps * TICKS_PER_DEGREE))


def servo_pulse_us(angle):
    """Host reference: a servo command (signed, +-500 = +-90 degrees) -> SET_SERVO's pulse, us."""
    return SERVO_CENTRE_US + max(-SERVO_FULL_COMMAND, min(SERVO_FULL_COMMAND, angle))


#: One byte for the SPI master; ``end`` releases chip select after it.
SPIByte = data.StructLayout({"data": 8, "end": 1})


class SPIByteMaster(CheckedArguments, wiring.Component):
    """SPI mode 0 master, write-only, MSB first, one chip select.

    Chip select is asserted for the first byte and released after a byte marked ``end``; then
    the bus stays idle for ``2 * half_period`` cycles. Bytes of one message are sent back to
    back as long as the next one is offered when the previous one ends.

    Parameters
    ----------
    half_period : int
        Clock cycles per half SCLK period (50 MHz / (2 * 50) = 500 kHz).

    Members
    -------
    bytes : In(stream.Signature(SPIByte))
        Bytes to send.
    sclk, copi : Out(1)
        SPI clock (idle low) and data out; data changes on falling edges.
    cs : Out(1)
        Chip select, active high here (the board pin is inverted).
    """

    @staticmethod
    def check_arguments(*, half_period):
        """Raise ``TypeError``/``ValueError`` unless ``SPIByteMaster`` accepts the arguments."""
        check_int("half_period", half_period, 1)

    def __init__(self, *, half_period):
        self.half_period = int(half_period)
        super().__init__(
            {
                "bytes": In(stream.Signature(SPIByte)),
                "sclk": Out(1),
                "copi": Out(1),
                "cs": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        timer = Signal(range(2 * self.half_period + 1))
        shift = Signal(8)
        bit = Signal(range(8))
        end = Signal()
        m.d.comb += self.copi.eq(shift[7])

        with m.If(timer != 0):
            m.d.sync += timer.eq(timer - 1)

        with m.FSM():
            with m.State("IDLE"):
                m.d.comb += self.bytes.ready.eq(timer == 0)
                with m.If(self.bytes.valid & (timer == 0)):
                    m.d.sync += [
                        shift.eq(self.bytes.payload.data),
                        end.eq(self.bytes.payload.end),
                        bit.eq(0),
                        self.cs.eq(1),
                        timer.eq(self.half_period - 1),
                    ]
                    m.next = "LOW"
            with m.State("LOW"), m.If(timer == 0):
                # SCLK low for half a period with the data set up
                m.d.sync += [self.sclk.eq(1), timer.eq(self.half_period - 1)]
                m.next = "HIGH"
            with m.State("HIGH"), m.If(timer == 0):
                # SCLK high: the peripheral sampled COPI on the rising edge
                m.d.sync += self.sclk.eq(0)
                with m.If(bit != 7):
                    m.d.sync += [
                        shift.eq(shift << 1),
                        bit.eq(bit + 1),
                        timer.eq(self.half_period - 1),
                    ]
                    m.next = "LOW"
                with m.Else():
                    m.next = "NEXT"
            with m.State("NEXT"):
                with m.If(~end):
                    # Same message: take the next byte at once, with the falling edge.
                    m.d.comb += self.bytes.ready.eq(1)
                    with m.If(self.bytes.valid):
                        m.d.sync += [
                            shift.eq(self.bytes.payload.data),
                            end.eq(self.bytes.payload.end),
                            bit.eq(0),
                            timer.eq(self.half_period - 1),
                        ]
                        m.next = "LOW"
                with m.Else():
                    m.d.sync += timer.eq(self.half_period - 1)  # hold time after the last edge
                    m.next = "RELEASE"
            with m.State("RELEASE"), m.If(timer == 0):
                m.d.sync += [self.cs.eq(0), timer.eq(2 * self.half_period)]
                m.next = "IDLE"
        return m


class GoPiGo3Motors(CheckedArguments, wiring.Component):
    """Sends the GoPiGo3 its motor limits after reset, then the wheel speeds on every update.

    Parameters
    ----------
    half_period : int
        Clock cycles per half SCLK period.
    startup_wait : int
        Clock cycles after reset before the first message.
    dps_limit : int
        Speed limit set once per motor, degrees per second (512, the published value).
    power_limit : int
        Power limit in percent, 0 = none (the driver's default).
    servo : bool
        Also send ``servo_angle`` to servo port 1 on every update.

    Members
    -------
    update : In(1)
        Strobe: latch ``left``/``right`` and send them.
    left, right : In(signed(16))
        Wheel speeds in degrees per second.
    servo_angle : In(signed(10))
        The servo command (only with ``servo``).
    sclk, copi, cs : Out(1)
        The SPI bus (``cs`` active high).
    busy : Out(1)
        A message is being sent or waits to be sent.
    """

    @staticmethod
    def check_arguments(*, half_period, startup_wait=0, dps_limit=512, power_limit=0, servo=False):
        """Raise ``TypeError``/``ValueError`` unless ``GoPiGo3Motors`` accepts the arguments."""
        SPIByteMaster.check_arguments(half_period=half_period)
        check_int("startup_wait", startup_wait, 0)
        check_int("dps_limit", dps_limit, 0, GOPIGO3_MAX_DPS_LIMIT)
        check_int("power_limit", power_limit, 0, 100)
        if not isinstance(servo, bool):
            raise TypeError(f"servo must be True or False, not {servo!r}")

    def __init__(self, *, half_period, startup_wait=0, dps_limit=512, power_limit=0, servo=False):
        self.half_period = int(half_period)
        self.startup_wait = int(startup_wait)
        self.dps_limit = int(dps_limit)
        self.power_limit = int(power_limit)
        self.servo = servo
        self.spi = SPIByteMaster(half_period=half_period)
        members = {
            "update": In(1),
            "left": In(signed(16)),
            "right": In(signed(16)),
            "sclk": Out(1),
            "copi": Out(1),
            "cs": Out(1),
            "busy": Out(1),
        }
        if servo:
            members["servo_angle"] = In(signed(10))
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        m.submodules.spi = spi = self.spi
        m.d.comb += [self.sclk.eq(spi.sclk), self.copi.eq(spi.copi), self.cs.eq(spi.cs)]

        def ticks(dps):
            # DPS x 2, saturated to int16 (only matters for |dps| > 16383).
            t = Signal(signed(18))
            out = Signal(signed(16))
            m.d.comb += t.eq(dps * TICKS_PER_DEGREE)
            m.d.comb += out.eq(Mux(t > 32767, 32767, Mux(t < -32768, -32768, t)))
            return out

        def pulse(angle):
            # 1500 + angle us, the angle clamped to +-500: 1000..2000 fits 16 bits unsigned.
            out = Signal(16)
            full = SERVO_FULL_COMMAND
            clamped = Mux(angle > full, full, Mux(angle < -full, -full, angle))
            m.d.comb += out.eq(SERVO_CENTRE_US + clamped)
            return out

        pending = Signal()
        next_left = Signal(signed(16))
        next_right = Signal(signed(16))
        next_servo = Signal(16)
        with m.If(self.update):
            m.d.sync += [
                pending.eq(1),
                next_left.eq(ticks(self.left)),
                next_right.eq(ticks(self.right)),
            ]
            if self.servo:
                m.d.sync += next_servo.eq(pulse(self.servo_angle))

        # The message being sent: its type, port and 16-bit argument.
        limits = Signal()
        port = Signal(8)
        value = Signal(16)
        byte = Signal(range(6))
        right_next = Signal()  # the left DPS message is out; the right one follows
        cur_right = Signal(16)
        servo_msg = Signal()  # the message being sent is SET_SERVO
        servo_next = Signal()  # SET_SERVO follows the right wheel's message
        cur_servo = Signal(16)
        length = Mux(limits, 6, 5)
        contents = Signal(8)
        with m.Switch(byte):
            with m.Case(0):
                m.d.comb += contents.eq(GOPIGO3_ADDRESS)
            with m.Case(1):
                m.d.comb += contents.eq(
                    Mux(
                        limits,
                        GoPiGo3Message.SET_MOTOR_LIMITS,
                        Mux(servo_msg, GoPiGo3Message.SET_SERVO, GoPiGo3Message.SET_MOTOR_DPS),
                    )
                )
            with m.Case(2):
                m.d.comb += contents.eq(port)
            with m.Case(3):
                m.d.comb += contents.eq(Mux(limits, self.power_limit, value[8:16]))
            with m.Case(4):
                m.d.comb += contents.eq(Mux(limits, value[8:16], value[0:8]))
            with m.Case(5):
                m.d.comb += contents.eq(value[0:8])
        m.d.comb += [
            spi.bytes.payload.data.eq(contents),
            spi.bytes.payload.end.eq(byte == length - 1),
        ]

        limit_ticks = Const(self.dps_limit * TICKS_PER_DEGREE, 16)
        wait = Signal(range(self.startup_wait + 1), init=self.startup_wait)
        with m.FSM():
            with m.State("STARTUP"):
                with m.If(wait != 0):
                    m.d.sync += wait.eq(wait - 1)
                with m.Else():
                    m.d.sync += [
                        limits.eq(1),
                        port.eq(MOTOR_LEFT),
                        value.eq(limit_ticks),
                        byte.eq(0),
                    ]
                    m.next = "SEND"
            with m.State("IDLE"), m.If(pending):
                m.d.sync += pending.eq(0)
                m.d.sync += [
                    limits.eq(0),
                    port.eq(MOTOR_LEFT),
                    value.eq(next_left),
                    cur_right.eq(next_right),
                    right_next.eq(1),
                    byte.eq(0),
                ]
                if self.servo:  # without a servo these stay 0: wheel messages only
                    m.d.sync += [
                        cur_servo.eq(next_servo),
                        servo_next.eq(1),
                        servo_msg.eq(0),
                    ]
                with m.If(self.update):  # a new update in this very cycle stays pending
                    m.d.sync += pending.eq(1)
                m.next = "SEND"
            with m.State("SEND"):
                m.d.comb += [spi.bytes.valid.eq(1), self.busy.eq(1)]
                with m.If(spi.bytes.ready):
                    m.d.sync += byte.eq(byte + 1)
                    with m.If(byte == length - 1):
                        m.d.sync += byte.eq(0)
                        with m.If(limits & (port == MOTOR_LEFT)):
                            m.d.sync += port.eq(MOTOR_RIGHT)
                        with m.Elif(~limits & right_next):
                            m.d.sync += [
                                port.eq(MOTOR_RIGHT),
                                value.eq(cur_right),
                                right_next.eq(0),
                            ]
                        if self.servo:
                            with m.Elif(~limits & servo_next):
                                m.d.sync += [
                                    port.eq(SERVO_1),
                                    value.eq(cur_servo),
                                    servo_msg.eq(1),
                                    servo_next.eq(0),
                                ]
                        with m.Else():
                            m.next = "IDLE"
        with m.If(pending):
            m.d.comb += self.busy.eq(1)
        return m
