"""Initial values kept through ``mutate``: a mutant on a register's output keeps its start.

A design without a reset (a Verilog ``reg q = 2'b11;``, an FPGA's configuration values)
starts from its registers' initial values, which Yosys keeps as an ``init`` attribute on the
wire a flip-flop's ``Q`` drives. ``mutate -ctrl`` on such a ``Q`` bit rewires the flip-flop to
a new wire and drives the old one through the mutant's ``$mux`` (``A``: the register's own
value, ``Y``: the old wire), so the register bit itself has no initial value any more: it
starts at x, which a simulator resolves as it likes, and the netlist at ``mutsel = 0`` is no
longer the design. ``restore_inits`` gives each such new wire the initial value of the bit
its mux drives (through a chain of muxes when several mutants sit on one bit).
"""

import re

from .mutant_watch import module_cells, module_span

__all__ = ["restore_inits"]

#: A wire with the attributes before it: (attributes text, its options, name).
_WIRE = re.compile(r"((?:^  attribute .*\n)*)^  wire ((?:\S+ )*?)(\S+)$", re.MULTILINE)
_WIDTH = re.compile(r"\bwidth (\d+)")
_INIT = re.compile(r"^  attribute \\init (\d+)'([01xz]+)$", re.MULTILINE)
_BIT = re.compile(r"^(\S+) \[(\d+)\]$")


def _bit(signal, widths):
    """``(wire, index)`` of a 1-bit signal (``\\q [3]``, or a 1-bit wire), else None."""
    m = _BIT.match(signal)
    if m:
        return m.group(1), int(m.group(2))
    if widths.get(signal) == 1:
        return signal, 0
    return None


def restore_inits(rtlil, top):
    """``rtlil`` (Yosys's ``write_rtlil`` of module ``top`` after ``mutate``) with an ``init``
    attribute on every flip-flop output wire that ``mutate`` made, the value of the design
    bit it stands for."""
    begin, end = module_span(rtlil, top)
    body = rtlil[begin:end]
    widths, inits = {}, {}
    for attrs, options, name in _WIRE.findall(body):
        width = _WIDTH.search(options)
        widths[name] = int(width.group(1)) if width else 1
        m = _INIT.search(attrs)
        if m:
            bits = m.group(2).rjust(
                int(m.group(1)), m.group(2)[0] if m.group(2)[0] in "xz" else "0"
            )
            inits[name] = bits[::-1]  # index i is bit i
    driven_by_ff = set()
    muxes = []  # (A wire, Y (wire, index))
    for kind, conns in module_cells(body):
        if "Q" in conns and kind.startswith("$") and "ff" in kind:
            driven_by_ff.update(re.findall(r"\$auto\$mutate\S*", conns["Q"]))
        if kind == "$mux" and conns.get("A", "").startswith("$auto$mutate"):
            y = _bit(conns.get("Y", ""), widths)
            if y is not None and widths.get(conns["A"]) == 1:
                muxes.append((conns["A"], y))
    start = {}  # new wire -> its initial bit
    changed = True
    while changed:  # down a chain of muxes on one bit, from the design's wire to the register
        changed = False
        for a, (wire, index) in muxes:
            value = start.get(wire) if wire in start else inits.get(wire, "")[index : index + 1]
            if value in ("0", "1") and start.get(a) != value:
                start[a], changed = value, True
    edits = {a: v for a, v in start.items() if a in driven_by_ff and a not in inits}
    if not edits:
        return rtlil

    def add_init(m):
        attrs, _, name = m.groups()
        if name not in edits:
            return m.group(0)
        return f"{attrs}  attribute \\init 1'{edits[name]}\n{m.group(0)[len(attrs) :]}"

    return rtlil[:begin] + _WIRE.sub(add_init, body) + rtlil[end:]
