"""hw.fit.load: a packed register loaded in one assignment, given fields replaced (cut or
zero-extended), the others kept, checked by simulation against hand-computed bit patterns."""

import pytest
from amaranth import Elaboratable, Module, Signal
from amaranth.lib import data
from hwsim import run_testbench

from fpga_robotics.hw.fit import load

LAYOUT = data.StructLayout({"a": 3, "b": 4, "c": 2, "d": 5})  # a at 0, b at 3, c at 7, d at 9


class _Loader(Elaboratable):
    def __init__(self):
        self.reg = Signal(LAYOUT, init={"a": 0b101, "b": 0b1100, "c": 0b10, "d": 0b10011})
        self.sel = Signal(2)

    def elaborate(self, platform):
        m = Module()
        with m.Switch(self.sel):
            with m.Case(1):
                m.d.sync += load(self.reg, b=0b11111)  # cut to 4 bits
            with m.Case(2):
                m.d.sync += load(self.reg, a=0, d=1)  # b and c kept as one slice
            with m.Case(3):
                m.d.sync += load(self.reg, a=7, b=0, c=1, d=31)
        return m


def test_given_fields_load_and_the_others_keep_their_value():
    dut = _Loader()
    seen = []

    async def bench(ctx):
        for sel in (0, 1, 2, 3):
            ctx.set(dut.sel, sel)
            await ctx.tick()
            seen.append(ctx.get(dut.reg.as_value()))

    run_testbench(dut, bench, watchdog=20)

    def word(a, b, c, d):
        return a | b << 3 | c << 7 | d << 9

    start = word(0b101, 0b1100, 0b10, 0b10011)
    assert seen == [
        start,
        word(0b101, 0b1111, 0b10, 0b10011),
        word(0, 0b1111, 0b10, 1),
        word(7, 0, 1, 31),
    ]


def test_unknown_field_is_an_error():
    with pytest.raises(ValueError, match="no field e"):
        load(Signal(LAYOUT), e=1)
