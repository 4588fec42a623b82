"""The ``pysim`` pin backend: the design in Amaranth's own simulator, the reference of the
compiled pin backends (slow: a few tens of microseconds per edge).

One ``Simulator`` lives as long as the backend. A single async testbench owns the design:
the host hands it a job (``run``, ``poke``, ``peek``, ``reset``) and advances the simulator
until the job is done. The testbench drives the clock itself (``ctx.set`` of the domain's
clock high, then low: one rising edge, settled before the testbench goes on), so simulated
time means nothing here and only edges are counted; between jobs it parks on a delay
(``JobLoop``, shared with the pysim frame backend).
"""

import bisect

from amaranth import ClockDomain, Elaboratable, Module, Signal
from amaranth.sim import Simulator

from ...hw.verilog import verilog_ports
from ..backends.pysim_jobs import JobLoop
from .base import PinError
from .host import HostPins, capture_error

__all__ = ["PysimPins"]

_FIRST, _LAST, _PIXEL = 1 << 12, 1 << 13, 0x0FFF
#: Simulated time a parked testbench waits for its next job (any positive time will do).
_PARK = 1e-6
_NEVER = float("inf")


class _Harness(Elaboratable):
    """The design in a ``sync`` domain whose clock and reset the testbench drives."""

    def __init__(self, dut):
        self.dut = dut
        self.domain = ClockDomain("sync")
        self.rst = Signal(name="")

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = self.domain
        m.d.comb += self.domain.rst.eq(self.rst)
        m.submodules.dut = self.dut
        return m


class PysimPins(HostPins):
    """The design simulated edge by edge by Amaranth's Python simulator."""

    name = "pysim"

    def __init__(self, source):
        super().__init__(source)
        dut = source.component()
        signals = verilog_ports(dut)
        self._signals = [signals[name][0] for name in self.ports]
        self._masks = [(1 << p.width) - 1 for p in self._port_list]
        self._inputs_idx = [i for i, p in enumerate(self._port_list) if p.direction == "in"]
        self._harness = _Harness(dut)
        self._sim = Simulator(self._harness)
        self._jobs = JobLoop(self._sim, self._run_job, park=_PARK, error=PinError)
        self._submit = self._jobs.submit
        pixels, filtered = source.pixels, source.filtered
        self._pixel_sigs = None if pixels is None else [signals[n][0] for n in pixels]
        self._filtered_sigs = None if filtered is None else [signals[n][0] for n in filtered]
        self._clear()
        self._submit(("reset",))

    def _clear(self):
        self._sim_cycle = 0
        self._queue = []  # (edge, sequence, index, raw), sorted
        self._sequence = 0
        self._frame = None
        self._next_pixel = _NEVER
        self._valid_off = _NEVER
        self._pixel_at = (0, 0)
        self._buffers = []  # capture buffers, flat, oldest first
        self._n_captured = 0  # beats of the oldest buffer
        self._frames_captured = 0
        self._order = []
        self._prev = {}

    # --- host side ------------------------------------------------------------------------

    def _raw_reset(self):
        self._clear()
        self._submit(("reset",))

    def _raw_poke(self, index, raw):
        self._submit(("set", index, raw))

    def _raw_peek(self, index):
        return self._submit(("get", index))

    def _raw_schedule(self, edge, index, raw):
        if edge == self._sim_cycle + 1:
            self._raw_poke(index, raw)
            return
        bisect.insort(self._queue, (edge, self._sequence, index, raw))
        self._sequence += 1

    def _raw_watch(self, indices):
        self._order = list(indices)
        self._prev = {i: self._raw_peek(i) for i in indices}

    def _raw_stream(self, frame, timing, capture):
        self._frame = (frame.tolist(), frame.shape[1], frame.shape[0], timing)
        self._pixel_at = (0, 0)
        self._next_pixel = timing.start
        if capture is not None:
            self._buffers.append(capture.reshape(-1))
        if timing.start == self._sim_cycle + 1:
            self._submit(("events",))

    def _raw_run(self, cycles):
        return self._submit(("run", cycles))

    # --- simulation side --------------------------------------------------------------------

    async def _run_job(self, ctx, job):
        return self._do(ctx, job)

    def _do(self, ctx, job):
        kind = job[0]
        if kind == "run":
            return self._run(ctx, job[1])
        if kind == "get":
            return ctx.get(self._signals[job[1]]) & self._masks[job[1]]
        if kind == "set":
            self._set(ctx, job[1], job[2])
        elif kind == "events":
            self._events(ctx, self._sim_cycle + 1)
        elif kind == "reset":
            for i in self._inputs_idx:
                ctx.set(self._signals[i], 0)
            ctx.set(self._harness.rst, 1)
            self._edge(ctx)
            ctx.set(self._harness.rst, 0)
        return None

    def _set(self, ctx, index, raw):
        port = self._port_list[index]
        ctx.set(self._signals[index], self._cooked(port, raw))

    def _edge(self, ctx):
        clk = self._harness.domain.clk
        ctx.set(clk, 1)
        ctx.set(clk, 0)

    def _events(self, ctx, e):
        """The inputs given for edge ``e``: scheduled changes in order, then the pixel slot."""
        queue = self._queue
        while queue and queue[0][0] == e:
            _, _, index, raw = queue.pop(0)
            self._set(ctx, index, raw)
        if self._next_pixel == e:
            pixels, width, height, timing = self._frame
            y, x = self._pixel_at
            payload = pixels[y][x] & _PIXEL
            if y == 0 and x == 0:
                payload |= _FIRST
            if x == width - 1:
                payload |= _LAST
            valid, data = self._pixel_sigs
            ctx.set(valid, 1)
            ctx.set(data, payload)
            self._valid_off = e + 1
            x += 1
            if x == width:
                x, y = 0, y + 1
            self._pixel_at = (y, x)
            self._next_pixel = _NEVER if y == height else timing.edge_of(y, x)
        elif self._valid_off == e:
            valid, data = self._pixel_sigs
            ctx.set(valid, 0)
            ctx.set(data, 0)
            self._valid_off = _NEVER

    def _capture(self, ctx):
        valid, data = self._filtered_sigs
        if not ctx.get(valid):
            return
        if not self._buffers:
            raise capture_error(True, 0)
        payload = ctx.get(data)
        buffer = self._buffers[0]
        n = self._n_captured
        width = self.source.frame_size[0]
        expect = (_FIRST if n == 0 else 0) | (_LAST if n % width == width - 1 else 0)
        if payload & (_FIRST | _LAST) != expect:
            raise capture_error(False, n)
        buffer[n] = payload & _PIXEL
        n += 1
        if n == buffer.size:
            self._buffers.pop(0)
            self._frames_captured += 1
            n = 0
        self._n_captured = n

    def _changed(self, ctx):
        for index in self._order:
            raw = ctx.get(self._signals[index]) & self._masks[index]
            if raw != self._prev[index]:
                self._prev[index] = raw
                return index, raw
        return None

    def _run(self, ctx, cycles):
        end = self._sim_cycle + cycles
        changed = self._changed(ctx)
        try:
            while changed is None and self._sim_cycle < end:
                if self._filtered_sigs is not None:
                    self._capture(ctx)  # the beat the coming edge samples
                self._edge(ctx)
                self._sim_cycle += 1
                self._events(ctx, self._sim_cycle + 1)
                changed = self._changed(ctx)
        except PinError:
            self._cycle = self._sim_cycle
            raise
        index, raw = changed if changed is not None else (-1, 0)
        return self._sim_cycle, index, raw, self._frames_captured
