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
Amaranth only starts waveforms at time 0 through its public API; this backend starts them later
through the simulation engine's own ``write_vcd`` (Amaranth 0.5), which dumps the current
values first.
"""

import os
import tempfile
import weakref

import numpy as np
from amaranth import Cat, ClockDomain, Const, Elaboratable, Module, Mux, Signal, Value
from amaranth.sim import Simulator

from ...hw.top import FollowTarget
from .base import BackendError, DesignBackend, FrameResult

__all__ = ["PysimBackend"]

#: Simulated clock period. Only the number of edges matters; 1 us keeps VCD times readable.
PERIOD = 1e-6

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
        when the last requested frame is done (or at ``close()``/``reset()``).
    """

    name = "pysim"

    def __init__(self, params=None, *, line_blank=0, frame_blank=0, waveform=None):
        super().__init__(params, line_blank=line_blank, frame_blank=frame_blank, waveform=waveform)
        if waveform is not None:
            waveform.check("pysim", hint="or the verilator backend for .fst")
        self.dut = FollowTarget(self.params)
        self._harness = _Harness(self.dut)
        self._sim = Simulator(self._harness)
        self._sim.add_clock(PERIOD)
        self._started = False  # the testbench is added with the first job (see _submit)
        self._job = None
        self._outcome = None
        self._broken = None
        self._vcd = None  # open waveform writer (a context manager)
        self._traced = False  # the requested waveform has been written
        p = self.params
        self._color_sel = None
        self._lane_flags = np.zeros((p.height, p.width), dtype=np.uint16)
        self._lane_flags[:, -1] |= LAST
        self._lane_flags[0, 0] |= FIRST

    # --- host side ------------------------------------------------------------------------

    def _reset(self):
        self._finish_trace()
        self._submit(("reset",))

    def _run_frame(self, packed, color_sel):
        index = self.frames_processed
        if (self.waveform is not None and not self._traced and self._vcd is None
                and self.waveform.covers(index)):
            self._start_trace()
        try:
            result = self._submit(("frame", packed, color_sel))
        finally:
            if self._vcd is not None and index >= self.waveform.last_frame:
                self._finish_trace()
        return result

    def close(self):
        self._finish_trace()

    def _submit(self, job):
        if self._broken is not None:
            raise BackendError(
                f"the pysim simulation failed earlier ({self._broken}); create a new backend"
            )
        if not self._started:
            # Added lazily: Amaranth creates the coroutine right away, and a backend that
            # never ran would otherwise warn about a coroutine never awaited.
            self._sim.add_testbench(self._testbench)
            self._started = True
        self._job = job
        self._outcome = None
        advance = self._sim.advance
        try:
            while self._job is not None:
                advance()
        except BackendError:
            raise
        except Exception as exc:  # a failure inside the simulator leaves it unusable
            self._broken = f"{type(exc).__name__}: {exc}"
            self._job = None
            raise BackendError(f"pysim simulation failed: {self._broken}") from exc
        outcome, self._outcome = self._outcome, None
        if isinstance(outcome, BaseException):
            raise outcome
        return outcome

    def _start_trace(self):
        engine = getattr(self._sim, "_engine", None)
        if engine is None or not hasattr(engine, "write_vcd"):
            raise BackendError(
                "this Amaranth version cannot start a waveform in mid-simulation; "
                "use the model, cxxrtl or verilator backend for waveforms"
            )
        # Written under a temporary name and renamed when complete, so that an interrupted
        # run never leaves a half-written file at the requested path.
        path = os.path.abspath(os.fspath(self.waveform.path))
        fd, self._vcd_tmp = tempfile.mkstemp(
            prefix=".tmp-", suffix=os.path.basename(path), dir=os.path.dirname(path)
        )
        os.close(fd)
        self._vcd_cleanup = weakref.finalize(self, _remove_if_exists, self._vcd_tmp)
        self._vcd = engine.write_vcd(
            vcd_file=self._vcd_tmp, gtkw_file=None, traces=(), fs_per_delta=0
        )
        self._vcd.__enter__()

    def _finish_trace(self):
        if self._vcd is not None:
            vcd, self._vcd = self._vcd, None
            self._traced = True
            vcd.__exit__(None, None, None)
            os.chmod(self._vcd_tmp, _default_file_mode())  # mkstemp made it private
            os.replace(self._vcd_tmp, os.fspath(self.waveform.path))
            self._vcd_cleanup.detach()

    # --- simulation side (runs inside the simulator) -----------------------------------------

    async def _testbench(self, ctx):
        while True:
            job = self._job
            try:
                if job[0] == "reset":
                    ctx.set(self._harness.rst, 1)
                    await ctx.tick()
                    ctx.set(self._harness.rst, 0)
                    self._color_sel = None
                    outcome = None
                else:
                    outcome = await self._frame(ctx, job[1], job[2])
            except BackendError as exc:
                outcome = exc
            self._outcome = outcome
            self._job = None
            # Park between two edges until the host hands over the next job.
            await ctx.delay(PERIOD / 4)

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
                await ctx.tick().repeat(end - edge)
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
            await ctx.tick().repeat(width)
            ctx.set(harness.line_valid, 0)
            self._collect_line(ctx, lines)
            if lb:
                await ctx.tick().repeat(lb)
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
        await ctx.tick()
        self._collect_line(ctx, lines)


def _default_file_mode():
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _remove_if_exists(path):
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


if __name__ == "__main__":  # the CLI lives in the application layer
    from ...pysim_bench import cli

    cli()
