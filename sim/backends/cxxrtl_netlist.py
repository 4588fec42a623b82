"""What the compiled harnesses need to know about a generated CXXRTL model, read from its
C++ text: how to read each output port right after a clock edge, and how to commit it.

Both answers let the harness evaluate the model once per clock cycle instead of twice
(docs/backends.md, "How the compiled backends work"). When the text does not have the
expected shape, each function returns ``None`` and the harness uses CXXRTL's general
``step()`` loop, which is always correct.
"""

import re

from .base import BackendError

__all__ = [
    "OUTPUTS",
    "check_clocks",
    "commit_wires",
    "fast_commit",
    "mangle",
    "model_header",
    "output_sources",
    "with_wire_copies_inlined",
    "without_port_copies",
]

#: The output ports of the port list in docs/contract.md that the frame driver reads.
OUTPUTS = (
    "filtered__valid",
    "filtered__payload",
    "frame_done",
    "found",
    "proximity",
    "centroid_x",
    "centroid_leds",
    "motor_left",
    "motor_right",
)

_IDENT = re.compile(r"\b([pi]_\w+)\b(\.curr\b|\.next\b)?")


def mangle(name):
    """CXXRTL's C++ name of a simple identifier: ``p_`` and every ``_`` doubled."""
    return "p_" + name.replace("_", "__")


#: An edge detector on a wire of the model (``p_div.curr`` against ``p_div.next``), not on an
#: input port (``prev_p_clk``): a clock the design drives itself. Its name is the wire's, with
#: the bit's index when the clock is one bit of a wider register (``posedge_p_div_1`` reads
#: ``p_div.curr.slice<1>()``).
_WIRE_EDGE = re.compile(r"bool (?:pos|neg)edge_(\w+)\(\) const \{\s*return !?\w+\.curr\b")


def check_clocks(source, design, instead):
    """``BackendError`` when the model clocks flip-flops from one of its wires: a clock the
    design derives itself (a divider's register, ``ClockSignal("half")`` driven by logic).
    CXXRTL tests such an edge at the start of ``eval()``, before the edge that makes it, and
    never sees it (Yosys issue #3549): those flip-flops would hold their initial values, a
    wrong run. ``design`` names it, ``instead`` the backends to run it on."""
    clocks = _WIRE_EDGE.findall(source)
    if clocks:
        raise BackendError(
            f"{design} clocks flip-flops from a signal of its own ({clocks[0]} in the CXXRTL "
            f"model), whose edges CXXRTL misses (Yosys issue #3549): run it with --backend "
            f"{instead}"
        )


def _eval_span(source):
    start = source.index("::eval(performer *performer) {")
    return start, source.index("\n}\n", start)


def _eval_body(source):
    start, end = _eval_span(source)
    return source[start:end]


def _with_eval_body(source, body):
    start, end = _eval_span(source)
    return source[:start] + body + source[end:]


def _wire_widths(source):
    """``{C++ name: width}`` of the model's wires (its flip-flops)."""
    found = re.findall(r"^\t(?:/\*\w+\*/ )?wire<(\d+)> (\w+);$", source, re.MULTILINE)
    return {name: width for width, name in found}


def _edge_only_wires(source):
    """C++ names of the wires whose ``.next`` is assigned only inside ``if (posedge_p_clk)``
    blocks of eval(), i.e. the flip-flops of the one clock domain."""
    wires = set(_wire_widths(source))
    depth, posedge_depth = 0, None
    assigned = re.compile(r"\b(\w+)\.next\b")
    for line in _eval_body(source).splitlines()[1:]:
        stripped = line.strip()
        if posedge_depth is None:
            for name in assigned.findall(stripped):
                wires.discard(name)
        if stripped == "if (posedge_p_clk) {" and posedge_depth is None:
            posedge_depth = depth
        depth += stripped.count("{") - stripped.count("}")
        if posedge_depth is not None and depth <= posedge_depth:
            posedge_depth = None
    return wires


def output_sources(source, outputs=OUTPUTS):
    """``{port: C++ expression}`` computing each of ``outputs`` (port names, by default the
    frame driver's) from flip-flops only (members prefixed with ``t.``), or ``None`` when some
    output depends on an input or on anything this reader does not follow.

    CXXRTL computes an output port during eval(), i.e. from the state before the clock edge;
    the expression gives the state after the edge, read right after the edge's commit,
    without a second evaluation. An output that is a flip-flop, a copy of one (``p_out =
    p_ff.curr;``) or any expression of flip-flops and single-assignment temporaries (slices
    of a packed register) qualifies.
    """
    if re.search(r"\bnegedge_|bool posedge_(?!p_clk\b)", source):
        return None  # another clock or edge: not the one-domain design this reads
    if "prev_p_clk" not in source:
        return None  # no flip-flop on clk (a combinational design): no edge to hold the clock for
    body = _eval_body(source)
    flops = _edge_only_wires(source)
    # Whole-value assignments at the top level of eval(); a name assigned more than once, or
    # in part (`x.slice<..>() = ...`), is not followed.
    assigned = {}
    for name, expr in re.findall(r"^\t(\w+) = (.+);$", body, re.MULTILINE):
        assigned[name] = None if name in assigned else expr
    for name in re.findall(r"^\t(\w+)\.slice<", body, re.MULTILINE):
        assigned[name] = None

    def resolve(expr, depth=0):
        if depth > 32:
            return None
        parts, pos = [], 0
        for match in _IDENT.finditer(expr):
            name, member = match.groups()
            parts.append(expr[pos : match.start()])
            pos = match.end()
            if member == ".curr" and name in flops:
                parts.append(f"t.{name}.curr")
                continue
            if member is not None or assigned.get(name) is None:
                return None
            inner = resolve(assigned[name], depth + 1)
            if inner is None:
                return None
            parts.append(f"({inner})")
        parts.append(expr[pos:])
        return "".join(parts)

    sources = {}
    for port in outputs:
        mangled = mangle(port)
        if re.search(rf"/\*output\*/ wire<\d+> {mangled};", source):
            expr = f"{mangled}.curr" if mangled in flops else None
        else:
            expr = assigned.get(mangled)
        resolved = resolve(expr) if expr is not None else None
        if resolved is None:
            return None
        sources[port] = resolved
    return sources


def without_port_copies(source, outputs=OUTPUTS):
    """The model's source without the statements of eval() that copy a register (or a slice
    of a packed one) into an output port, for a harness that reads every output from its
    flip-flops (``output_sources``), which then never reads the port itself.

    Each such copy is a store per port on every clock that nothing reads (9 ports of a
    packed design cost about 10% of a cycle). Only top-level statements ``p_port = ...;``
    of a port that eval() reads nowhere else are removed; the waveform build keeps them.
    Returns ``source`` unchanged when ``output_sources`` does not apply.
    """
    if output_sources(source, outputs) is None:
        return source
    body = _eval_body(source)
    for port in outputs:
        name = mangle(port)
        if not re.search(rf"/\*output\*/ value<\d+> {name};", source):
            continue  # the port is the flip-flop itself: nothing is copied
        copies = re.findall(rf"^\t{name} = .*;\n", body, re.MULTILINE)
        if len(copies) == 1 and len(re.findall(rf"\b{name}\b", body)) == 1:
            body = body.replace(copies[0], "")
    return _with_eval_body(source, body)


def with_wire_copies_inlined(source):
    """The model's source with eval()'s whole-wire copies into locals replaced by the wire.

    CXXRTL copies a flip-flop into a local value when a submodule port it drives has several
    readers (``value<112> x; x = p_ff.curr;``): a copy of every word of a wide register on
    every clock. A flip-flop's ``.curr`` only changes in commit(), so reading it directly
    wherever the local is read is the same computation. Only locals of eval() assigned once,
    at its top level, from a wire of the same width are replaced."""
    body = _eval_body(source)
    wire_width = _wire_widths(source)
    for name, wire in re.findall(r"^\t(\w+) = (\w+)\.curr;$", body, re.MULTILINE):
        declaration = re.search(rf"^\tvalue<(\d+)> {name};\n", body, re.MULTILINE)
        assignments = re.findall(rf"^\s*{name}(?:\.slice<[^>]*>\(\))? = ", body, re.MULTILINE)
        if declaration is None or wire_width.get(wire) != declaration.group(1):
            continue
        if len(assignments) != 1:
            continue
        body = body.replace(declaration.group(0), "")
        body = body.replace(f"\t{name} = {wire}.curr;\n", "")
        body = re.sub(rf"\b{name}\b", f"{wire}.curr", body)
    return _with_eval_body(source, body)


def commit_wires(source):
    """C++ names of every wire the model's ``commit()`` commits, or ``None`` when it also
    commits something else (memories, submodules): then only CXXRTL's own ``commit()``
    will do."""
    start = source.find("bool commit(ObserverT &observer) {")
    if start < 0:
        return None
    body = source[start : source.index("return changed;", start)]
    statements = [s.strip() for s in body.splitlines()[1:] if s.strip()]
    declared = _wire_widths(source)
    wires = []
    for statement in statements:
        match = re.fullmatch(r"if \((\w+)\.commit\(observer\)\) changed = true;", statement)
        if match and match.group(1) in declared:
            wires.append(match.group(1))
        elif statement not in ("bool changed = false;", "prev_p_clk = p_clk;"):
            return None
    return wires


def fast_commit(source):
    """``FR_COMMIT``'s statements (``t.<wire>.curr = t.<wire>.next;`` for every wire), or
    ``None`` when only CXXRTL's ``commit()`` will do: it commits something else, or the
    design needs more than one evaluation to settle."""
    wires = commit_wires(source)
    converged = "bool converged = true;" in _eval_body(source) and "converged = false" not in source
    if wires is None or not converged:
        return None
    return " ".join(f"t.{w}.curr = t.{w}.next;" for w in wires)


def model_header(source):
    """The ``fr_model.h`` the CXXRTL harness includes.

    ``FR_OUT_<PORT>(t)`` reads an output of model ``t``. With ``FR_REGISTERED_OUTPUTS`` every
    output is read from flip-flops right after an edge (see ``output_sources``), and with
    ``FR_COMMIT(t)`` the harness commits by copying each wire's next value, which is all that
    CXXRTL's ``commit()`` does besides telling whether anything changed (the one-evaluation
    loop never asks: a flattened design without feedback settles in one evaluation)."""
    sources = output_sources(source)
    copies = fast_commit(source) if sources is not None else None
    lines = ["// Generated by fpga_robotics.sim.backends.cxxrtl_netlist from the model's source."]
    if sources is not None:
        lines.append("#define FR_REGISTERED_OUTPUTS 1")
    if copies is not None:
        lines.append(f"#define FR_COMMIT(t) do {{ {copies} }} while (0)")
    for port in OUTPUTS:
        expr = sources[port] if sources is not None else f"t.{mangle(port)}"
        lines.append(f"#define FR_OUT_{port.upper()}(t) ({expr})")
    return "\n".join(lines) + "\n"
