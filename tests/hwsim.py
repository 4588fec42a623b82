"""Testbench helpers for the gateware tests: cycle schedules, a traced run, a watchdog.

A test builds a *schedule*: one entry per clock edge, the values the testbench drives so that
they are sampled at that edge (``None`` for "no transfer"). Edges are numbered from 1: schedule
index k is sampled at edge k + 1. ``run_schedule`` clocks the design through it (plus some idle
edges) and returns traces: trace index j holds an output's value right after edge j + 1.

So for a pixel at schedule index k (sampled at edge P = k + 1):
- it is *sampled* from a registered output stream at edge P + L when that stream is valid at
  trace index j = k + L - 1 (the ``filter_latency`` convention);
- an output that *shows* right after edge P + L is at trace index j = k + L (the
  ``result_latency`` convention).

Every run has a watchdog: a background testbench that fails the simulation after a bound on
the number of edges, so a hung design fails the test instead of hanging CI.
"""

from typing import NamedTuple

import numpy as np
from amaranth import ClockDomain, Elaboratable, Module, Signal, Value
from amaranth.hdl import ValueCastable
from amaranth.sim import Simulator

__all__ = [
    "Step",
    "WatchdogTimeout",
    "WithReset",
    "edges_where",
    "frame_schedule",
    "lines_schedule",
    "match_lines_schedule",
    "match_transfer",
    "pack_transfer",
    "run_follow_target",
    "run_schedule",
    "run_testbench",
    "small_params",
    "stream_get",
    "stream_put",
    "unpack_lanes",
]

#: Clock period of the test simulations (its value does not matter, only the edge count).
PERIOD = 1e-6

FIRST_BIT = 12
LAST_BIT = 13


class Step(NamedTuple):
    """A schedule entry that also sets other inputs before its edge."""

    payload: int | None
    sets: list


class WatchdogTimeout(AssertionError):
    """The simulation ran longer than its watchdog allows."""


class WithReset(Elaboratable):
    """Wraps a design in an explicit ``sync`` domain whose reset a testbench can drive
    (``ctx.set(wrapper.rst, 1)``)."""

    def __init__(self, dut):
        self.dut = dut
        self.rst = Signal()

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = cd = ClockDomain("sync")
        m.d.comb += cd.rst.eq(self.rst)
        m.submodules.dut = self.dut
        return m


def _cast(value):
    return value.as_value() if isinstance(value, ValueCastable) else Value.cast(value)


def pack_transfer(pixel, first=False, last=False):
    """The 14-bit ``FramedPixel`` payload: pixel 11:0, ``first`` bit 12, ``last`` bit 13."""
    return (int(pixel) & 0xFFF) | (int(first) << FIRST_BIT) | (int(last) << LAST_BIT)


def lines_schedule(lines, *, line_blank=0, first=True, gaps=None):
    """Schedule of pixel payloads for ``lines`` (a list of 1-D sequences of packed pixels,
    possibly of different lengths: malformed frames). ``first`` on the first pixel of the
    first line, ``last`` on the final pixel of every line; ``line_blank`` idle edges after
    each line; ``gaps`` maps a flat pixel index to a number of idle edges inserted before it
    (blanking inside a line)."""
    gaps = gaps or {}
    schedule = []
    index = 0
    for y, line in enumerate(lines):
        line = list(line)
        for x, pixel in enumerate(line):
            schedule.extend([None] * gaps.get(index, 0))
            schedule.append(
                pack_transfer(pixel, first=first and y == 0 and x == 0, last=x == len(line) - 1)
            )
            index += 1
        schedule.extend([None] * line_blank)
    return schedule


def frame_schedule(packed, *, line_blank=0, gaps=None):
    """Schedule of a well-formed frame (H, W) of packed RGB444."""
    return lines_schedule(list(np.asarray(packed)), line_blank=line_blank, gaps=gaps)


def edges_where(trace, name):
    """Indices of the edges after which ``trace[name]`` is non-zero."""
    return [t for t, v in enumerate(trace[name]) if v]


async def stream_put(ctx, stream, payload):
    """Present one transfer on a non-stallable stream, sampled at the next edge. ``payload``
    is an int (the raw bits) or what the payload's layout accepts."""
    ctx.set(_cast(stream.payload) if isinstance(payload, int) else stream.payload, payload)
    ctx.set(stream.valid, 1)
    await ctx.tick()
    ctx.set(stream.valid, 0)


async def stream_get(ctx, stream, *, timeout=1000):
    """Take the next transfer of a non-stallable stream (waiting at most ``timeout`` edges):
    a transfer happens at the edge where ``valid`` is high. Returns the payload as an int,
    after that edge."""
    payload = _cast(stream.payload)
    for _ in range(timeout + 1):
        if ctx.get(stream.valid):
            value = ctx.get(payload)
            await ctx.tick()
            return value
        await ctx.tick()
    raise WatchdogTimeout(f"no transfer on the stream within {timeout} edges")


def run_testbench(dut, bench, *, watchdog):
    """Simulate ``dut`` with the async testbench ``bench`` and a watchdog that fails the run
    after ``watchdog`` edges."""

    async def watchdog_bench(ctx):
        await ctx.delay(watchdog * PERIOD)  # one timer, no per-edge cost
        raise WatchdogTimeout(f"simulation still running after {watchdog} edges")

    sim = Simulator(dut)
    sim.add_clock(PERIOD)
    sim.add_testbench(bench)
    sim.add_testbench(watchdog_bench, background=True)
    sim.run()


def run_schedule(dut, drive, schedule, probes, *, static=None, tail=64, watchdog=None):
    """Clock ``dut`` through ``schedule`` and return the traced probes.

    Parameters
    ----------
    dut : Elaboratable
    drive : stream interface
        Non-stallable stream driven by the schedule (``valid`` and ``payload``).
    schedule : list
        One entry per edge: a payload int (a transfer sampled at that edge) or ``None``.
        An entry may also be a ``Step(payload, sets)``: ``sets`` is a list of
        ``(signal, value)`` set before that edge (other inputs), ``payload`` as above.
    probes : dict
        ``{name: value}`` to record after every edge.
    static : list
        ``(signal, value)`` pairs set once at the start (e.g. ``color_sel``).
    tail : int
        Idle edges after the schedule.
    watchdog : int
        Maximum edges before the simulation fails (default: the run's length + 100).

    Returns
    -------
    dict
        ``{name: numpy int64 array}``, entry j = the value right after edge j + 1.
    """
    total = len(schedule) + tail
    limit = watchdog if watchdog is not None else total + 100
    probe_items = [(name, _cast(v)) for name, v in probes.items()]
    valid, payload = drive.valid, _cast(drive.payload)
    trace = {name: [] for name in probes}
    done = []

    async def bench(ctx):
        for signal, value in static or ():
            ctx.set(signal, value)
        for t in range(total):
            entry = schedule[t] if t < len(schedule) else None
            if isinstance(entry, Step):
                for signal, value in entry.sets:
                    ctx.set(signal, value)
                entry = entry.payload
            if entry is None:
                ctx.set(valid, 0)
            else:
                ctx.set(payload, entry)
                ctx.set(valid, 1)
            await ctx.tick()
            for name, value in probe_items:
                trace[name].append(ctx.get(value))
        done.append(True)

    run_testbench(dut, bench, watchdog=limit)
    assert done, "testbench did not finish"
    return {name: _as_array(values) for name, values in trace.items()}


def _as_array(values):
    wide = any(v >= 1 << 62 or v < -(1 << 62) for v in values)
    return np.array(values, dtype=object if wide else np.int64)


def unpack_lanes(value, lane_bits, count):
    """Split a wide int (e.g. an ``ArrayLayout`` value) into ``count`` lanes."""
    mask = (1 << lane_bits) - 1
    return tuple((int(value) >> (lane_bits * i)) & mask for i in range(count))


TOP_OUTPUTS = ("found", "proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right")


def run_follow_target(
    dut, frames, color_sels, *, line_blank=0, frame_gap=0, tail=None, gaps=None, extra_schedule=None
):
    """Stream whole frames into a ``FollowTarget`` and trace every port.

    ``frames`` are packed RGB444 (H, W) arrays, ``color_sels`` one code per frame (changed in
    the cycle of the frame's first pixel). ``frame_gap`` idle edges after each frame.
    ``extra_schedule`` (a schedule list) is appended after the frames.

    Returns ``(trace, last_pixel_index)``: the traces of ``run_schedule`` and, for each
    frame, the schedule index of its last pixel.
    """
    schedule = []
    last_index = []
    for frame, sel in zip(frames, color_sels):
        part = frame_schedule(frame, line_blank=line_blank, gaps=gaps)
        part[0] = Step(part[0], [(dut.color_sel, sel)])
        schedule.extend(part)
        last_index.append(len(schedule) - 1 - line_blank)
        schedule.extend([None] * frame_gap)
    schedule.extend(extra_schedule or [])
    p = dut.params
    if tail is None:
        tail = p.result_latency + p.motor_latency + 8
    probes = {
        "filtered_valid": dut.filtered.valid,
        "filtered_payload": dut.filtered.payload,
        "frame_done": dut.frame_done,
        **{name: getattr(dut, name) for name in TOP_OUTPUTS},
    }
    trace = run_schedule(dut, dut.pixels, schedule, probes, tail=tail)
    return trace, last_index


def small_params(**changes):
    """A small geometry for fast tests: 48x12, window 40x10 (8 bins of 5 columns), small
    thresholds so that every proximity level occurs, ``lost_frames=3``."""
    from fpga_robotics.hw.params import FollowTargetParams

    values = {
        "width": 48,
        "height": 12,
        "margin_x": 4,
        "margin_y": 1,
        "min_pixels": 8,
        "proximity_thresholds": (8, 16, 32, 64, 128, 200, 300),
        "lost_frames": 3,
    }
    values.update(changes)
    return FollowTargetParams(**values)


def match_flag_offset(name):
    """Bit offset of field ``name`` ("match", "first", "last") in a ``MatchFlags`` payload."""
    from fpga_robotics.hw.color_filter import MatchFlags

    return MatchFlags[name].offset


def match_transfer(match, first=False, last=False):
    """The ``MatchFlags`` payload with these field values."""
    return sum(
        int(bool(v)) << match_flag_offset(name)
        for name, v in (("match", match), ("first", first), ("last", last))
    )


def match_lines_schedule(lines, *, line_blank=0, first=True, gaps=None):
    """Like ``lines_schedule`` for the tracker's match stream; ``lines`` hold bools."""
    schedule = lines_schedule(
        [[int(bool(v)) for v in line] for line in lines],
        line_blank=line_blank,
        first=first,
        gaps=gaps,
    )
    return [
        None if e is None else match_transfer(e & 1, (e >> FIRST_BIT) & 1, (e >> LAST_BIT) & 1)
        for e in schedule
    ]
