"""CXXRTL backend: Amaranth's ``amaranth.back.cxxrtl`` output compiled with the C++ compiler
against the CXXRTL runtime headers of Amaranth's builtin Yosys, driven frame by frame by the
C++ harness (cxxrtl_harness.cpp + frame_driver.h) through ctypes.
"""

from . import build_cache
from .base import BackendError
from .compiled import ABI_VERSION, HARNESS_DIR, LIBRARY_NAME, CompiledBackend
from .cxxrtl_netlist import (
    check_clocks,
    model_header,
    with_wire_copies_inlined,
    without_port_copies,
)
from .lifecycle import BuildPlan, digest, read_sources
from .toolchain import cxxrtl_include_dir, find_compiler, run_tool

__all__ = ["CXX_FLAGS", "CxxrtlBackend", "cxxrtl_build_plan"]

#: Compiler flags of the model. Measured here on FollowTarget at 160x120: -O3 without the
#: vectoriser 0.90 ms a frame, -O2 1.29 ms, -O3 1.24 ms, -O1 3.1 ms; the vectoriser packs
#: CXXRTL's multi-chunk values into vector stores that stall the loads that follow.
#: -fvisibility=hidden lets the compiler treat the model as private to the library.
CXX_FLAGS = ("-std=c++17", "-O3", "-fno-tree-vectorize", "-fPIC", "-fvisibility=hidden", "-shared")

_HARNESS_FILES = ("cxxrtl_harness.cpp", "frame_driver.h", "cxxrtl_clock.h")


def cxxrtl_build_plan(design, variant, flags=None, include=None):
    """The ``BuildPlan`` of a ``DesignSource`` in variant ``"plain"`` or ``"vcd"``;
    ``flags`` replaces ``CXX_FLAGS``, ``include`` the runtime headers of Amaranth's Yosys
    (for a model another Yosys wrote)."""
    compiler = find_compiler()
    include = cxxrtl_include_dir() if include is None else include
    source = design.cxxrtl()
    if "struct p_follow__target" not in source:
        raise BackendError("the CXXRTL output has no p_follow__target module")
    check_clocks(source, design.design, "verilator")
    header = model_header(source)
    flags = list(CXX_FLAGS if flags is None else flags)
    if variant == "plain":
        # The one-evaluation loop reads every output from its flip-flops (fr_model.h); the
        # same computation with fewer copies (see cxxrtl_netlist).
        source = with_wire_copies_inlined(without_port_copies(source))
    else:
        flags.append("-DFR_TRACE")
    harness = read_sources(_HARNESS_FILES, HARNESS_DIR)
    key = build_cache.build_key(
        {
            "flow": "cxxrtl",
            "abi": ABI_VERSION,
            "source": digest(source + header),
            "harness": {f: digest(t) for f, t in harness.items()},
            "params": design.params.as_dict(),
            "design": design.design,
            "flags": flags,
            "compiler": compiler.version,
            "runtime": str(include),
        }
    )

    def build(directory):
        (directory / "design.cc").write_text(source)
        (directory / "fr_model.h").write_text(header)
        for name, text in harness.items():
            (directory / name).write_text(text)
        run_tool(
            [
                compiler.path,
                *flags,
                f"-I{directory}",
                f"-I{include}",
                directory / "cxxrtl_harness.cpp",
                "-o",
                directory / LIBRARY_NAME,
            ],
            cwd=directory,
            what=f"compiling the CXXRTL model ({compiler.path})",
        )

    return BuildPlan(f"cxxrtl-{design.design}-{variant}", key, [LIBRARY_NAME], build)


class CxxrtlBackend(CompiledBackend):
    """``FollowTarget`` compiled with CXXRTL. See ``CompiledBackend`` for the parameters;
    waveforms are ``.vcd`` (CXXRTL's VCD writer)."""

    name = "cxxrtl"
    waveform_formats = (".vcd",)

    @staticmethod
    def build_plan(design, variant):
        return cxxrtl_build_plan(design, variant)
