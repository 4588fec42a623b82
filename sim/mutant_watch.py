"""The mutant netlist's watch output: where each mutant first acts.

``mutate -ctrl`` puts each mutant in as a 1-bit ``$mux``: ``Y = (mutsel == k) ? B : A``,
``A`` the design's own value of the bit, ``B`` the faulty one (its inverse, a constant, an
XOR or XNOR with another bit). ``add_watch`` gives the netlist an output whose bit ``k - 1``
is ``A ^ B`` of mutant ``k``'s mux: high in a cycle where the fault would change the bit.

Run at ``mutsel = 0`` (the design itself), the watch tells for every mutant at once whether
it ever acts: a mutant whose bit never rises in a run behaves in that run exactly as the
design does, cycle for cycle (its mux gives ``A`` whichever way it is set, so every signal,
and the world they drive, stays the design's). The closed loop records the frame each bit
first rises in (fpga_robotics.loop.fork); a forked run skips a mutant whose bit never rose.
"""

import re

__all__ = ["WATCH_PORT", "add_watch", "module_cells", "module_span"]

#: The output of the mutant netlist that shows where each mutant acts.
WATCH_PORT = "mutinf"

_CELL = re.compile(r"^  cell (\S+) (\S+)\n(.*?)^  end\n", re.MULTILINE | re.DOTALL)
_CONNECT = re.compile(r"^    connect \\(\w+) (.+)$", re.MULTILINE)
_PORT_NUMBER = re.compile(r"^  wire (?:width \d+ )?(?:input|output|inout) (\d+) ", re.MULTILINE)


def module_cells(body):
    """The cells of a module's RTLIL ``body``: ``[(kind, {port: connected signal})]``."""
    return [(kind, dict(_CONNECT.findall(text))) for kind, _, text in _CELL.findall(body)]


def module_span(rtlil, top):
    """The span of module ``top`` in ``rtlil`` (start, end of its body before ``end``)."""
    start = re.search(rf"^module \\{re.escape(top)}$", rtlil, re.MULTILINE)
    if start is None:
        raise ValueError(f"no module {top} in the netlist")
    end = re.compile(r"^end$", re.MULTILINE).search(rtlil, start.end())
    return start.end(), end.start()


def add_watch(rtlil, top, select, count, port=WATCH_PORT):
    """``rtlil`` (Yosys's ``write_rtlil`` of module ``top`` after ``mutate -ctrl select``)
    with the output ``port``, ``count`` bits wide: bit ``k - 1`` high when mutant ``k``'s
    faulty value differs from the design's. A mutant whose mux is not found gets a bit tied
    high (it counts as acting from the start: its runs are made in full). Without mutants
    the output is one bit, tied low."""
    begin, end = module_span(rtlil, top)
    body = rtlil[begin:end]
    cells = module_cells(body)
    selects = {}  # the $eq's output wire -> mutant index
    for kind, conns in cells:
        if kind == "$eq" and conns.get("A") == f"\\{select}":
            value = conns.get("B", "")
            if re.fullmatch(r"\d+'[01]+", value):
                selects[conns["Y"]] = int(value.partition("'")[2], 2)
    faults = {}  # mutant index -> (A, B)
    for kind, conns in cells:
        if kind == "$mux" and conns.get("S") in selects:
            faults[selects[conns["S"]]] = (conns["A"], conns["B"])
    number = 1 + max((int(n) for n in _PORT_NUMBER.findall(body)), default=0)
    lines = [f"  wire width {max(count, 1)} output {number} \\{port}"]
    if count < 1:
        lines.append(f"  connect \\{port} 1'0")
    for k in range(1, count + 1):
        bit = f"\\{port} [{k - 1}]"
        if k not in faults:
            lines.append(f"  connect {bit} 1'1")
            continue
        a, b = faults[k]
        lines += [
            f"  cell $xor $fr_watch${k}",
            "    parameter \\A_SIGNED 0",
            "    parameter \\B_SIGNED 0",
            "    parameter \\A_WIDTH 1",
            "    parameter \\B_WIDTH 1",
            "    parameter \\Y_WIDTH 1",
            f"    connect \\A {a}",
            f"    connect \\B {b}",
            f"    connect \\Y {bit}",
            "  end",
        ]
    return rtlil[:end] + "\n".join(lines) + "\n" + rtlil[end:]
