"""The host side every pin backend shares: argument checks with one-line ``PinError``s, port
values as the user sees them (signed ports negative) and as the simulators hold them (raw
unsigned bits), the pixel stream's bookkeeping and the filtered frames' buffers.

A backend implements the ``_raw_*`` methods on port indices (signature order) and raw values.
"""

from collections import deque

import numpy as np

from ..camera.frames import FrameError, to_rgb444
from .base import PinBackend, PinError, PixelTiming, Stop, StopLimit

__all__ = ["HostPins", "capture_error"]


def capture_error(too_many, bad_index):
    """The ``PinError`` of a filtered stream that does not frame the frames streamed."""
    if too_many:
        return PinError("the design put out more filtered pixels than the frames streamed")
    return PinError(f"filtered pixel {bad_index} of a frame carries wrong first/last framing flags")


class HostPins(PinBackend):
    """Checks and bookkeeping around a simulator reached by port index (see module doc)."""

    def __init__(self, source):
        self.source = source
        self.ports = dict(source.ports)
        self._index = {name: i for i, name in enumerate(self.ports)}
        self._port_list = list(self.ports.values())
        self._stream_ports = set(source.pixels or ())
        self._cycle = 0
        self._last_pixel_edge = 0
        self._captures = deque()  # buffers of frames whose filtered stream is still coming
        self._filtered = None
        self._captured = 0  # frames the simulator has completed (its counter)
        # [runtime] inputs of a Verilog design: held at these values from every reset on.
        self._held = dict(getattr(source, "runtime", None) or {})
        self._watch_known = 0  # the [watch] bits watch_risen gave since the reset
        #: Watched changes ``run`` stopped at since the reset.
        self.stops = 0
        #: More stops than this since the reset raise ``StopLimit`` (None: no limit).
        self.stop_limit = None

    # --- values ---------------------------------------------------------------------------

    def _port(self, name):
        index = self._index.get(name)
        if index is None:
            raise PinError(f"unknown port {name!r}; the design's ports: {', '.join(self.ports)}")
        return index, self._port_list[index]

    def _input(self, name):
        index, port = self._port(name)
        if port.direction != "in":
            raise PinError(
                f"port {name!r} is an output of the design; only inputs can be "
                f"driven (inputs: {', '.join(self._inputs())})"
            )
        if name in self._stream_ports:
            raise PinError(f"port {name!r} is driven by the pixel stream; use stream_frame")
        return index, port

    def _inputs(self):
        return [p.name for p in self._port_list if p.direction == "in"]

    @staticmethod
    def _raw(port, value):
        if isinstance(value, (bool, np.bool_)):
            value = int(value)
        if not isinstance(value, (int, np.integer)):
            raise PinError(f"the value for {port.name!r} must be an int, not {value!r}")
        value = int(value)
        lo, hi = HostPins._range(port)
        if not lo <= value <= hi:
            kind = "signed" if port.signed else "unsigned"
            raise PinError(
                f"{value} does not fit port {port.name!r} ({port.width}-bit {kind}: {lo}..{hi})"
            )
        return value & ((1 << port.width) - 1)

    @staticmethod
    def _range(port):
        """The values ``port`` takes: ``(lowest, highest)``."""
        if port.signed:
            return -(1 << (port.width - 1)), (1 << (port.width - 1)) - 1
        return 0, (1 << port.width) - 1

    @staticmethod
    def _cooked(port, raw):
        if port.signed and raw >> (port.width - 1):
            return raw - (1 << port.width)
        return raw

    # --- the interface ----------------------------------------------------------------------

    @property
    def cycle(self):
        return self._cycle

    def reset(self):
        self._raw_reset()
        self._cycle = 0
        self._last_pixel_edge = 0
        self._captures.clear()
        self._filtered = None
        self._captured = 0
        self.stops = 0
        self._watch_known = 0
        for name, value in self._held.items():
            self.poke(name, value)

    def watch_risen(self):
        """The bits of the design's ``[watch]`` output that rose since the reset (at a clock
        edge, or high now) and were not given by an earlier call, in bit order; None for a
        design without one (the source's ``watch``, sim.pins.verilog)."""
        chunks = getattr(self.source, "watch", None)
        if not chunks:
            return None
        now = 0
        for name, low in chunks:
            now |= self.peek(name) << low
        new, self._watch_known = now & ~self._watch_known, self._watch_known | now
        return [bit for bit in range(new.bit_length()) if new >> bit & 1]

    def set_runtime(self, name, value):
        """Hold the ``[runtime]`` input ``name`` at ``value``, now and after every reset (one
        build of the model for every value, e.g. a mutant select)."""
        if name not in self._held:
            known = ", ".join(self._held) or "none"
            raise PinError(
                f"the design has no [runtime] input {name!r} (its runtime inputs: {known})"
            )
        self.poke(name, value)
        self._held[name] = int(value)

    def poke(self, name, value):
        index, port = self._input(name)
        self._raw_poke(index, self._raw(port, value))

    def peek(self, name):
        index, port = self._port(name)
        return self._cooked(port, self._raw_peek(index))

    def schedule(self, edge, name, value):
        index, port = self._input(name)
        raw = self._raw(port, value)
        if isinstance(edge, bool) or not isinstance(edge, (int, np.integer)):
            raise PinError(f"the edge must be an int, not {edge!r}")
        if edge <= self._cycle:
            raise PinError(
                f"edge {edge} is in the past (cycle is {self._cycle}); schedule "
                f"changes for edge {self._cycle + 1} or later"
            )
        self._raw_schedule(int(edge), index, raw)

    def schedule_many(self, name, edges, values):
        """``schedule`` for many changes of input ``name`` at once: ``values[k]`` from edge
        ``edges[k]`` on, the edges strictly increasing and after ``cycle`` (a frame's pixels,
        a seeded stimulus: one call instead of one a change)."""
        index, port = self._input(name)
        edges = np.asarray(edges)
        values = np.asarray(values)
        if edges.ndim != 1 or values.shape != edges.shape:
            raise PinError(
                f"schedule_many needs edges and values of one length, got shapes "
                f"{edges.shape} and {values.shape}"
            )
        if len(edges) == 0:
            return
        if edges.dtype.kind not in "iu":
            raise PinError(f"the edges must be ints, not {edges.dtype}")
        edges = edges.astype(np.int64)
        if (np.diff(edges) <= 0).any():
            raise PinError("the edges of schedule_many must be strictly increasing")
        if edges[0] <= self._cycle:
            raise PinError(
                f"edge {int(edges[0])} is in the past (cycle is {self._cycle}); schedule "
                f"changes for edge {self._cycle + 1} or later"
            )
        self._raw_schedule_many(index, edges, self._raw_array(port, values))

    def _raw_array(self, port, values):
        """``_raw`` of every value, as uint64."""
        if values.dtype.kind not in "iub" or port.width >= 64:
            return np.array([self._raw(port, v) for v in values.tolist()], np.uint64)
        values = values.astype(np.int64)
        lo, hi = self._range(port)
        bad = (values < lo) | (values > hi)
        if bad.any():
            self._raw(port, int(values[np.argmax(bad)]))  # raises, with the message
        return (values & ((1 << port.width) - 1)).astype(np.uint64)

    def record_changes(self, cycles, names):
        """Run ``cycles`` edges watching the outputs ``names`` (``watch``); returns every
        change: ``{name: [(cycle, value), ...]}`` in order, as a ``run`` loop would give
        them, one stop each (counted in ``stops``; ``stop_limit`` is checked once they are
        all recorded)."""
        self._check_cycles(cycles)
        self.watch(names)
        changes = {name: [] for name in names}
        end = self._cycle + cycles
        for cycle, index, raw in self._raw_record(int(cycles)):
            port = self._port_list[index]
            changes[port.name].append((cycle, self._cooked(port, raw)))
            self.stops += 1
        if self.stop_limit is not None and self.stops > self.stop_limit:
            raise StopLimit(
                f"the design's watched outputs changed more than {self.stop_limit} times "
                f"by edge {end}, over this run's budget"
            )
        return changes

    def watch(self, names):
        if isinstance(names, str):
            names = [names]
        indices = []
        for name in names:
            index, port = self._port(name)
            if port.direction != "out":
                raise PinError(f"port {name!r} is an input; only outputs can be watched")
            if index not in indices:
                indices.append(index)
        self._raw_watch(indices)

    @property
    def frame_pending(self):
        return self._last_pixel_edge > self._cycle

    def stream_frame(self, packed, timing):
        source = self.source
        if source.pixels is None:
            raise PinError("this design has no pixel stream binding (PinDesignSource pixels=...)")
        width, height = source.frame_size
        shape = getattr(packed, "shape", None)
        if shape not in ((height, width), (height, width, 3)):
            raise PinError(
                f"a frame must be a ({height}, {width}) uint16 array of RGB444 "
                f"pixels (or ({height}, {width}, 3) uint8 RGB888), not "
                f"{getattr(packed, 'dtype', type(packed).__name__)} {shape}"
            )
        try:
            frame = to_rgb444(packed, width, height)
        except FrameError as exc:
            raise PinError(str(exc)) from None
        if self.frame_pending:
            raise PinError(
                f"a frame is still streaming (its last pixel is at edge "
                f"{self._last_pixel_edge}, cycle is {self._cycle}); run until "
                f"frame_pending is False first"
            )
        if not isinstance(timing, PixelTiming):
            raise PinError(f"timing must be a PixelTiming, not {timing!r}")
        if timing.start <= self._cycle:
            raise PinError(
                f"the frame starts at edge {timing.start}, in the past (cycle is "
                f"{self._cycle}); start it at edge {self._cycle + 1} or later"
            )
        if timing.pixel_period < 1 or timing.line_period < (width - 1) * timing.pixel_period + 1:
            raise PinError(
                f"pixel_period must be >= 1 and line_period >= (width - 1) * "
                f"pixel_period + 1 = {(width - 1) * max(1, timing.pixel_period) + 1} "
                f"so that lines do not overlap (got {timing})"
            )
        capture = None
        if source.filtered is not None:
            if len(self._captures) >= 2:
                raise PinError(
                    "two frames' filtered streams are still incomplete; the "
                    "design's filtered output lags by more than a frame"
                )
            capture = np.zeros((height, width), np.uint16)
            self._captures.append(capture)
        self._raw_stream(frame, timing, capture)
        self._last_pixel_edge = timing.last_edge(width, height)

    def filtered_frame(self):
        return self._filtered

    @staticmethod
    def _check_cycles(cycles):
        if isinstance(cycles, bool) or not isinstance(cycles, (int, np.integer)) or cycles < 0:
            raise PinError(f"run needs a number of cycles >= 0, not {cycles!r}")

    def run(self, cycles):
        self._check_cycles(cycles)
        cycle, index, raw, captured = self._raw_run(int(cycles))
        self._ran_to(cycle, captured)
        if index < 0:
            return Stop(cycle)
        port = self._port_list[index]
        self.stops += 1
        if self.stop_limit is not None and self.stops > self.stop_limit:
            raise StopLimit(
                f"the design's watched outputs changed more than {self.stop_limit} times "
                f"(the last: {port.name} at edge {cycle}), over this run's budget"
            )
        return Stop(cycle, port.name, self._cooked(port, raw))

    def _ran_to(self, cycle, captured):
        """The bookkeeping after a run to ``cycle`` (``captured`` frames filtered so far)."""
        self._cycle = cycle
        while self._captured < captured:
            self._filtered = self._captures.popleft()
            self._captured += 1

    # --- what a backend implements -----------------------------------------------------------

    def _raw_schedule_many(self, index, edges, raws):
        for edge, raw in zip(edges.tolist(), raws.tolist()):
            self._raw_schedule(edge, index, raw)

    def _raw_record(self, cycles):
        """``(cycle, port index, raw value)`` of every watched change over ``cycles``
        edges (a ``run`` loop; a compiled backend runs it in the model)."""
        end = self._cycle + cycles
        while True:
            cycle, index, raw, captured = self._raw_run(end - self._cycle)
            self._ran_to(cycle, captured)
            if index < 0:
                return
            yield cycle, index, raw

    def _raw_reset(self):
        raise NotImplementedError

    def _raw_poke(self, index, raw):
        raise NotImplementedError

    def _raw_peek(self, index):
        raise NotImplementedError

    def _raw_schedule(self, edge, index, raw):
        raise NotImplementedError

    def _raw_watch(self, indices):
        raise NotImplementedError

    def _raw_stream(self, frame, timing, capture):
        raise NotImplementedError

    def _raw_run(self, cycles):
        """Returns ``(cycle, stop port index or -1, raw value, frames captured so far)``."""
        raise NotImplementedError
