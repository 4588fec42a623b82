"""Foreign Verilog designs on Verilator: any Verilog top with a port map (port_map.py,
docs/foreign.md) runs behind the frame API of every backend.

The design's ports are read from Verilator's JSON tree and checked against the map; then a
generated wrapper module gives the design the port list of docs/contract.md (renaming ports,
inverting an active-low reset, encoding the colour select, splitting the pixel payload,
extending the outputs) so that the Verilator backend's own harness drives it unchanged.
Outputs the map does not name are ``None`` in the ``FrameResult`` (``filtered`` too when the
design has no filtered stream); ``ForeignVerilatorBackend(fill_absent=True)`` gives 0 instead,
which the closed loop needs.

For real-clock timing (``ForeignDesign(..., pins=True)``, the Verilator pin backend) the
wrapper has the same ports where the map gives them (the pixel stream, colour select, result
strobe, the outputs it names) and passes the ports of ``[connectors.<kind>]`` through under
their own names.
"""

import contextlib
import ctypes
import hashlib
import json
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from ...hw.params import FollowTargetParams
from ...hw.pixel import COLOR_SELECT
from ..files import read_user_text
from ..processes import run_captured
from . import build_cache
from .base import BackendError, DesignBackend, FrameResult
from .comb_loops import combinational_loop
from .compiled import (
    _N_ARGS,
    _N_OUT,
    _STATUS,
    ABI_VERSION,
    HARNESS_DIR,
    LIBRARY_NAME,
    HarnessFrames,
    _address,
    _Library,
)
from .lifecycle import BuildPlan, digest, load_built, read_sources
from .port_map import OUTPUTS, PortMapError, check_connectors, check_widths, load_port_map
from .registered_outputs import REGISTERED_ANALYSIS, outputs_registered
from .toolchain import find_compiler, find_make, run_tool, verilator_root, verilator_version
from .verilator import CXX_FLAGS, MAKE_FLAGS, VERILATOR_FLAGS
from .verilog_cxxrtl import DESIGN_DIR
from .verilog_params import VerilogOverrides

__all__ = [
    "ForeignDesign",
    "ForeignVerilatorBackend",
    "design_parameters",
    "design_ports",
    "include_dirs",
    "pin_ports",
    "refuse_ignored_defines",
    "verilog_includes",
    "verilog_layout",
    "watch_chunks",
    "wrapper_verilog",
]

WRAPPER = "fr_foreign_top"
#: The wrapper's own port names (docs/contract.md): no connector port may take one.
_WRAPPER_PORTS = (
    "clk",
    "rst",
    "pixels__valid",
    "pixels__payload",
    "color_sel",
    "filtered__valid",
    "filtered__payload",
    "frame_done",
    *OUTPUTS,
)
_HARNESS_FILES = (
    "verilator_harness.cpp",
    "frame_driver.h",
    "verilator_clock.h",
    "verilator_fatal.h",
)
_LINT_FLAGS = ("-Wno-fatal", "-Wno-lint", "-Wno-style")


class ForeignDesign:
    """Verilog files and their port map (a path or a ``PortMap``), for frames of ``params``
    (``FollowTargetParams``, default 160x120).

    ``pins=True``: for the pin backend (real-clock timing), with the map's connectors;
    ``connector_kinds`` (kind -> {pin: (direction, max width)}) checks them
    (``port_map.check_connectors``). Without ``pins`` a map with connectors is refused: the
    frame backend drives no connector. A combinational loop is refused (``refuse_loops``):
    no model of it settles. ``overrides`` (``VerilogOverrides``): the parameters of the top
    and the `define macros it is built with.
    """

    def __init__(
        self,
        files,
        port_map,
        params=None,
        *,
        pins=False,
        connector_kinds=None,
        frame_size=None,
        refuse_loops=True,
        overrides=None,
    ):
        #: The design's parameters and `define macros (``VerilogOverrides``).
        self.overrides = overrides or VerilogOverrides()
        self.params = params if params is not None else FollowTargetParams()
        #: (width, height) of the frames the wrapper addresses and ends: ``params``' unless
        #: ``frame_size`` says otherwise (a unit judge's frames, smaller than any camera's).
        self.frame_size = frame_size or (self.params.width, self.params.height)
        if isinstance(files, (str, os.PathLike)):
            files = [files]
        self.files = [Path(f) for f in files]
        if not self.files:
            raise PortMapError("no Verilog file given")
        for f in self.files:
            try:
                read_user_text(f, any_bytes=True)
            except OSError as exc:
                raise PortMapError(
                    f"cannot read the Verilog file {f}: {getattr(exc, 'strerror', None) or exc}"
                ) from None
        #: The files (``sources``) and those named by `include or a $readmemh/$readmemb,
        #: found next to the including file or a listed one (``includes``), by their paths
        #: from the folder that holds them all: copied so into the build folder (an include
        #: of "../inc/defs.vh" finds its file) and part of the build's cache key.
        #: ``data_paths``: where each data file is, for Verilator (``verilator_text``).
        self.data_paths = {}
        self.sources, self.includes = verilog_layout(self.files, self.data_paths)
        if len(self.sources) != len(self.files):
            raise PortMapError("a Verilog file is listed twice")
        _refuse_unused_defines(self.overrides, [*self.sources.values(), *self.includes.values()])
        self.port_map = (
            port_map if not isinstance(port_map, (str, os.PathLike)) else load_port_map(port_map)
        )
        pm = self.port_map
        if not pins and (pm.connectors or pm.extra_outputs or not pm.has_pixels):
            what = (
                f"binds connectors ([connectors.{next(iter(pm.connectors))}])"
                if pm.connectors
                else "records [extra_outputs]"
                if pm.extra_outputs
                else "has no pixel stream"
            )
            raise PortMapError(
                f"port map: {pm.top}'s map {what}: the design runs in real-clock "
                'timing (sim.timing = "real_clock", on the cxxrtl or verilator pin backend) '
                "with the scenario's [[robot.sensors]]"
            )
        passed = {
            **pm.connector_ports(),
            **{port: f"extra_outputs.{name}" for name, port in pm.extra_outputs.items()},
        }
        clash = sorted(set(passed) & set(_WRAPPER_PORTS))
        if clash:
            raise PortMapError(
                f"port map: {passed[clash[0]]}: the port name "
                f"{clash[0]!r} is reserved for the wrapper's own ports; rename "
                "it in the design"
            )
        self.pins = pins
        self.ports = design_ports(self.sources, self.port_map.top, self.includes, self.overrides)
        check_widths(self.port_map, self.ports, self.frame_size[0] * self.frame_size[1])
        if connector_kinds is not None:
            check_connectors(self.port_map, self.ports, connector_kinds)
        for key in ("motor_left", "motor_right"):
            out = self.port_map.outputs.get(key)
            if out is not None and self.ports[out.port][1] > 16:
                raise PortMapError(f"port map: outputs.{key} is wider than 16 bits")
        if (
            "found" in self.port_map.outputs
            and self.ports[self.port_map.outputs["found"].port][1] != 1
        ):
            raise PortMapError("port map: outputs.found must be a 1-bit port")
        if refuse_loops:
            _refuse_loop(self.sources, self.port_map.top, self.includes, self.overrides)
        self.wrapper = wrapper_verilog(
            self.port_map, self.ports, *self.frame_size, pins=pins, overrides=self.overrides
        )

    def registered_outputs(self):
        """Whether no output of the wrapper around the design depends on an input but
        through a flip-flop (sim.backends.registered_outputs: False when Yosys cannot say):
        the Verilator harnesses then evaluate once per clock edge."""
        wrapper = wrapper_verilog(
            self.port_map,
            self.ports,
            *self.frame_size,
            pins=self.pins,
            runtime_dpi=False,
            overrides=self.overrides,
        )
        return outputs_registered({"fr_wrapper.v": wrapper, **self.sources}, WRAPPER, self.includes)

    def verilator_text(self, text):
        """``text`` with each data file its $readmemh/$readmemb names at its absolute path:
        Verilator's model reads the file when it starts, relative to the process's folder."""
        return _READMEM.sub(
            lambda m: (
                f'{m[1]}"{self.data_paths[m[2]].as_posix()}"' if m[2] in self.data_paths else m[0]
            ),
            text,
        )

    def digest(self):
        h = hashlib.sha256()
        for name in sorted(self.data_paths):  # where the Verilator model reads them
            h.update(b"data\0" + name.encode() + b"\0" + str(self.data_paths[name]).encode())
        for name in sorted(self.sources):
            h.update(name.encode() + b"\0" + self.sources[name].encode() + b"\0")
        for name in sorted(self.includes):
            h.update(b"include\0" + name.encode() + b"\0" + self.includes[name].encode() + b"\0")
        h.update(self.wrapper.encode())
        return h.hexdigest()


#: Compiler directives: any other `NAME is a use of the macro NAME.
_DIRECTIVES = frozenset(
    [
        "define",
        "undef",
        "ifdef",
        "ifndef",
        "elsif",
        "else",
        "endif",
        "include",
        "timescale",
        "default_nettype",
        "resetall",
        "celldefine",
        "endcelldefine",
        "line",
        "begin_keywords",
        "end_keywords",
        "pragma",
        "unconnected_drive",
        "nounconnected_drive",
        "undefineall",
        "__FILE__",
        "__LINE__",
    ]
)


def _refuse_unused_defines(overrides, texts):
    """A ``PortMapError`` for a ``--define`` no file of the design uses (a misspelt name
    would be defined for nothing and the design built with its own default)."""
    used = set()
    for text in texts:
        text = _COMMENTS.sub("", text)
        used.update(re.findall(r"`(?:ifdef|ifndef|elsif|undef)\s+(\w+)", text))
        used.update(n for n in re.findall(r"`(\w+)", text) if n not in _DIRECTIVES)
    unused = [name for name, _ in overrides.defines if name not in used]
    if unused:
        known = ", ".join(sorted(used)) or "none"
        raise PortMapError(
            f"--define {unused[0]}: no file of the design uses the macro `{unused[0]} (the "
            f"macros it uses: {known})"
        )


def refuse_ignored_defines(sources, includes, overrides, extra=()):
    """A ``PortMapError`` for a ``--define`` that would change nothing: one no file of the
    design uses, or one the design's own `define replaces (read after ours), as Verilator's
    preprocessor finds it, with the macros ``extra`` (``("FORMAL",)``) defined as the tool
    that reads the design defines them. For the flows that read the design without
    elaborating it in Verilator (``formal``), which checks both when it reads the ports."""
    _refuse_unused_defines(overrides, [*sources.values(), *(includes or {}).values()])
    if not overrides.defines:
        return
    root = verilator_root()
    with tempfile.TemporaryDirectory(prefix="fr-foreign-") as tmp:
        paths = _write_sources(tmp, overrides.with_defines(sources), includes)
        _, output = run_captured(
            [
                root / "bin" / "verilator",
                "-E",
                "-P",
                *(f"+define+{name}" for name in extra),
                *include_dirs(tmp, sources, includes or {}),
                *paths,
            ],
            cwd=tmp,
            env=dict(os.environ, VERILATOR_ROOT=str(root)),
        )
        _refuse_redefined(overrides, _unprefixed(output, tmp), sources, includes)


def _refuse_loop(sources, top, includes, overrides):
    loop = combinational_loop(sources, top, includes, overrides)
    if loop is not None:
        wires, where = loop
        through = f" through {', '.join(wires)}" if wires else ""
        raise PortMapError(
            f"design {top} has a combinational loop{through} ({where}): logic that feeds "
            "its own input without a flip-flop never settles; break the loop with a "
            "register (always @(posedge clk))"
        )


_INCLUDE = re.compile(r'`include\s+"([^"]+)"')
#: A memory's data file named by a literal path: ``$readmemh("table.hex", mem)``.
_READMEM = re.compile(r'(\$readmem[hb]\s*\(\s*)"([^"]+)"')
_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*", re.DOTALL)


def verilog_includes(files, data_paths=None):
    """The included and data files of ``verilog_layout``: ``{path: text}``."""
    return verilog_layout(files, data_paths)[1]


def verilog_layout(files, data_paths=None):
    """``(sources, includes)``: the text of each of ``files`` and of every file they `include
    (recursively) that is found relative to the including file's folder or a listed file's
    folder, and of every data file a $readmemh/$readmemb names (found there too, or in the
    current folder, where Verilator and Yosys look themselves), each by its path from the
    folder that holds them all (their layout kept, so that an include of "../inc/defs.vh"
    finds its file where the tools look; a data file beside the file that reads it). An
    include not found is left to Verilator to report, a data file not found is a
    ``PortMapError``. ``data_paths`` (a dict) gets each data file's path by its name."""
    files = [Path(os.path.abspath(f)) for f in files]
    folders = [f.parent for f in files]
    texts, data = {}, {}  # absolute path -> text; data file's place -> its path
    todo = list(files)
    while todo:
        path = todo.pop(0)
        if path in texts:
            continue
        try:
            texts[path] = text = read_user_text(path, any_bytes=True)
        except OSError:
            if path in files:
                raise
            raise PortMapError(f"cannot read the included file {path}") from None
        for _, name in _READMEM.findall(_COMMENTS.sub("", text)):
            if Path(name).is_absolute() or ".." in Path(name).parts:
                continue
            candidate = next(
                (b / name for b in (path.parent, *folders, Path.cwd()) if (b / name).is_file()),
                None,
            )
            if candidate is None:
                raise PortMapError(
                    f"{path.name} reads the data file {name!r} ($readmem), which is not next "
                    f"to it, next to a listed file, nor in the current folder: put it beside "
                    f"{path.name}"
                )
            data.setdefault(path.parent / name, candidate)
            if data_paths is not None:
                data_paths.setdefault(name, candidate.resolve())
        for name in _INCLUDE.findall(text):
            if Path(name).is_absolute():
                continue
            found = next((b / name for b in (path.parent, *folders) if (b / name).is_file()), None)
            if found is not None:
                todo.append(Path(os.path.normpath(found)))
    places = [*texts, *data]
    root = Path(os.path.commonpath([p.parent for p in places]))
    sources = {p.relative_to(root).as_posix(): texts[p] for p in files}
    includes = {p.relative_to(root).as_posix(): t for p, t in texts.items() if p not in files}
    for place, path in data.items():
        includes[place.relative_to(root).as_posix()] = _read_included(path)
    return sources, includes


def include_dirs(directory, *files):
    """Verilator's ``-I`` options for ``files`` (dicts by path, the sources first) written
    under ``directory / DESIGN_DIR``: the folder of each, where an include next to a listed
    file, or next to the included file that includes it, is found."""
    folders = dict.fromkeys(Path(name).parent for names in files for name in names)
    return [f"-I{Path(directory) / DESIGN_DIR / folder}" for folder in folders]


def _read_included(path):
    try:
        return read_user_text(path, any_bytes=True)
    except OSError as exc:
        raise PortMapError(
            f"cannot read the included file {path}: {getattr(exc, 'strerror', None) or exc}"
        ) from None


def _write_sources(directory, sources, includes=None):
    for name, text in (includes or {}).items():
        path = Path(directory) / DESIGN_DIR / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    paths = []
    for name, text in sources.items():
        path = Path(directory) / DESIGN_DIR / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        paths.append(path)
    return paths


def _dtypes(node, acc):
    if isinstance(node, dict):
        if "DTYPE" in node.get("type", "") and "addr" in node:
            acc[node["addr"]] = node
        for value in node.values():
            _dtypes(value, acc)
    elif isinstance(node, list):
        for value in node:
            _dtypes(value, acc)
    return acc


def design_ports(sources, top, includes=None, overrides=None):
    """Ports of module ``top`` as Verilator elaborates it (with ``overrides``, a
    ``VerilogOverrides``): name -> (direction, width, signed)."""
    ports, _ = _elaborate(sources, top, includes, overrides or VerilogOverrides())
    return ports


def design_parameters(sources, top, includes=None, overrides=None):
    """The names of the parameters of module ``top`` a ``--param`` may set, in order."""
    return _elaborate(sources, top, includes, overrides or VerilogOverrides())[1]


def _elaborate(sources, top, includes, overrides):
    root = verilator_root()
    with tempfile.TemporaryDirectory(prefix="fr-foreign-") as tmp:
        paths = _write_sources(tmp, overrides.with_defines(sources), includes)
        code, output = run_captured(
            [
                root / "bin" / "verilator",
                "--json-only",
                *_LINT_FLAGS,
                "--top-module",
                top,
                *overrides.verilator_flags(),
                *include_dirs(tmp, sources, includes or {}),
                "--Mdir",
                Path(tmp) / "obj",
                *paths,
            ],
            cwd=tmp,
            env=dict(os.environ, VERILATOR_ROOT=str(root)),
        )
        _refuse_redefined(overrides, _unprefixed(output, tmp), sources, includes)
        if code != 0:
            errors = [line for line in output.splitlines() if line.startswith("%Error")]
            first = (errors or output.strip().splitlines() or ["(no output)"])[0]
            if "Parameters from the command line were not found" in first:
                _refuse_parameters(sources, top, includes, overrides)
            first = _unprefixed(first, tmp)
            if _read_hint(first):
                first = first.rstrip(".") + _read_hint(first)
            # Named as the step it is: the CXXRTL backend reads the ports with Verilator too.
            raise PortMapError(
                f"Verilator cannot read the design (top {top}) for its ports, which every "
                f"backend reads first: {first}"
            )
        tree = json.loads(next((Path(tmp) / "obj").glob("*.tree.json")).read_text())
    dtypes = _dtypes(tree, {})
    module = next(
        (m for m in tree["modulesp"] if m.get("origName", m["name"]) == top or m["name"] == top),
        None,
    )
    if module is None:
        raise PortMapError(f"Verilator found no module {top}")
    ports = {}
    for var in module.get("stmtsp", []):
        if var.get("type") != "VAR" or not var.get("isPrimaryIO"):
            continue
        direction = {"INPUT": "input", "OUTPUT": "output"}.get(var.get("direction"))
        if direction is None:
            raise PortMapError(
                f"port {var['name']!r} of {top} is {var.get('direction')}: only "
                "inputs and outputs are supported"
            )
        dtype = dtypes.get(var.get("dtypep"), {})
        rng = dtype.get("range")
        width = 1
        if rng:
            left, right = (int(x) for x in rng.split(":"))
            width = abs(left - right) + 1
        name = var.get("verilogName", var["name"])
        ports[name] = (direction, width, bool(dtype.get("signed")))
    parameters = [
        var.get("verilogName", var["name"])
        for var in module.get("stmtsp", [])
        if var.get("type") == "VAR" and var.get("isGParam")
    ]
    return ports, parameters


#: Verilator's warning for a `define of a name already defined with another value.
_REDEFINED = re.compile(
    r"%Warning-REDEFMACRO: (\S+?):(\d+):\d+: Redefining existing define: '(\w+)'"
)


def _unprefixed(text, tmp):
    """Verilator's ``text`` with the design's files named by their own paths, not by their
    copies' in the temporary folder ``tmp``."""
    return text.replace(str(Path(tmp) / DESIGN_DIR) + "/", "")


def _refuse_redefined(overrides, output, sources, includes):
    """A ``PortMapError`` for a ``--define`` the design's own `define of the same name
    overrides (its file read after ours): the value given would be dropped without a word.
    ``output``: Verilator's (``_unprefixed``); ``sources`` and ``includes``: the design's
    files by path, to find the `define's line (Verilator names the line after it)."""
    texts = {**(includes or {}), **sources}
    given = {name for name, _ in overrides.defines}
    for where, after, name in _REDEFINED.findall(output):
        if name not in given:
            continue
        where = os.path.normpath(where)
        lines = texts.get(where, "").splitlines()[: int(after)]
        line = next(
            (
                n
                for n in range(len(lines), 0, -1)
                if re.search(rf"`define\s+{name}\b", lines[n - 1])
            ),
            int(after),
        )
        raise PortMapError(
            f"--define {name}: the design's own `define {name} ({where}:{line}) replaces "
            f"the value given; put that `define between `ifndef {name} and `endif so that "
            "--define can set it"
        )


def _refuse_parameters(sources, top, includes, overrides):
    """A ``PortMapError`` naming the ``--param`` names ``top`` does not have, and those it has."""
    plain = VerilogOverrides((), overrides.defines)
    known = _elaborate(sources, top, includes, plain)[1]
    unknown = [n for n, _ in overrides.parameters if n not in known]
    raise PortMapError(
        f"the design {top} has no parameter {unknown[0]!r} to set (its parameters: "
        f"{', '.join(known) if known else 'none'})"
    )


def _read_hint(error):
    """What to do about Verilator's first ``error`` on reading the design, when it says."""
    if "Cannot find include file" in error:
        return "; put that file next to the file that includes it or next to a listed file"
    if "Cannot find file containing module" in error:
        return "; list the file that defines that module with the design's files"
    if "--top-module" in error:
        return "; the port map's top must name a module of the design's files"
    return ""


def wrapper_verilog(pm, ports, width, height, pins=False, runtime_dpi=True, overrides=None):
    """A module ``fr_foreign_top`` with the ports of docs/contract.md around ``pm.top``, for
    frames of ``width`` x ``height``.

    ``pins=True`` (the pin backend): only the ports the map gives (no pixel stream, strobe
    or colour select without ``pixels``, no absent outputs), the connector ports passed
    through under their own names, ``[runtime]`` inputs too (the pin backend holds them at
    their values, ``HostPins.set_runtime``). ``runtime_dpi=False``: the frames' ``[runtime]``
    registers keep their value instead of loading it through DPI (the same wrapper for
    Yosys, which reads no DPI: ``registered_outputs``). ``overrides`` (``VerilogOverrides``):
    the top's parameters, set on its instance, and the `define lines, first: the wrapper is
    the first file every tool reads."""
    overrides = overrides or VerilogOverrides()
    conns = [f".{pm.clock}(clk)"]
    if pm.reset:
        conns.append(f".{pm.reset}({'~rst' if pm.reset_active_low else 'rst'})")
    if pm.has_pixels:
        conns.append(f".{pm.valid}(pixels__valid)")
    body = []
    last = width * height - 1
    if pm.has_pixels and (pm.style == "framebuffer" or pm.after_cycles):
        # The pixel's linear address, counted from the frame's first pixel (flag bit 12).
        aw = max(1, last.bit_length())
        body.append(
            f"  reg [{aw - 1}:0] fr_next;\n"
            f"  wire [{aw - 1}:0] fr_addr = pixels__payload[12] ? {aw}'d0 : fr_next;\n"
            f"  wire fr_end = pixels__valid && fr_addr == {aw}'d{last};\n"
            "  always @(posedge clk)\n"
            f"    if (rst) fr_next <= {aw}'d0;\n"
            f"    else if (pixels__valid) fr_next <= fr_addr + {aw}'d1;"
        )
    if not pm.has_pixels:
        pass
    elif pm.style == "framebuffer":
        conns.append(f".{pm.data}(pixels__payload[11:0])")
        conns.append(f".{pm.address}(fr_addr)")
        if pm.new_frame:
            body.append(
                "  reg fr_new_frame;\n  always @(posedge clk) fr_new_frame <= !rst && fr_end;"
            )
            conns.append(f".{pm.new_frame}(fr_new_frame)")
    elif pm.payload:
        conns.append(f".{pm.payload}(pixels__payload)")
    else:
        conns.append(f".{pm.data}(pixels__payload[11:0])")
        if pm.first:
            conns.append(f".{pm.first}(pixels__payload[12])")
        if pm.last:
            conns.append(f".{pm.last}(pixels__payload[13])")
    if pm.color_port:
        width = ports[pm.color_port][1]
        cases = "\n".join(
            f"      3'd{code_of}: fr_sel = {width}'d{code};"
            for code_of, code in sorted((COLOR_SELECT[n], c) for n, c in pm.color_codes.items())
        )
        body.append(
            f"  reg [{width - 1}:0] fr_sel;\n  always @* begin\n    case (color_sel)\n"
            f"{cases}\n      default: fr_sel = {width}'d0;\n    endcase\n  end"
        )
        conns.append(f".{pm.color_port}(fr_sel)")
    # The pin loop reads the per-frame outputs when frame_done rises; the frame harness reads
    # them `latency` edges after it (1 with after_cycles): on pins frame_done is delayed by
    # as much, so that both read the same cycle's values.
    delay = (pm.latency if pm.strobe else 1) if pins and pm.has_pixels else 0
    done = "fr_result" if delay else "frame_done"
    if delay:
        body.append(
            "  wire fr_result;\n  reg [31:0] fr_read;\n"
            "  always @(posedge clk)\n"
            "    if (rst) fr_read <= 32'd0;\n"
            f"    else if (fr_result) fr_read <= 32'd{delay};\n"
            "    else if (fr_read != 32'd0) fr_read <= fr_read - 32'd1;\n"
            "  assign frame_done = fr_read == 32'd1;"
        )
    if pm.strobe:
        conns.append(f".{pm.strobe}({done})")
    elif pm.has_pixels:
        # frame_done one cycle before the outputs are read (the harness reads them one edge
        # later: the backend's latency is 1), after_cycles edges after the last pixel's.
        body.append(
            "  reg [31:0] fr_wait;\n"
            "  always @(posedge clk)\n"
            "    if (rst) fr_wait <= 32'd0;\n"
            f"    else if (fr_end) fr_wait <= 32'd{pm.after_cycles};\n"
            "    else if (fr_wait != 32'd0) fr_wait <= fr_wait - 32'd1;\n"
            f"  assign {done} = fr_wait == 32'd1;"
        )
    decls, header = [], []
    for key, (out_width, _) in (
        ("found", (1, 0)),
        ("proximity", (16, 0)),
        ("centroid_x", (16, 0)),
        ("centroid_leds", (16, 0)),
        ("motor_left", (16, 0)),
        ("motor_right", (16, 0)),
    ):
        out = pm.outputs.get(key)
        if out is None:
            if not pins:
                body.append(f"  assign {key} = {out_width}'d0;")
            continue
        header.append(f"output [{out_width - 1}:0] {key}")
        width = ports[out.port][1]
        decls.append(f"  wire [{width - 1}:0] fr_{key};")
        conns.append(f".{out.port}(fr_{key})")
        if width == out_width:
            body.append(f"  assign {key} = fr_{key};")
        else:
            fill = (
                f"{{{out_width - width}{{fr_{key}[{width - 1}]}}}}"
                if out.signed
                else f"{out_width - width}'d0"
            )
            body.append(f"  assign {key} = {{{fill}, fr_{key}}};")
    for name, value in pm.constants.items():
        conns.append(f".{name}({ports[name][1]}'d{value})")
    if pm.runtime and not pins and runtime_dpi:
        # Held in registers loaded every clock from the host's values (fr_foreign_set_runtime,
        # in the hooks compiled with the design), so a new value acts from the next edge.
        body.append('  import "DPI-C" function int fr_runtime_value(input int index);')
    for index, name in enumerate(() if pins else pm.runtime):
        width = ports[name][1]
        body.append(
            f"  reg [{width - 1}:0] fr_rt_{index};\n"
            + (  # without DPI (for Yosys's reading): a register all the same
                f"  always @(posedge clk) fr_rt_{index} <= fr_runtime_value({index});"
                if runtime_dpi
                else f"  always @(posedge clk) fr_rt_{index} <= fr_rt_{index};"
            )
        )
        conns.append(f".{name}(fr_rt_{index})")
    if pm.watch:
        body.append(_watch_verilog(ports[pm.watch][1], declare=pins))
        conns.append(f".{pm.watch}(fr_watch)")
    if pm.filtered_valid:
        conns += [
            f".{pm.filtered_valid}(filtered__valid)",
            f".{pm.filtered_payload}(filtered__payload)",
        ]
    elif not pins:
        body.append("  assign filtered__valid = 1'b0;\n  assign filtered__payload = 14'd0;")
    conn_text = ",\n    ".join(conns)
    if pins:
        return overrides.define_text() + _pin_wrapper(
            pm, ports, header, decls, body, conns, overrides.instance()
        )
    watch_port = f",\n  output [{ports[pm.watch][1] - 1}:0] fr_watch_any" if pm.watch else ""
    instance = overrides.instance()
    return f"""{overrides.define_text()}// Generated by fpga_robotics.sim.backends.foreign: {pm.top} with the ports of
// docs/contract.md, for the Verilator harness.
module {WRAPPER} (
  input clk, input rst,
  input pixels__valid, input [13:0] pixels__payload, input [2:0] color_sel,
  output filtered__valid, output [13:0] filtered__payload, output frame_done,
  output found, output [15:0] proximity, output [15:0] centroid_x,
  output [15:0] centroid_leds, output [15:0] motor_left, output [15:0] motor_right{watch_port}
);
{chr(10).join(decls)}
{chr(10).join(body)}
  {pm.top} {instance}fr_design (
    {conn_text}
  );
endmodule
"""


def _watch_verilog(width, declare=False):
    """The watch of ``[watch]``: ``fr_watch_any``, the bits of the watched output that were
    high at a clock edge since the last reset (the values the edge samples, the reset's own
    edge included) or are high now, where the harness reads the outputs between edges. The
    host reads it once a frame (``watch_risen``). ``declare``: ``fr_watch_any`` is a wire of
    the wrapper, not its output (the pin wrapper gives it out in ``watch_chunks``)."""
    return (
        (f"  wire [{width - 1}:0] fr_watch_any;\n" if declare else "")
        + f"  wire [{width - 1}:0] fr_watch;\n"
        f"  reg [{width - 1}:0] fr_watch_seen = {width}'d0;\n"
        "  always @(posedge clk)\n"
        "    fr_watch_seen <= rst ? fr_watch : fr_watch_seen | fr_watch;\n"
        "  assign fr_watch_any = fr_watch_seen | fr_watch;"
    )


def _pin_wrapper(pm, ports, outputs, decls, body, conns, instance):
    header = ["input clk", "input rst"]
    if pm.has_pixels:
        header += [
            "input pixels__valid",
            "input [13:0] pixels__payload",
            "input [2:0] color_sel",
            "output frame_done",
        ]
    if pm.filtered_valid:
        header += ["output filtered__valid", "output [13:0] filtered__payload"]
    header += outputs
    for name, low, width in watch_chunks(pm, ports):
        header.append(f"output [{width - 1}:0] {name}")
        body.append(f"  assign {name} = fr_watch_any[{low + width - 1}:{low}];")
    for port in (*pm.connector_ports(), *pm.extra_outputs.values(), *pm.runtime):
        direction, width, signed = ports[port]
        # Escaped identifiers: a port may have any name the design's Verilog gives it.
        header.append(f"{direction} {'signed ' if signed else ''}[{width - 1}:0] \\{port} ")
        conns.append(f".\\{port} (\\{port} )")
    ports_text = ",\n  ".join(header)
    conn_text = ",\n    ".join(conns)
    return f"""// Generated by fpga_robotics.sim.backends.foreign: {pm.top} with the ports of
// docs/contract.md and its connector ports, for the Verilator pin harness.
module {WRAPPER} (
  {ports_text}
);
{chr(10).join(decls)}
{chr(10).join(body)}
  {pm.top} {instance}fr_design (
    {conn_text}
  );
endmodule
"""


def watch_chunks(pm, ports):
    """The pin wrapper's outputs that give ``fr_watch_any`` (``[watch]``): ``[(name, lowest
    bit, width)]``, 64 bits each at most (a pin port's widest), none without a watch."""
    if not pm.watch:
        return []
    width = ports[pm.watch][1]
    return [
        (f"fr_watch_any_{i}", low, min(64, width - low))
        for i, low in enumerate(range(0, width, 64))
    ]


def pin_ports(design):
    """The pin wrapper's ports of a ``ForeignDesign(pins=True)``: name -> (direction ``in`` or
    ``out``, width, signed), clock and reset left out (the pin driver's own)."""
    pm, ports = design.port_map, {}
    if pm.has_pixels:
        ports.update(
            pixels__valid=("in", 1, False),
            pixels__payload=("in", 14, False),
            color_sel=("in", 3, False),
            frame_done=("out", 1, False),
        )
    if pm.filtered_valid:
        ports.update(filtered__valid=("out", 1, False), filtered__payload=("out", 14, False))
    for key in OUTPUTS:
        if key in pm.outputs:
            # The contract's wheel speeds are signed 16 bits; the other outputs unsigned.
            ports[key] = ("out", 1 if key == "found" else 16, key.startswith("motor_"))
    for port in (*pm.connector_ports(), *pm.extra_outputs.values(), *pm.runtime):
        direction, width, signed = design.ports[port]
        ports[port] = ("in" if direction == "input" else "out", width, signed)
    for name, _, width in watch_chunks(pm, design.ports):
        ports[name] = ("out", width, False)
    return ports


#: Compiled with the design: $stop, $fatal and $finish record where they were called instead
#: of aborting the process (Verilator's default for $stop and $fatal); the backend raises
#: ``BackendError`` after the frame.
_HOOKS = """\
// Generated by fpga_robotics.sim.backends.foreign (VL_USER_STOP, VL_USER_FINISH,
// VL_USER_FATAL).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include "verilated.h"

static char fr_stop_message[600];
static int fr_stopped = 0;

static void fr_record(const char *what, const char *filename, int linenum) {
    if (!fr_stopped)
        std::snprintf(fr_stop_message, sizeof fr_stop_message, "%s at %s:%d", what, filename,
                      linenum);
    fr_stopped = 1;
    Verilated::threadContextp()->gotFinish(true);
}
void vl_stop(const char *filename, int linenum, const char *) {
    fr_record("$stop or $fatal", filename, linenum);
}
void vl_finish(const char *filename, int linenum, const char *) {
    fr_record("$finish", filename, linenum);
}
#include "verilator_fatal.h"
extern "C" __attribute__((visibility("default"))) const char *fr_foreign_stop() {
    return fr_stopped ? fr_stop_message : nullptr;
}
extern "C" __attribute__((visibility("default"))) void fr_foreign_clear() { fr_stopped = 0; }

// [runtime] inputs: the wrapper reads these through DPI at every clock edge.
static int fr_runtime[8];
extern "C" int fr_runtime_value(int index) {
    return index >= 0 && index < 8 ? fr_runtime[index] : 0;
}
extern "C" __attribute__((visibility("default"))) void fr_foreign_set_runtime(int index,
                                                                              int value) {
    if (index >= 0 && index < 8)
        fr_runtime[index] = value;
}
"""


def foreign_build_plan(design):
    compiler = find_compiler()
    find_make()
    root = verilator_root()
    harness = read_sources(_HARNESS_FILES, HARNESS_DIR)
    cflags = " ".join([*CXX_FLAGS, "-DVL_USER_STOP", "-DVL_USER_FINISH", "-DVL_USER_FATAL"])
    key = build_cache.build_key(
        {
            "flow": "verilator-foreign",
            "abi": ABI_VERSION,
            "source": design.digest(),
            # The folder the files are built in: the model's $stop messages name it.
            "layout": DESIGN_DIR,
            "hooks": digest(_HOOKS),
            # Built once per clock edge where Yosys finds the outputs registered.
            "registered": REGISTERED_ANALYSIS,
            "harness": {f: digest(t) for f, t in harness.items()},
            "flags": [*VERILATOR_FLAGS, cflags, *MAKE_FLAGS],
            "compiler": compiler.version,
            "verilator": verilator_version(),
        }
    )

    watched = design.port_map.watch is not None

    def build(directory):
        paths = _write_sources(
            directory,
            {name: design.verilator_text(text) for name, text in design.sources.items()},
            {name: design.verilator_text(text) for name, text in design.includes.items()},
        )
        (directory / "fr_wrapper.v").write_text(design.wrapper)
        (directory / "fr_foreign_hooks.cpp").write_text(_HOOKS)
        (directory / "fr_ports.h").write_text(
            "// Generated by the foreign backend.\n"
            + ("#define FR_WATCH 1  // the wrapper's fr_watch_any output\n" if watched else "")
            + ("#define FR_REGISTERED_OUTPUTS 1\n" if design.registered_outputs() else "")
        )
        for name, text in harness.items():
            (directory / name).write_text(text)
        env = dict(os.environ, VERILATOR_ROOT=str(root))
        make_flags = [*MAKE_FLAGS, f"CXX={compiler.path}", f"LINK={compiler.path}"]
        run_tool(
            [
                root / "bin" / "verilator",
                *VERILATOR_FLAGS,
                "-j",
                "2",
                *include_dirs(directory, design.sources, design.includes),
                "--top-module",
                WRAPPER,
                "--prefix",
                "Vfollow_target",
                "--Mdir",
                directory / "obj",
                "-CFLAGS",
                f"{cflags} -I{directory}",
                "-LDFLAGS",
                "-shared",
                "-MAKEFLAGS",
                " ".join(make_flags),
                "-o",
                directory / LIBRARY_NAME,
                directory / "fr_wrapper.v",
                *paths,
                directory / "verilator_harness.cpp",
                directory / "fr_foreign_hooks.cpp",
            ],
            cwd=directory,
            env=env,
            what=f"building the Verilator model of {design.port_map.top}",
        )

    return BuildPlan(f"verilator-foreign-{design.port_map.top}", key, [LIBRARY_NAME], build)


class ForeignVerilatorBackend(HarnessFrames, DesignBackend):
    """A foreign Verilog design (``ForeignDesign``, or ``files`` and ``port_map``) on
    Verilator. ``params`` gives the frame size; the design is the user's, built with
    ``overrides`` (``VerilogOverrides``: its parameters and `define macros).

    Raises ``BackendError`` (``PortMapError``) for a bad map, and per frame when the design
    does not raise its result strobe within ``result.timeout`` cycles after the frame.
    """

    name = "verilator-foreign"
    #: The simulator, as the build notice names it.
    flow = "Verilator"

    def __init__(
        self,
        params=None,
        *,
        design=None,
        files=None,
        port_map=None,
        line_blank=0,
        frame_blank=0,
        waveform=None,
        on_build=None,
        fill_absent=False,
        overrides=None,
    ):
        super().__init__(params, line_blank=line_blank, frame_blank=frame_blank)
        if waveform is not None:
            raise BackendError("the foreign Verilog backend writes no waveforms yet")
        self.design = (
            design
            if design is not None
            else ForeignDesign(files, port_map, self.params, overrides=overrides)
        )
        if (self.design.params.width, self.design.params.height) != (
            self.params.width,
            self.params.height,
        ):
            raise BackendError("the ForeignDesign was made for another frame size")
        self.fill_absent = fill_absent
        self._handle = None
        self._watch_known = 0  # the [watch] bits given since the last reset
        notice = (
            None
            if on_build is None
            else (
                lambda: on_build(
                    f"compiling the {self.flow} model of {self.design.port_map.top} "
                    "(once; later runs load it from the cache)"
                )
            )
        )
        self._runtime = dict(self.design.port_map.runtime)
        self.cache_entry, self._library = load_built(
            self._build_plan(self.design), LIBRARY_NAME, _Library, on_build=notice
        )
        self._bind_hooks(self._library.lib)
        self._apply_runtime()
        self._handle = self._library.lib.fr_create()
        p, pm = self.params, self.design.port_map
        pixel_edges = p.height * (p.width + line_blank)
        self._out = np.zeros(_N_OUT, np.int64)
        self._args = np.array(
            [
                p.width,
                p.height,
                0,
                line_blank,
                frame_blank,
                1 if pm.after_cycles else pm.latency,
                pixel_edges + frame_blank + (pm.after_cycles or pm.latency) + pm.timeout,
            ],
            np.int64,
        )
        assert len(self._args) == _N_ARGS
        self._init_harness()

    @staticmethod
    def _build_plan(design):
        return foreign_build_plan(design)

    def _bind_hooks(self, lib):
        """The C entry points compiled with the design (``_HOOKS``)."""
        self._stop = lib.fr_foreign_stop
        self._stop.restype = ctypes.c_char_p
        self._stop.argtypes = []
        lib.fr_foreign_clear.restype = None
        lib.fr_foreign_clear()
        lib.fr_foreign_set_runtime.restype = None
        lib.fr_foreign_set_runtime.argtypes = [ctypes.c_int, ctypes.c_int]
        if self.design.port_map.watch is not None:
            lib.fr_watch_read.restype = ctypes.c_int
            lib.fr_watch_read.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]

    @property
    def evals_per_cycle(self):
        return self._library.evals_per_cycle

    def set_runtime(self, name, value):
        """Hold the ``[runtime]`` input ``name`` at ``value`` from the next clock edge (the
        next frame, or the next ``reset()``). The values belong to the loaded model: two
        backends of the same design in one process share them, so each sets its own before
        its frames (``process_frame`` does)."""
        pm = self.design.port_map
        if name not in pm.runtime:
            known = ", ".join(pm.runtime) or "none"
            raise BackendError(
                f"{pm.top} has no [runtime] input {name!r} (its runtime inputs: {known})"
            )
        width = self.design.ports[name][1]
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, np.integer))
            or not (0 <= value < 1 << width)
        ):
            raise BackendError(
                f"runtime input {name!r} is {width} bits wide: the value must "
                f"be 0..{(1 << width) - 1}, got {value!r}"
            )
        self._runtime[name] = int(value)
        self._apply_runtime()

    def _apply_runtime(self):
        for index, value in enumerate(self._runtime.values()):
            self._library.lib.fr_foreign_set_runtime(index, value)

    def _reset(self):
        self._apply_runtime()
        self._watch_known = 0
        self._library.lib.fr_reset(self._live())

    def watch_risen(self):
        """The bits of the ``[watch]`` output that were high at a clock edge since the last
        reset or are high now (``_watch_verilog``) and were not given by an earlier call,
        in bit order; None without a ``[watch]``. Call it after each frame: a bit is given
        with the first frame it was high in (a bit high in the reset's cycle, with the
        first frame after it)."""
        pm = self.design.port_map
        if pm.watch is None:
            return None
        words = np.zeros((self.design.ports[pm.watch][1] + 31) // 32, np.uint32)
        self._library.lib.fr_watch_read(self._live(), words.ctypes.data, words.size)
        now = int.from_bytes(words.astype("<u4").tobytes(), "little")
        new, self._watch_known = now & ~self._watch_known, self._watch_known | now
        return [bit for bit in range(new.bit_length()) if new >> bit & 1]

    def _run_harness(self, entry, frame, color_sel, filtered):
        pm = self.design.port_map
        names = [n for n, c in COLOR_SELECT.items() if c == color_sel]
        if pm.color_port and names[0] not in pm.color_codes:
            raise BackendError(
                f"{pm.top} has no code for colour {names[0]!r} "
                f"(color.codes: {', '.join(pm.color_codes)})"
            )
        self._args[2] = color_sel
        if self._runtime:
            self._apply_runtime()
        out = self._out
        status = entry(
            self._live(), _address(frame), self._args_address, _address(filtered), self._out_address
        )
        index = self.frames_processed
        stopped = self._stop()
        if stopped:
            self._library.lib.fr_foreign_clear()
            # The file as the user named it, not its copy in the build folder.
            where = re.sub(rf" at .*/{DESIGN_DIR}/", " at ", stopped.decode(errors="replace"))
            raise BackendError(f"{pm.top}: frame {index}: the design called {where}")
        if status == 1:
            raise BackendError(
                f"{pm.top}: frame {index}: timeout: the result strobe {pm.strobe!r} never "
                f"rose within {pm.timeout} cycles (result.timeout) after the frame"
            )
        if status == 3 and pm.filtered_valid is None:
            status = 0
        if status != 0:
            message = _STATUS.get(status, f"harness status {status}").format(
                cycles=int(out[0]), filtered=int(out[7]), pixels=filtered.size, bad=int(out[9])
            )
            raise BackendError(f"{pm.top}: frame {index}: {message}")
        absent = 0 if self.fill_absent else None
        values = {}
        for i, key in enumerate(OUTPUTS, start=1):
            if key in pm.outputs:
                value = int(out[i])
                values[key] = bool(value) if key == "found" else value
            else:
                values[key] = absent
        if pm.filtered_valid is None:
            if not self.fill_absent:
                filtered = None
            else:
                filtered.fill(0)  # the harness wrote none of it
        return FrameResult(filtered=filtered, cycles=int(out[0]), **values)

    def close(self):
        if self._handle is not None:
            self._library.lib.fr_destroy(self._handle)
            self._handle = None

    def __del__(self):
        # Interpreter shutdown may have torn down ctypes already: nothing to save then.
        with contextlib.suppress(AttributeError, TypeError, OSError):
            self.close()
