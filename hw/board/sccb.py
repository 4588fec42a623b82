"""SCCB (the camera's I2C-like bus) master that writes the OV7670 register table after reset.

SCCB writes are 3-phase transmissions: START, the device ID (0x42 for the OV7670, i.e. 7-bit
address 0x21 with the write bit), the register address, the value, STOP. Each byte is followed by
a ninth "don't care" bit during which the master releases SIOD (the camera may pull it low, as an
I2C acknowledge; we do not check it, since the bus is write-only here).

Bit timing, in quarter periods of SIOC (``quarter_period`` clock cycles each): SIOC is low for
the first two quarters of a bit and high for the last two; SIOD changes one quarter after SIOC
falls, so it is stable a quarter period before and the whole high time of SIOC. START is SIOD
falling while SIOC is high, STOP is SIOD rising while SIOC is high. At 50 MHz with
``quarter_period=125`` SIOC runs at 100 kHz (the OV7670 allows 400 kHz).

The table comes first. It sets up RGB444 at QQVGA (160x120) as the published robot did; each
entry's comment says why. See ``docs/board.md`` for the byte order it produces.
"""

from typing import NamedTuple

from amaranth.hdl import Cat, Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from ..validate import CheckedArguments, check_int

__all__ = ["OV7670_INIT", "OV7670_SCCB_ID", "RegisterWrite", "SCCBInit"]

#: The OV7670's SCCB write ID (7-bit address 0x21, R/W bit 0).
OV7670_SCCB_ID = 0x42


class RegisterWrite(NamedTuple):
    """One camera register write. ``wait_after``: pause ``reset_wait`` cycles after it."""

    reg: int
    value: int
    comment: str
    wait_after: bool = False


#: OV7670 initialisation, written in this order. RGB444 "xR GB": the first byte of a pixel is
#: ``xxxxRRRR``, the second ``GGGGBBBB``.
OV7670_INIT = (
    RegisterWrite(0x12, 0x80, "COM7: software reset of every register", wait_after=True),
    RegisterWrite(0x11, 0x00, "CLKRC: internal clock = XCLK (no prescaler)"),
    RegisterWrite(0x12, 0x04, "COM7: RGB output, VGA timing (QQVGA comes from the scaler)"),
    RegisterWrite(0x8C, 0x02, "RGB444: enable, xR GB byte order"),
    RegisterWrite(0x40, 0xF0, "COM15: output range 00..FF, RGB555/444 (bit 4 needed for 444)"),
    RegisterWrite(0x0C, 0x04, "COM3: enable scaling (DCW)"),
    RegisterWrite(0x3E, 0x1A, "COM14: manual scaling, PCLK divided by 4"),
    RegisterWrite(0x70, 0x3A, "SCALING_XSC: horizontal scale factor"),
    RegisterWrite(0x71, 0x35, "SCALING_YSC: vertical scale factor"),
    RegisterWrite(0x72, 0x22, "SCALING_DCWCTR: downsample by 4 in both directions"),
    RegisterWrite(0x73, 0xF2, "SCALING_PCLK_DIV: DSP clock divided by 4"),
    RegisterWrite(0xA2, 0x02, "SCALING_PCLK_DELAY: scaling output delay"),
    RegisterWrite(0x17, 0x16, "HSTART: horizontal window start, high 8 bits"),
    RegisterWrite(0x18, 0x04, "HSTOP: horizontal window stop, high 8 bits"),
    RegisterWrite(0x32, 0xA4, "HREF: window low bits (start, stop) and edge offset"),
    RegisterWrite(0x19, 0x02, "VSTART: vertical window start, high 8 bits"),
    RegisterWrite(0x1A, 0x7A, "VSTOP: vertical window stop, high 8 bits"),
    RegisterWrite(0x03, 0x0A, "VREF: vertical window low bits"),
    RegisterWrite(0x15, 0x00, "COM10: default sync polarities; PCLK keeps running in blanking"),
)

# One SCCB write: 3 bytes, each with its don't-care bit.
_BITS = 27


class SCCBInit(CheckedArguments, wiring.Component):
    """Writes a register table over SCCB once after reset, then holds the bus idle.

    Parameters
    ----------
    table : sequence of RegisterWrite
        What to write, in order.
    quarter_period : int
        Clock cycles per quarter of an SIOC period.
    reset_wait : int
        Clock cycles to wait after an entry marked ``wait_after`` (the software reset: the
        OV7670 needs 1 ms before it accepts writes again).
    startup_wait : int
        Clock cycles to wait after reset before the first write (camera power-up).
    device_id : int
        SCCB write ID, 0x42 for the OV7670.

    Members
    -------
    sioc : Out(1)
        SCCB clock (push-pull; high when idle).
    siod_o, siod_oe : Out(1)
        SCCB data output and its output enable (released on the don't-care bits).
    done : Out(1)
        High once the whole table has been written.
    """

    @staticmethod
    def check_arguments(
        table=OV7670_INIT, *, quarter_period, reset_wait, startup_wait=0, device_id=OV7670_SCCB_ID
    ):
        """Raise ``TypeError``/``ValueError`` unless ``SCCBInit`` accepts these arguments."""
        if iter(table) is table:  # read once here and once by the constructor
            raise TypeError("the SCCB register table must be a sequence, not an iterator")
        if not table:
            raise ValueError("the SCCB register table is empty")
        for i, w in enumerate(table):
            check_int(f"table[{i}].reg (a byte)", w.reg, 0, 0xFF)
            check_int(f"table[{i}].value (a byte)", w.value, 0, 0xFF)
        check_int("quarter_period", quarter_period, 1)
        check_int("reset_wait", reset_wait, 0)
        check_int("startup_wait", startup_wait, 0)
        check_int("device_id", device_id, 0, 0xFF)

    def __init__(
        self,
        table=OV7670_INIT,
        *,
        quarter_period,
        reset_wait,
        startup_wait=0,
        device_id=OV7670_SCCB_ID,
    ):
        table = tuple(table)  # checked in check_arguments, before the component existed
        self.table = table
        self.quarter_period = int(quarter_period)
        self.reset_wait = int(reset_wait)
        self.startup_wait = int(startup_wait)
        self.device_id = int(device_id)
        super().__init__(
            {
                "sioc": Out(1, init=1),
                "siod_o": Out(1, init=1),
                "siod_oe": Out(1, init=1),
                "done": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        n = len(self.table)

        # Quarter-period strobe.
        presc = Signal(range(self.quarter_period))
        tick = Signal()
        m.d.comb += tick.eq(presc == 0)
        with m.If(presc == 0):
            m.d.sync += presc.eq(self.quarter_period - 1)
        with m.Else():
            m.d.sync += presc.eq(presc - 1)

        index = Signal(range(n + 1))
        quarter = Signal(2)
        bit = Signal(range(_BITS))
        gap = 4 * self.quarter_period  # bus free time between two writes: one bit time
        wait = Signal(
            range(max(self.reset_wait, self.startup_wait, gap) + 1), init=self.startup_wait
        )

        # The 27-bit frame of the current entry, MSB first; don't-care bits are 1 (released).
        reg = Signal(8)
        value = Signal(8)
        wait_after = Signal()
        with m.Switch(index):
            for i, w in enumerate(self.table):
                with m.Case(i):
                    m.d.comb += [reg.eq(w.reg), value.eq(w.value), wait_after.eq(w.wait_after)]
        frame = Signal(_BITS)
        m.d.comb += frame.eq(
            Cat(Const(1, 1), value, Const(1, 1), reg, Const(1, 1), Const(self.device_id, 8))
        )
        current = Signal()
        in_order = Cat(frame[i] for i in reversed(range(_BITS)))  # bit k = k-th sent
        m.d.comb += current.eq(in_order.bit_select(bit, 1))
        dont_care = Signal()
        m.d.comb += dont_care.eq((bit == 8) | (bit == 17) | (bit == 26))

        with m.FSM():
            with m.State("WAIT"):
                with m.If(wait != 0):
                    m.d.sync += wait.eq(wait - 1)
                with m.Elif(index == n):
                    m.next = "DONE"
                with m.Elif(tick):
                    m.d.sync += quarter.eq(0)
                    m.next = "START"
            with m.State("START"), m.If(tick):
                # Quarter 1: SIOD falls with SIOC high; quarter 3: SIOC falls.
                m.d.sync += quarter.eq(quarter + 1)
                with m.Switch(quarter):
                    with m.Case(1):
                        m.d.sync += self.siod_o.eq(0)
                    with m.Case(3):
                        m.d.sync += [self.sioc.eq(0), bit.eq(0)]
                        m.next = "BITS"
            with m.State("BITS"), m.If(tick):
                m.d.sync += quarter.eq(quarter + 1)
                with m.Switch(quarter):
                    with m.Case(0):
                        m.d.sync += [self.siod_o.eq(current), self.siod_oe.eq(~dont_care)]
                    with m.Case(1):
                        m.d.sync += self.sioc.eq(1)
                    with m.Case(3):
                        m.d.sync += self.sioc.eq(0)
                        with m.If(bit == _BITS - 1):
                            m.next = "STOP"
                        with m.Else():
                            m.d.sync += bit.eq(bit + 1)
            with m.State("STOP"), m.If(tick):
                # Quarter 0: drive SIOD low; 1: SIOC rises; 3: SIOD rises with SIOC high.
                m.d.sync += quarter.eq(quarter + 1)
                with m.Switch(quarter):
                    with m.Case(0):
                        m.d.sync += [self.siod_o.eq(0), self.siod_oe.eq(1)]
                    with m.Case(1):
                        m.d.sync += self.sioc.eq(1)
                    with m.Case(3):
                        m.d.sync += [self.siod_o.eq(1), index.eq(index + 1)]
                        # Bus free for at least one bit time before the next START.
                        with m.If(wait_after):
                            m.d.sync += wait.eq(max(self.reset_wait, gap))
                        with m.Else():
                            m.d.sync += wait.eq(gap)
                        m.next = "WAIT"
            with m.State("DONE"):
                m.d.comb += self.done.eq(1)
        return m
