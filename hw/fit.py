"""Helper for packed registers: fields are loaded together with one ``Cat`` assignment."""

from amaranth import Cat, Const, Value

__all__ = ["fit"]


def fit(value, width):
    """``value`` cut or zero-extended to ``width`` bits, so that it fills exactly one field
    of a ``Cat`` that loads a packed register in one assignment.

    Why packed loads: the compiled simulators (CXXRTL, Verilator) compute the next value of
    every register on every clock. A register loaded field by field is split by Yosys into one
    computation per field, done every clock even when nothing loads; loaded whole, it costs
    one test while it holds."""
    value = Value.cast(value)
    return value[:width] if len(value) >= width else Cat(value, Const(0, width - len(value)))
