"""Helpers for packed registers: all fields of a register load together, in one assignment.

Why packed loads: the compiled simulators (CXXRTL, Verilator) compute the next value of
every register on every clock. A register loaded field by field is split by Yosys into one
computation per field, done every clock even when nothing loads; loaded whole, it costs
one test while it holds.
"""

from amaranth import Cat, Const, Value

__all__ = ["fit", "load"]


def fit(value, width):
    """``value`` cut or zero-extended to ``width`` bits, so that it fills exactly one field
    of a ``Cat`` that loads a packed register in one assignment."""
    value = Value.cast(value)
    return value[:width] if len(value) >= width else Cat(value, Const(0, width - len(value)))


def load(view, **fields):
    """``view.eq(...)`` of a ``data.StructLayout`` view in one assignment: the named fields
    take the given values (each cut or zero-extended to its width), the others keep their
    current value (neighbouring kept fields as one slice)."""
    layout = view.shape()
    unknown = set(fields) - {name for name, _ in layout}
    if unknown:
        raise ValueError(f"no field {', '.join(sorted(unknown))} in {layout!r}")
    whole = Value.cast(view)
    parts, kept_from = [], None
    for name, field in sorted(layout, key=lambda item: item[1].offset):
        if name in fields:
            if kept_from is not None:
                parts.append(whole[kept_from:field.offset])
                kept_from = None
            parts.append(fit(fields[name], field.width))
        elif kept_from is None:
            kept_from = field.offset
    if kept_from is not None:
        parts.append(whole[kept_from:layout.size])
    return view.eq(Cat(*parts))
