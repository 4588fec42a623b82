"""Foreign Verilog designs on CXXRTL: the wrapper of foreign.py and the user's files read by
Yosys (verilog_cxxrtl.py) into a CXXRTL model that the CXXRTL frame harness drives as it
drives FollowTarget. Results are the Verilator foreign backend's, cycle for cycle; what only
Verilator does (``[runtime]`` inputs through DPI, Verilog Yosys cannot read) is a one-line
error pointing at ``--backend verilator``.
"""

from .base import BackendError
from .cxxrtl import cxxrtl_build_plan
from .foreign import WRAPPER, ForeignVerilatorBackend
from .verilog_cxxrtl import runtime_include_dir, verilog_to_cxxrtl

__all__ = ["ForeignCxxrtlBackend", "foreign_cxxrtl_plan"]


class _YosysSource:
    """A ``ForeignDesign`` as the CXXRTL build plan takes a ``DesignSource``."""

    def __init__(self, design):
        self.params = design.params
        self.design = f"foreign-{design.port_map.top}"
        self._foreign = design

    def cxxrtl(self):
        d = self._foreign
        return verilog_to_cxxrtl(
            {"fr_wrapper.v": d.wrapper, **d.sources}, WRAPPER, d.includes, d.port_map.top
        )


def foreign_cxxrtl_plan(design):
    """The ``BuildPlan`` of a ``ForeignDesign`` (frames, no waveform) on CXXRTL."""
    pm = design.port_map
    if pm.runtime:
        raise BackendError(
            f"{pm.top}'s [runtime] inputs are set through Verilator's DPI: run "
            "it with --backend verilator"
        )
    if pm.watch:
        raise BackendError(
            f"{pm.top}'s [watch] output is watched through Verilator's DPI: run "
            "it with --backend verilator"
        )
    return cxxrtl_build_plan(_YosysSource(design), "plain", include=runtime_include_dir())


class ForeignCxxrtlBackend(ForeignVerilatorBackend):
    """A foreign Verilog design on CXXRTL; the parameters and results of
    ``ForeignVerilatorBackend``. ``$stop``/``$finish`` are not caught and there are no
    ``[runtime]`` inputs (both need Verilator)."""

    name = "cxxrtl-foreign"
    flow = "CXXRTL"

    @staticmethod
    def _build_plan(design):
        return foreign_cxxrtl_plan(design)

    def _bind_hooks(self, lib):
        self._stop = lambda: None
