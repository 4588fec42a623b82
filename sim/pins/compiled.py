"""The compiled pin backends: a design's CXXRTL or Verilator model with the pin driver
(pin_driver.h) and its generated port accessors (codegen.py) built into a shared library
(through the frame backends' build cache and toolchain), driven through ctypes: one call
per ``run``, ``poke``, ``peek``, ``schedule``, ``watch`` and ``stream_frame``.
"""

import contextlib
import ctypes
import functools
import os
import re
from pathlib import Path

import numpy as np

from ..backends import build_cache
from ..backends.base import BackendError
from ..backends.compiled import HARNESS_DIR
from ..backends.cxxrtl import CXX_FLAGS as CXXRTL_FLAGS
from ..backends.cxxrtl_netlist import (
    check_clocks,
    fast_commit,
    output_sources,
    with_wire_copies_inlined,
    without_port_copies,
)
from ..backends.lifecycle import BuildPlan, bind_library, digest, load_built, read_sources
from ..backends.registered_outputs import REGISTERED_ANALYSIS
from ..backends.toolchain import (
    cxxrtl_include_dir,
    find_compiler,
    find_make,
    run_tool,
    verilator_root,
    verilator_version,
)
from ..backends.verilator import CXX_FLAGS as VERILATOR_CXX_FLAGS
from ..backends.verilator import MAKE_FLAGS, VERILATOR_FLAGS
from ..backends.verilog_cxxrtl import DESIGN_DIR, runtime_include_dir
from .base import DesignStopped, PinError
from .codegen import PIN_WRAPPER, cxxrtl_accessors, verilator_accessors, verilator_wrapper
from .host import HostPins, capture_error

__all__ = ["CompiledPins", "CxxrtlPins", "VerilatorPins"]

#: Directory of the C++ sources (package data).
SOURCE_DIR = Path(__file__).resolve().parent
LIBRARY_NAME = "libpins.so"
#: Must match ``pin::ABI_VERSION`` in pin_driver.h.
ABI_VERSION = 3
_DRIVER = "pin_driver.h"
# Layout of run()'s result array (enum Out in pin_driver.h) and its status codes.
_N_OUT = 7
_TOO_MANY_FILTERED = 1  # the other failure of a run: 2, wrong framing flags
_STOPPED = 5  # the design called $finish, $stop or $fatal
#: Changes ``pin_record`` writes per call.
_RECORD_CHUNK = 65536

_VP = ctypes.c_void_p
_I64 = ctypes.c_int64
_U64 = ctypes.c_uint64
_ENTRIES = (
    ("pin_abi_version", ctypes.c_int, []),
    ("pin_evals_per_cycle", ctypes.c_int, []),
    ("pin_create", _VP, []),
    ("pin_destroy", None, [_VP]),
    ("pin_reset", None, [_VP]),
    ("pin_cycle", _I64, [_VP]),
    ("pin_poke", None, [_VP, ctypes.c_int, _U64]),
    ("pin_peek", _U64, [_VP, ctypes.c_int]),
    ("pin_schedule", None, [_VP, _I64, ctypes.c_int, _U64]),
    ("pin_schedule_many", None, [_VP, ctypes.c_int, _VP, _VP, _I64]),
    ("pin_record", ctypes.c_int, [_VP, _I64, _VP, _I64, _VP]),
    ("pin_watch", None, [_VP, _VP, _I64]),
    ("pin_stream", ctypes.c_int, [_VP, _VP, _VP, _VP]),
    ("pin_run", ctypes.c_int, [_VP, _I64, _VP]),
    ("pin_stop_message", ctypes.c_char_p, [_VP]),
)


def _sources(*names):
    """``{name: text}`` of harness files of this package or, shared with the frame
    harnesses, of sim/backends."""
    return read_sources(names, SOURCE_DIR, HARNESS_DIR)


@functools.lru_cache(maxsize=16)
def _fast_model(model, outputs):
    """``(model, output expressions, commit)``: the CXXRTL text with the outputs read from
    flip-flops where they can be (``output_exprs``/``commit`` None where not). Kept per
    process: reading a large model takes a tenth of a second, on every run of the design."""
    exprs = output_sources(model, list(outputs))
    if exprs is None:
        return model, None, None
    commit = fast_commit(model)
    return with_wire_copies_inlined(without_port_copies(model, list(outputs))), exprs, commit


def cxxrtl_plan(source):
    """The ``BuildPlan`` of a ``PinDesignSource`` (Amaranth's CXXRTL output) or a
    ``VerilogPinSource`` (its files read by Yosys) with CXXRTL."""
    compiler = find_compiler()
    foreign = hasattr(source, "verilog_files")
    # Each model compiles against the runtime headers of the Yosys that wrote it.
    include = runtime_include_dir() if foreign else cxxrtl_include_dir()
    outputs = tuple(p.name for p in source.ports.values() if p.direction == "out")
    check_clocks(source.cxxrtl, source.key, "verilator or pysim")
    model, exprs, commit = _fast_model(source.cxxrtl, outputs)
    accessors = cxxrtl_accessors(source, exprs, commit)
    harness = _sources("pin_cxxrtl.cpp", _DRIVER, "cxxrtl_clock.h")
    flags = list(CXXRTL_FLAGS)
    key = build_cache.build_key(
        {
            "flow": "pins-cxxrtl",
            "abi": ABI_VERSION,
            "design": source.key,
            "source": digest(model + accessors),
            "harness": {name: digest(text) for name, text in harness.items()},
            "flags": flags,
            "compiler": compiler.version,
            "runtime": str(include),
        }
    )

    def build(directory):
        (directory / "design.cc").write_text(model)
        (directory / "pin_design.h").write_text(accessors)
        for name, text in harness.items():
            (directory / name).write_text(text)
        run_tool(
            [
                compiler.path,
                *flags,
                f"-I{directory}",
                f"-I{include}",
                directory / "pin_cxxrtl.cpp",
                "-o",
                directory / LIBRARY_NAME,
            ],
            cwd=directory,
            what=f"compiling the CXXRTL pin model ({compiler.path})",
        )

    return BuildPlan(f"pins-cxxrtl-{source.key}", key, [LIBRARY_NAME], build)


def verilator_plan(source):
    """The ``BuildPlan`` of a ``PinDesignSource`` (its exported Verilog) or a
    ``VerilogPinSource`` (a foreign design's files and wrapper) with Verilator."""
    compiler = find_compiler()
    find_make()
    root = verilator_root()
    outputs = [p.name for p in source.ports.values() if p.direction == "out"]
    if hasattr(source, "verilog_files"):  # a foreign Verilog design
        files, compiled = source.verilog_files()
        # None: whether every output is registered is found when the model is built.
        top, registered = source.verilog_top, source.registered_outputs
    else:
        files, compiled = {"follow_target.v": source.verilog}, ["follow_target.v"]
        top = "follow_target"
        registered = output_sources(source.cxxrtl, outputs) is not None
    # The model's top is a wrapper whose ports are numbered: any port name builds.
    files = {**files, "fr_pin_top.v": verilator_wrapper(source, top)}
    compiled = [*compiled, "fr_pin_top.v"]
    text = "".join(f"{name}\0{body}\0" for name, body in files.items())
    accessors = verilator_accessors(source, bool(registered))
    harness = _sources("pin_verilator.cpp", _DRIVER, "verilator_clock.h", "verilator_fatal.h")
    # $finish, $stop and $fatal reach the harness's hooks (pin_verilator.cpp), not the
    # process's exit; Verilator's own fatal errors are one line and exit code 2.
    flags = ("-DVL_USER_STOP", "-DVL_USER_FINISH", "-DVL_USER_FATAL")
    cflags = " ".join([*VERILATOR_CXX_FLAGS, *flags])
    jobs = str(max(1, min(os.cpu_count() or 1, 4)))
    key = build_cache.build_key(
        {
            "flow": "pins-verilator",
            "abi": ABI_VERSION,
            # The folder the files are built in: the model's $stop messages name it.
            "layout": DESIGN_DIR,
            "design": source.key,
            "source": digest(text + accessors),
            "registered": REGISTERED_ANALYSIS if registered is None else registered,
            "harness": {name: digest(text) for name, text in harness.items()},
            "flags": [*VERILATOR_FLAGS, cflags, *MAKE_FLAGS],
            "compiler": compiler.version,
            "verilator": verilator_version(),
        }
    )

    def build(directory):
        for name, body in files.items():
            path = directory / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(body)
        if registered is None:
            (directory / "pin_design.h").write_text(
                verilator_accessors(source, source.registered_when_built())
            )
        else:
            (directory / "pin_design.h").write_text(accessors)
        for name, body in harness.items():
            (directory / name).write_text(body)
        env = dict(os.environ, VERILATOR_ROOT=str(root))
        make_flags = [*MAKE_FLAGS, f"CXX={compiler.path}", f"LINK={compiler.path}"]
        run_tool(
            [
                root / "bin" / "verilator",
                *VERILATOR_FLAGS,
                "-j",
                jobs,
                "--top-module",
                PIN_WRAPPER,
                "--prefix",
                "Vfollow_target",
                # An include next to a listed file or the file that includes it is found.
                *dict.fromkeys(f"-I{(directory / name).parent}" for name in [*compiled, *files]),
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
                *(directory / name for name in compiled),
                directory / "pin_verilator.cpp",
            ],
            cwd=directory,
            env=env,
            what=f"building the Verilator pin model (make, {compiler.path})",
        )

    return BuildPlan(f"pins-verilator-{source.key}", key, [LIBRARY_NAME], build)


def _load(path):
    return bind_library(
        path,
        _ENTRIES,
        what="compiled pin model",
        abi_entry="pin_abi_version",
        abi=ABI_VERSION,
        error=PinError,
    )


def _address(array):
    return array.__array_interface__["data"][0]


class CompiledPins(HostPins):
    """A design's compiled model behind the pin interface (see ``HostPins``).

    Parameters
    ----------
    source : PinDesignSource
    on_build : callable(str), optional
        Told (one line) before a build that is not in the cache.
    """

    #: ``plan(source)`` -> ``BuildPlan``.
    plan = None

    def __init__(self, source, *, on_build=None):
        super().__init__(source)
        self._handle = None
        self._on_build = on_build
        try:
            self._lib = self._build_and_load()
        except BackendError as exc:
            raise PinError(f"{self.name}: {exc}") from None
        self._handle = self._lib.pin_create()
        if not self._handle:
            raise PinError(f"the {self.name} pin model could not be created")
        self._out = np.zeros(_N_OUT, np.int64)
        self._out_address = _address(self._out)
        self._run_entry = self._lib.pin_run
        self._geometry = np.zeros(5, np.int64)
        #: Simulator evaluations per clock cycle (1 when every output is a flip-flop).
        self.evals_per_cycle = self._lib.pin_evals_per_cycle()

    def _live(self):
        """The model's handle for a call into the harness; ``PinError`` once ``close()`` has
        freed the model (the harness would dereference a null model and crash Python)."""
        if self._handle is None:
            raise PinError(
                f"{self.name}: the pins are closed; open new ones to run the design again"
            )
        return self._handle

    def _build_and_load(self):
        self.cache_entry, lib = load_built(
            type(self).plan(self.source), LIBRARY_NAME, _load, on_build=self._notice, error=PinError
        )
        return lib

    def _notice(self):
        if self._on_build is not None:
            self._on_build(
                f"compiling the {self.name} pin model of {self.source.key} (once; "
                f"later runs load it from the cache)"
            )

    def _raw_reset(self):
        self._lib.pin_reset(self._live())

    def _raw_poke(self, index, raw):
        self._lib.pin_poke(self._live(), index, raw)

    def _raw_peek(self, index):
        return self._lib.pin_peek(self._live(), index)

    def _raw_schedule(self, edge, index, raw):
        self._lib.pin_schedule(self._live(), edge, index, raw)

    def _raw_schedule_many(self, index, edges, raws):
        if edges[0] == self._cycle + 1:  # that edge's inputs are on already: a poke
            self._raw_schedule(int(edges[0]), index, int(raws[0]))
            edges, raws = edges[1:], raws[1:]
        edges, raws = np.ascontiguousarray(edges), np.ascontiguousarray(raws)
        self._lib.pin_schedule_many(
            self._live(), index, _address(edges), _address(raws), len(edges)
        )

    def _raw_record(self, cycles):
        end = self._cycle + cycles
        buffer = np.zeros((_RECORD_CHUNK, 3), np.int64)
        while True:
            status = self._lib.pin_record(
                self._live(), end - self._cycle, _address(buffer), _RECORD_CHUNK, self._out_address
            )
            cycle, _port, _value, captured, _pending, bad, recorded = self._out.tolist()
            if status:
                self._cycle = cycle
                raise self._run_error(status, bad)
            self._ran_to(cycle, captured)
            rows = buffer[:recorded]
            raws = rows[:, 2].astype(np.uint64).tolist()
            yield from zip(rows[:, 0].tolist(), rows[:, 1].tolist(), raws)
            if recorded < _RECORD_CHUNK:
                return

    def _raw_watch(self, indices):
        order = np.array(indices, np.int32)
        self._lib.pin_watch(self._live(), _address(order), len(order))

    def _raw_stream(self, frame, timing, capture):
        height, width = frame.shape
        self._geometry[:] = (width, height, timing.start, timing.line_period, timing.pixel_period)
        status = self._lib.pin_stream(
            self._live(),
            _address(frame),
            _address(self._geometry),
            None if capture is None else _address(capture),
        )
        if status != 0:
            raise PinError(f"{self.name}: the pin model rejected the frame (status {status})")

    def _raw_run(self, cycles):
        out = self._out
        status = self._run_entry(self._live(), cycles, self._out_address)
        cycle, port, value, captured, _pending, bad, _recorded = out.tolist()  # enum Out
        if status:
            self._cycle = cycle
            raise self._run_error(status, bad)
        return cycle, port, value & 0xFFFF_FFFF_FFFF_FFFF, captured

    def _run_error(self, status, bad):
        """The error of a run that ended with ``status``."""
        if status != _STOPPED:
            return capture_error(status == _TOO_MANY_FILTERED, bad)
        text = (self._lib.pin_stop_message(self._live()) or b"").decode(errors="replace")
        # The file as the user named it, not its copy in the build folder.
        return DesignStopped(re.sub(rf" at (?:\S*/)?{DESIGN_DIR}/", " at ", text), self._cycle)

    def close(self):
        if self._handle is not None:
            self._lib.pin_destroy(self._handle)
            self._handle = None

    def __del__(self):
        with contextlib.suppress(AttributeError, TypeError, OSError):
            self.close()


class CxxrtlPins(CompiledPins):
    """The design compiled with CXXRTL."""

    name = "cxxrtl"
    plan = staticmethod(cxxrtl_plan)


class VerilatorPins(CompiledPins):
    """The design built with Verilator."""

    name = "verilator"
    plan = staticmethod(verilator_plan)
