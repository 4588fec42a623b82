"""A cycle-level VCD of the ``follow_target`` ports, reconstructed from the golden model.

The model computes whole frames, not clock cycles, but the frame driver's cycle accounting
(sim/backends/base.py) and the design's documented latencies fix when every port changes:

- the input pixel sampled at edge ``k`` is on ``pixels`` during the cycle before edge ``k``;
- ``filtered`` carries the same transfer ``filter_latency`` edges later;
- ``frame_done`` is high, and ``found``, ``proximity``, ``centroid_x``, ``centroid_leds`` take the
  frame's values, in the cycle right after edge ``P + result_latency`` (``P``: the edge that
  samples the frame's last pixel);
- ``motor_left``/``motor_right`` change right after edge ``P + result_latency + motor_latency``.

So the trace shows what the gateware shows at its ports when it agrees with the model; a
difference between this trace and a gateware trace is a bug in one of them. Internal signals do
not exist here. Times: the clock period is ``CLOCK_PERIOD_NS`` (50 MHz, the board clock); the
value after edge ``k`` is written at edge ``k``'s time, as Amaranth's simulator does.
"""

import os

import numpy as np
from vcd import VCDWriter

from ..files import PendingOutput

__all__ = ["CLOCK_PERIOD_NS", "ModelWaveformWriter"]

CLOCK_PERIOD_NS = 20

# (name, width) of every traced port, in Verilog port order.
_PORTS = (
    ("rst", 1),
    ("pixels__valid", 1),
    ("pixels__payload", 14),
    ("color_sel", 3),
    ("filtered__valid", 1),
    ("filtered__payload", 14),
    ("frame_done", 1),
    ("found", 1),
    ("proximity", 3),
    ("centroid_x", None),  # params.x_bits
    ("centroid_leds", 8),
    ("motor_left", 16),
    ("motor_right", 16),
)


class ModelWaveformWriter:
    """Writes the port trace of consecutive frames to ``path`` (``.vcd``).

    The file appears at ``path`` only when :meth:`finish` is called; until then it is a
    temporary file in the same directory, removed by :meth:`abort`.
    """

    def __init__(self, path, params, *, line_blank, outputs):
        self.path = os.fspath(path)
        self.params = params
        self.line_blank = line_blank
        self._output = PendingOutput(self.path, what="waveform")
        self._file = open(self._output.tmp, "w")  # noqa: SIM115 (closed by finish/abort)
        self._writer = VCDWriter(
            self._file, timescale="1 ns", date="", comment="fpga_robotics model backend"
        )
        self._clk = self._writer.register_var("follow_target", "clk", "wire", size=1, init=0)
        self._vars = {}
        initial = self._output_values(*outputs)
        for name, width in _PORTS:
            size = params.x_bits if width is None else width
            init = initial.get(name, 0)
            self._vars[name] = self._writer.register_var(
                "follow_target", name, "wire", size=size, init=init
            )
        # Last value of each stream signal in the generated series, and of each written var.
        self._last = {name: 0 for name, _ in _PORTS}
        self._written = {name: initial.get(name, 0) for name, _ in _PORTS}
        self._edge = 0  # global edges written so far
        self._pending = []  # (interval, name, value) not yet written

    @staticmethod
    def _output_values(found, proximity, centroid_x, leds, left, right):
        return {
            "found": int(found),
            "proximity": proximity,
            "centroid_x": centroid_x,
            "centroid_leds": leds,
            "motor_left": left & 0xFFFF,
            "motor_right": right & 0xFFFF,
        }

    def add_frame(self, packed, color_sel, filtered, outputs, cycles):
        """Trace one frame call of ``cycles`` edges; ``outputs`` are the frame's new values
        (found, proximity, centroid_x, centroid_leds, motor_left, motor_right)."""
        p = self.params
        h, w, lb = p.height, p.width, self.line_blank
        base = self._edge
        # Local interval i is the cycle after local edge i (edge 0: the call's start). The
        # pixel sampled at edge y*(W+lb) + x + 1 is presented in interval y*(W+lb) + x.
        idx = (np.arange(h)[:, None] * (w + lb) + np.arange(w)[None, :]).ravel()
        flags = np.zeros((h, w), np.int64)
        flags[0, 0] |= 1 << 12
        flags[:, w - 1] |= 1 << 13
        flags = flags.ravel()
        fl = p.filter_latency
        streams = {name: np.zeros(cycles, np.int64) for name, _ in _PORTS[1:3] + _PORTS[4:6]}
        streams["pixels__valid"][idx] = 1
        streams["pixels__payload"][idx] = packed.astype(np.int64).ravel() | flags
        streams["filtered__valid"][idx + fl] = 1
        streams["filtered__payload"][idx + fl] = filtered.astype(np.int64).ravel() | flags

        events = [(base, "color_sel", color_sel)]
        for name, values in streams.items():
            series = np.concatenate([[self._last[name]], values])
            for j in np.flatnonzero(np.diff(series)):
                events.append((base + int(j), name, int(values[j])))
            self._last[name] = int(values[-1])
        done = h * (w + lb) - lb + p.result_latency
        events.append((base + done, "frame_done", 1))
        events.append((base + done + 1, "frame_done", 0))
        for name, value in self._output_values(*outputs).items():
            at = done + (p.motor_latency if name.startswith("motor") else 0)
            events.append((base + at, name, value))
        self._emit(events, base + cycles)

    def _emit(self, events, end):
        """Write the clock and every event of the intervals before ``end``; keep the rest."""
        events = sorted(self._pending + events, key=lambda e: e[0])
        self._pending = [e for e in events if e[0] >= end]
        by_time = {}
        for t, name, value in events:
            if t < end:
                by_time.setdefault(t, []).append((name, value))
        change, clk, half = self._writer.change, self._clk, CLOCK_PERIOD_NS // 2
        written = self._written
        for edge in range(self._edge, end):
            t = edge * CLOCK_PERIOD_NS
            if edge > 0:
                change(clk, t, 1)
            for name, value in by_time.get(edge, ()):
                if written.get(name) != value:
                    change(self._vars[name], t, value)
                    written[name] = value
            change(clk, t + half, 0)
        self._edge = end

    def finish(self):
        """Write the remaining events, close the file and move it to ``path``."""
        end = max([self._edge + 1] + [t + 1 for t, _, _ in self._pending])
        self._emit([], end)
        self._writer.close(end * CLOCK_PERIOD_NS)
        self._file.close()
        self._output.commit()

    def abort(self):
        """Drop the unfinished trace."""
        try:
            self._file.close()
        finally:
            self._output.discard()
