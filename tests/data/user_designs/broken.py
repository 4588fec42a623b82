"""Design references that must fail with one clear line (tests/test_user_designs.py)."""

from amaranth.lib import data, wiring
from amaranth.lib.wiring import Out


class NotAComponent:
    """A class, but no Amaranth component."""


#: Callable (a layout makes a view of a value), but neither a component class nor a function.
Stats = data.StructLayout({"count": 12, "seen": 1})


def raises(width: int = 4):
    raise ValueError(f"width {width} is not supported")


def returns_a_number():
    return 42


class Sized(wiring.Component):
    """A component with a typed parameter."""

    def __init__(self, width: int = 4):
        super().__init__({"motor_left": Out(width)})

    def elaborate(self, platform):
        from amaranth import Module

        return Module()
