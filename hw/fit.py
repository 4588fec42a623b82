"""Helpers for packed registers: all fields of a register load together, in one assignment.

A packed register is one register with one load condition per branch: every branch
assigns all of it, so the fields that load together share one enable and the fields a branch
does not name keep their value through the same assignment. Yosys keeps it as one register
instead of splitting it into one per field, each with its own enable logic (why this shape
was chosen: docs/hardware.md).
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
                parts.append(whole[kept_from : field.offset])
                kept_from = None
            parts.append(fit(fields[name], field.width))
        elif kept_from is None:
            kept_from = field.offset
    if kept_from is not None:
        parts.append(whole[kept_from : layout.size])
    return view.eq(Cat(*parts))
