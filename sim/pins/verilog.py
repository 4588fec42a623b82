"""``VerilogPinSource``: a foreign Verilog design (files and a port map, docs/foreign.md) for
the compiled pin backends, in real-clock timing.

The design is wrapped by the foreign backend's generated module (``ForeignDesign(pins=True)``):
the pixel stream, colour codes, reset polarity and output extension work as in compressed
timing, and the ports of the map's ``[connectors.<kind>]`` tables pass through under their own
names. Verilator reads the files (``verilator``), or Yosys, which writes them as a CXXRTL
model (``cxxrtl``); Amaranth's simulator cannot take Verilog.
"""

import functools
import hashlib

from ..backends.foreign import WRAPPER, pin_ports, watch_chunks
from ..backends.verilog_cxxrtl import DESIGN_DIR, verilog_to_cxxrtl
from .base import PinError, Port
from .design import FILTERED_PORTS, MAX_PORTS, PIXEL_PORTS

__all__ = ["VerilogPinSource"]


class VerilogPinSource:
    """A ``ForeignDesign`` made with ``pins=True`` (sim.backends.foreign) as a pin design.

    Its ports are the wrapper's: ``pixels__valid``/``pixels__payload``, ``color_sel`` and
    ``frame_done`` when the map has a pixel stream, the outputs the map names (``found``,
    ``motor_left``, ...; absent ones are not ports), ``filtered__*`` with ``[filtered]``,
    every connector port under the design's own name, and with ``[watch]`` the bits its
    output rose in since the reset (``fr_watch_any_0``, ...: ``watch``). ``stream=False``:
    the pixel ports are plain inputs (no ``stream_frame``).
    """

    #: The wrapper's module: the pin harness's model (``--prefix Vfollow_target``).
    verilog_top = "fr_foreign_top"

    def __init__(self, design, *, stream=True):
        if not design.pins:
            raise PinError("a VerilogPinSource needs a ForeignDesign made with pins=True")
        assert WRAPPER == self.verilog_top
        self.design = design
        pm = design.port_map
        self.key = f"verilog-{pm.top}-{design.digest()[:16]}"
        self.ports = {
            name: Port(name, width, direction, signed)
            for name, (direction, width, signed) in pin_ports(design).items()
        }
        if len(self.ports) > MAX_PORTS:
            raise PinError(
                f"design {pm.top!r} has {len(self.ports)} ports; the pin backends "
                f"take at most {MAX_PORTS}"
            )
        #: ``[runtime]`` inputs -> the values the backend holds them at (``set_runtime``).
        self.runtime = dict(pm.runtime)
        #: The ``[watch]`` output's bits since the reset, as outputs of 64 bits at most:
        #: ``[(port, lowest bit)]`` (``HostPins.watch_risen``).
        self.watch = [(name, low) for name, low, _ in watch_chunks(pm, design.ports)]
        # Without the stream (``stream=False``) the pixel ports are inputs like any other,
        # each edge's value given by ``poke`` (a unit judge's random stimulus).
        streamed = pm.has_pixels and stream
        if pm.has_pixels and not stream:
            self.key += "-unstreamed"
        self.pixels = PIXEL_PORTS if streamed else None
        self.filtered = FILTERED_PORTS if pm.filtered_valid and streamed else None
        self.frame_size = design.frame_size if streamed else None

    def verilog_files(self):
        """``(files, compiled)``: every file to write (relative path -> text, the design's
        `include files too) and the ones Verilator compiles, in order; the includes are
        found under ``DESIGN_DIR`` in their layout."""
        d = self.design
        files = {"fr_wrapper.v": d.wrapper}
        # The data files of $readmemh/$readmemb at their absolute paths (verilator_text).
        files.update(
            {f"{DESIGN_DIR}/{name}": d.verilator_text(text) for name, text in d.includes.items()}
        )
        files.update(
            {f"{DESIGN_DIR}/{name}": d.verilator_text(text) for name, text in d.sources.items()}
        )
        compiled = ["fr_wrapper.v", *(f"{DESIGN_DIR}/{name}" for name in d.sources)]
        return files, compiled

    @functools.cached_property
    def cxxrtl(self):
        """CXXRTL C++ text of the wrapper and the design (class ``p_follow__target``), written
        by Yosys; ``BackendError`` for what Yosys cannot read."""
        d = self.design
        return verilog_to_cxxrtl(
            {"fr_wrapper.v": d.wrapper, **d.sources}, self.verilog_top, d.includes, d.port_map.top
        )

    #: Whether every output is a flip-flop (one evaluation per edge, else two): None, found
    #: when the model is built (``registered_when_built``).
    registered_outputs = None

    def registered_when_built(self):
        """Whether every output is a flip-flop, as Yosys reads the wrapper and the files
        (sim.backends.registered_outputs; False when it cannot say)."""
        return self.design.registered_outputs()

    @property
    def digest(self):
        return hashlib.sha256(self.design.digest().encode()).hexdigest()

    def __repr__(self):
        return f"VerilogPinSource({self.key!r}, {len(self.ports)} ports)"
