"""The ``pysim`` backend: ``FollowTarget`` in Amaranth's own Python simulator.

One ``Simulator`` lives as long as the backend, so the design's state (motor outputs, lost
count, last side) persists across frames exactly as in hardware. A single long-running async
testbench does the work: ``process_frame`` hands it a job and advances the simulator until the
job is done; between jobs the testbench parks a quarter clock period after the last edge.

Per-cycle Python work is kept minimal: a small simulation-only harness around the design holds
one whole line of pixels in a wide signal (the testbench sets it once per line and then lets
the clock run for the line with ``ctx.tick().repeat``), picks the pixel of each cycle, and
collects the filtered pixels of a line into another wide signal that the testbench reads once
per line. Only the few cycles after the frame's last pixel are stepped one by one, to detect
``frame_done``.

A ``WaveformRequest`` gets a VCD of every signal of the design from the start of frame
``first_frame`` to the end of frame ``last_frame``. The harness's signals have private (empty)
names, which Amaranth leaves out of waveforms, so the wide line signals do not swamp the file.
Amaranth's public ``Simulator.write_vcd`` starts only at time 0, so a backend with a waveform
request records from its first job into a hidden temporary file next to the target. The
testbench counts the clock edges it awaits, which gives the exact time of every frame's start
and end (rising edge n is at (n - 1/2) ``PERIOD``; a job starts a quarter period after the
previous job's last edge). When the last requested frame is done (or at ``close()``, or at a
``reset()`` inside the window) the recording stops and ``vcd_trim.trim_vcd`` cuts the window
out of it into the requested path: the header, the values at the window's start as the initial
dump at time 0, then only the changes inside the window, at their simulation times. The
recording is removed in every case, also on an error or Ctrl-C, or when the backend is dropped.

Cost: the frames before ``first_frame`` are traced too (and then cut), so they run at the
traced speed, not the untraced one. At 160x120 a frame takes about 1.8 s traced instead of
0.6 s (3 times as long), the recording grows by about 4 MB a frame, and cutting the window out
reads the recording at about 0.1 s a frame. A late ``first_frame`` is therefore costly;
once the window is written, tracing stops and the frames run at the untraced speed again.
"""

import os
import tempfile
import weakref
from pathlib import Path

import numpy as np
from amaranth import Cat, ClockDomain, Const, Elaboratable, Module, Mux, Signal, Value
from amaranth.sim import Simulator

from ...hw.top import FollowTarget
from ..files import atomic_output
from .base import BackendError, DesignBackend, FrameResult
from .pysim_jobs import JobLoop
from .vcd_trim import trim_vcd

__all__ = ["PysimBackend"]

#: Simulated clock period. Only the number of edges matters; 1 us keeps VCD times readable.
PERIOD = 1e-6
#: The same in femtoseconds, the unit of Amaranth's VCD times (a whole number of them,
#: divisible by 4). Rising edge n (from 1) is at (n - 1/2) periods (``add_clock`` with phase
#: PERIOD / 2); a job starts a quarter period after the previous job's last edge.
PERIOD_FS = round(PERIOD * 10**15)

#: Bits per pixel lane in the harness's line signals (a 14-bit payload, rounded up so that
#: numpy can pack and unpack lines as little-endian uint16).
LANE = 16
FIRST = 1 << 12
LAST = 1 << 13

#: Edges the driver waits for ``frame_done`` beyond the documented latency before it declares
#: the design hung.
WATCHDOG_MARGIN = 1024


class _Harness(Elaboratable):
    """Simulation-only wrapper: the clock domain with its reset, and the line-at-a-time pixel
    driver and filtered-line collector. Its own signals have private names (``name=""``):
    they stay out of waveforms."""

    def __init__(self, dut):
        self.dut = dut
        width = dut.params.width
        self.rst = Signal(name="")
        self.done_count = Signal(16, name="")  # frame_done pulses seen (mod 2**16)
        self.line = Signal(LANE * width, name="")  # payload of pixel x in lane x
        self.line_valid = Signal(name="")
        self.captured = Signal(LANE * width, name="")  # the last complete line of `filtered`
        self.captured_lines = Signal(16, name="")  # complete lines collected (mod 2**16)

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = cd = ClockDomain("sync")
        m.d.comb += cd.rst.eq(self.rst)
        m.submodules.dut = dut = self.dut
        with m.If(dut.frame_done):
            m.d.sync += self.done_count.eq(self.done_count + 1)

        width = dut.params.width
        index = Signal(range(width), name="")  # pixel of the line on the input now
        with m.If(self.line_valid):
            m.d.sync += index.eq(Mux(index == width - 1, 0, index + 1))
        m.d.comb += [
            dut.pixels.valid.eq(self.line_valid),
            dut.pixels.payload.eq(self.line.word_select(index, LANE)),
        ]

        # Filtered payloads of the line so far, newest on top; a full line is copied out.
        shift = Signal(LANE * width, name="")
        count = Signal(range(width), name="")
        shifted = Cat(shift[LANE:], Value.cast(dut.filtered.payload), Const(0, LANE - 14))
        with m.If(dut.filtered.valid):
            m.d.sync += shift.eq(shifted)
            with m.If(count == width - 1):
                m.d.sync += [
                    count.eq(0),
                    self.captured.eq(shifted),
                    self.captured_lines.eq(self.captured_lines + 1),
                ]
            with m.Else():
                m.d.sync += count.eq(count + 1)
        return m


class PysimBackend(DesignBackend):
    """``FollowTarget`` simulated cycle by cycle by Amaranth's Python simulator.

    Parameters
    ----------
    params : FollowTargetParams, optional
    line_blank, frame_blank : int
        Idle cycles after every line / at least after the frame (see ``base.py``).
    waveform : WaveformRequest, optional
        Write a ``.vcd`` of the frames ``first_frame`` .. ``last_frame``. The file is complete
        when the last requested frame is done (or at ``close()``/``reset()``). The frames
        before ``first_frame`` are traced too, and run slower for it (see the module's notes).
    """

    name = "pysim"

    def __init__(self, params=None, *, line_blank=0, frame_blank=0, waveform=None):
        super().__init__(params, line_blank=line_blank, frame_blank=frame_blank, waveform=waveform)
        if waveform is not None:
            waveform.check("pysim", hint="or the verilator backend for .fst")
        self.dut = FollowTarget(self.params)
        self._harness = _Harness(self.dut)
        self._sim = Simulator(self._harness)
        self._sim.add_clock(PERIOD, phase=PERIOD / 2)
        self._jobs = JobLoop(self._sim, self._run_job, park=PERIOD / 4, error=BackendError)
        self._edges = 0  # rising clock edges the testbench has awaited
        self._recording = None  # the whole-run VCD the requested window is cut from
        self._traced = False  # the requested waveform has been written (or given up)
        p = self.params
        self._color_sel = None
        self._lane_flags = np.zeros((p.height, p.width), dtype=np.uint16)
        self._lane_flags[:, -1] |= LAST
        self._lane_flags[0, 0] |= FIRST

    # --- host side ------------------------------------------------------------------------

    def _reset(self):
        if self._recording is not None and self._recording.start is not None:
            self._finish_trace()  # the window ends with the last frame before the reset
        self._submit(("reset",))

    def _run_frame(self, packed, color_sel):
        index = self.frames_processed
        if not self._jobs.started:
            self._start()
        recording = self._recording
        if recording is not None and recording.start is None and self.waveform.covers(index):
            recording.start = self._edges
        try:
            result = self._submit(("frame", packed, color_sel))
        finally:
            if (
                recording is not None
                and recording.start is not None
                and index >= self.waveform.last_frame
            ):
                self._finish_trace()
        return result

    def close(self):
        self._finish_trace()

    def _start(self):
        """Start the simulation: the waveform recording (only possible at time 0), then the
        testbench."""
        if self.waveform is not None and not self._traced:
            self._recording = _Recording(self._sim, self.waveform.path)
        self._jobs.start()

    def _submit(self, job):
        if not self._jobs.started:
            self._start()
        return self._jobs.submit(job)

    def _finish_trace(self):
        """Stop recording; write the window to the requested path if it has begun."""
        if self._recording is not None:
            recording, self._recording = self._recording, None
            self._traced = True
            recording.finish(self.waveform.path, self._edges)

    # --- simulation side (runs inside the simulator) -----------------------------------------

    async def _run_job(self, ctx, job):
        if job[0] == "reset":
            ctx.set(self._harness.rst, 1)
            await self._ticks(ctx, 1)
            ctx.set(self._harness.rst, 0)
            self._color_sel = None
            return None
        return await self._frame(ctx, job[1], job[2])

    async def _frame(self, ctx, packed, color_sel):
        p = self.params
        dut, harness = self.dut, self._harness
        width, height, lb = p.width, p.height, self.line_blank
        if color_sel != self._color_sel:
            ctx.set(dut.color_sel, color_sel)
            self._color_sel = color_sel
        lanes = packed | self._lane_flags
        done_before = ctx.get(harness.done_count)

        lines = await self._stream_lines(ctx, lanes)
        edge = height * (width + lb)  # edges so far in this call
        if ctx.get(harness.done_count) != done_before:
            raise BackendError("frame_done came before the frame's last pixel was sampled")

        # After the pixels: step until frame_done shows (the watchdog bounds the wait),
        # then until both the frame blanking and the motor latency have passed.
        last_pixel = edge - lb
        deadline = last_pixel + p.result_latency + p.motor_latency + WATCHDOG_MARGIN
        done_edge = None
        while done_edge is None:
            if edge >= deadline:
                raise BackendError(
                    f"frame_done did not come within {deadline - last_pixel} cycles after the "
                    f"frame's last pixel (documented: {p.result_latency}); the design hung"
                )
            await self._tick_collect(ctx, lines)
            edge += 1
            if ctx.get(dut.frame_done):
                done_edge = edge
        end = max(height * (width + lb) + self.frame_blank, done_edge + p.motor_latency)
        while edge < end:
            if len(lines) >= height:
                await self._ticks(ctx, end - edge)
                edge = end
            else:
                await self._tick_collect(ctx, lines)
                edge += 1
        self._collect_line(ctx, lines)
        if len(lines) != height:
            raise BackendError(
                f"the design put out {len(lines)} complete filtered lines (of {width} pixels) "
                f"for a frame of {height}"
            )
        filtered = np.frombuffer(b"".join(lines), dtype="<u2").reshape(height, width)
        flags = filtered & (FIRST | LAST)
        if not np.array_equal(flags, self._lane_flags):
            raise BackendError("the filtered stream's first/last flags differ from the input's")
        return FrameResult(
            filtered=(filtered & 0xFFF).astype(np.uint16),
            found=bool(ctx.get(dut.found)),
            proximity=ctx.get(dut.proximity),
            centroid_x=ctx.get(dut.centroid_x),
            centroid_leds=ctx.get(dut.centroid_leds),
            motor_left=ctx.get(dut.motor_left),
            motor_right=ctx.get(dut.motor_right),
            cycles=end,
        )

    async def _stream_lines(self, ctx, lanes):
        """Drive the frame one line at a time; return the filtered lines collected so far."""
        harness, lb = self._harness, self.line_blank
        width = self.params.width
        lines = []
        self._captured_seen = ctx.get(harness.captured_lines)
        for row in lanes.astype("<u2", copy=False):
            ctx.set(harness.line, int.from_bytes(row.tobytes(), "little"))
            ctx.set(harness.line_valid, 1)
            await self._ticks(ctx, width)
            ctx.set(harness.line_valid, 0)
            self._collect_line(ctx, lines)
            if lb:
                await self._ticks(ctx, lb)
        return lines

    def _collect_line(self, ctx, lines):
        """Take the harness's newest complete filtered line, if there is one not yet read."""
        harness = self._harness
        seen = ctx.get(harness.captured_lines)
        new = (seen - self._captured_seen) & 0xFFFF
        if new == 0:
            return
        if new > 1:
            raise BackendError("internal: the filtered lines came faster than they were read")
        self._captured_seen = seen
        lines.append(ctx.get(harness.captured).to_bytes(LANE // 8 * self.params.width, "little"))

    async def _tick_collect(self, ctx, lines):
        """One edge, then collect a filtered line if one has completed."""
        await self._ticks(ctx, 1)
        self._collect_line(ctx, lines)

    async def _ticks(self, ctx, count):
        """Wait for ``count`` rising edges and count them: the waveform's window is found
        from the edge count (every wait for the clock goes through here)."""
        if count == 1:
            await ctx.tick()
        else:
            await ctx.tick().repeat(count)
        self._edges += count


def _edge_time(edges):
    """Simulation time (fs) of rising edge ``edges`` (from 1); 0 before the first."""
    return 0 if edges == 0 else PERIOD_FS // 2 + (edges - 1) * PERIOD_FS


class _Recording:
    """The VCD of the whole simulation from time 0, in a hidden temporary file next to the
    requested path, that the requested window is cut from. The file goes away at ``finish``,
    or when the recording is dropped unfinished."""

    def __init__(self, sim, path):
        path = Path(os.path.abspath(os.fspath(path)))
        fd, raw = tempfile.mkstemp(
            prefix=f".{path.stem}.", suffix=".untrimmed.vcd", dir=path.parent
        )
        os.close(fd)
        self.raw = Path(raw)
        self._cleanup = weakref.finalize(self, self.raw.unlink, missing_ok=True)
        self.start = None  # edges before the first requested frame, once it has begun
        try:
            self._writer = sim.write_vcd(str(self.raw))
            self._writer.__enter__()
        except BaseException:
            self._cleanup()
            raise

    def finish(self, path, edges):
        """Stop recording after ``edges`` edges; if the window has begun, write it to
        ``path`` (atomically). The recording is removed in any case."""
        try:
            self._writer.__exit__(None, None, None)
            if self.start is not None:
                start = _edge_time(self.start)
                # Up to the time the next job would start: a quarter period after the edge.
                end = _edge_time(edges) + PERIOD_FS // 4
                with open(self.raw) as src, atomic_output(path, what="waveform") as dst:
                    trim_vcd(src, dst, start, end, timescale="1 fs")
        finally:
            self._cleanup()
