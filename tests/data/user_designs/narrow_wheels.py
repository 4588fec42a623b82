"""Wheels narrower than the connector's 16 bits: constant commands, ``left`` and ``right``
DPS, on ``Out(signed(width))`` ports (``signed_wheels = false``: unsigned ones, refused)."""

from amaranth import Module, signed, unsigned
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class NarrowWheels(wiring.Component):
    """Constant wheel commands on narrow ports."""

    def __init__(
        self, width: int = 8, left: int = -100, right: int = 60, signed_wheels: bool = True
    ):
        self.left, self.right = left, right
        shape = signed(width) if signed_wheels else unsigned(width)
        super().__init__({"motor_left": Out(shape), "motor_right": Out(shape)})

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.motor_left.eq(self.left), self.motor_right.eq(self.right)]
        return m
