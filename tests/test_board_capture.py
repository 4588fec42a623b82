"""OV7670 capture against a simulated camera: byte-level PCLK/VSYNC/HREF timing with blanking,
crossing from the PCLK domain into ``sync``; the framed stream must match exactly."""

import random

import pytest
from amaranth.hdl import ClockDomain, Module
from amaranth.sim import Simulator

from fpga_robotics.hw.board.ov7670_capture import OV7670Capture

# Blanking (in PCLK cycles) of the simulated camera; small but with every phase present.
VSYNC_CYCLES = 5
FRONT_PORCH = 4  # after VSYNC falls, before the first line
HBLANK = 6  # HREF low between lines
BACK_PORCH = 5  # after the last line, before the next VSYNC


def camera_frames(seed, width, height, frames):
    rng = random.Random(seed)
    return [
        [
            [(rng.randrange(16), rng.randrange(16), rng.randrange(16)) for _ in range(width)]
            for _ in range(height)
        ]
        for _ in range(frames)
    ]


def expected_stream(frames, lead_in):
    """(packed pixel, first, last) for every pixel, from the frames alone."""
    out = []
    for x, (r, g, b) in enumerate(lead_in):
        out.append(((r << 8) | (g << 4) | b, 0, int(x == len(lead_in) - 1)))
    for frame in frames:
        for y, line in enumerate(frame):
            for x, (r, g, b) in enumerate(line):
                out.append(
                    ((r << 8) | (g << 4) | b, int(x == 0 and y == 0), int(x == len(line) - 1))
                )
    return out


def run_capture(frames, lead_in, *, sync_period, pclk_period, fifo_depth=16, seed=0):
    dut = OV7670Capture(fifo_depth=fifo_depth)
    m = Module()
    m.domains.sync = ClockDomain("sync")
    m.domains.pclk = ClockDomain("pclk")
    m.submodules.dut = dut
    sim = Simulator(m)
    sim.add_clock(sync_period, domain="sync")
    sim.add_clock(pclk_period, domain="pclk", phase=pclk_period * 0.37)
    rng = random.Random(seed + 1)
    got = []
    state = {"camera_done": False, "overflow": 0}

    async def send_line(ctx, line):
        for r, g, b in line:
            # Byte 1: xxxxRRRR (the top nibble is don't-care: make it noise); byte 2: GGGGBBBB.
            for byte in ((rng.randrange(16) << 4) | r, (g << 4) | b):
                ctx.set(dut.href, 1)
                ctx.set(dut.data, byte)
                await ctx.tick("pclk")
        for _ in range(HBLANK):
            ctx.set(dut.href, 0)
            ctx.set(dut.data, rng.randrange(256))  # bus noise in blanking must be ignored
            await ctx.tick("pclk")

    async def camera(ctx):
        for _ in range(3):
            await ctx.tick("pclk")
        if lead_in:  # the camera was already mid-frame when the design came out of reset
            await send_line(ctx, lead_in)
        for frame in frames:
            ctx.set(dut.vsync, 1)
            for _ in range(VSYNC_CYCLES):
                await ctx.tick("pclk")
            ctx.set(dut.vsync, 0)
            for _ in range(FRONT_PORCH):
                await ctx.tick("pclk")
            for line in frame:
                await send_line(ctx, line)
            for _ in range(BACK_PORCH):
                await ctx.tick("pclk")
        for _ in range(20):
            await ctx.tick("pclk")
        state["camera_done"] = True

    async def sink(ctx):
        async for _clk, _rst, valid, payload, overflow in ctx.tick("sync").sample(
            dut.pixels.valid, dut.pixels.payload, dut.overflow
        ):
            if valid:
                got.append((payload.pixel.as_value().value, int(payload.first), int(payload.last)))
            state["overflow"] |= overflow

    sim.add_testbench(camera)
    sim.add_process(sink)
    total_bytes = sum(2 * len(line) + HBLANK for f in frames for line in f)
    budget = (total_bytes + len(frames) * 40 + 2 * len(lead_in) + 100) * pclk_period
    sim.run_until(budget * 1.5)  # watchdog: a hung design fails below instead of hanging
    assert state["camera_done"], "the simulated camera did not finish within the time budget"
    return got, state["overflow"]


@pytest.mark.parametrize(
    "sync_period,pclk_period",
    [
        (20e-9, 80e-9),  # 50 MHz design, 12.5 MHz PCLK: the board's worst case
        (20e-9, 320e-9),  # PCLK divided by 4 (the QQVGA register table)
        (20e-9, 45e-9),  # PCLK faster than half the design clock, unrelated phase
    ],
)
def test_capture_yields_exact_framed_stream(sync_period, pclk_period):
    frames = camera_frames(seed=7, width=5, height=3, frames=2)
    lead_in = [(1, 2, 3), (4, 5, 6)]
    got, overflow = run_capture(frames, lead_in, sync_period=sync_period, pclk_period=pclk_period)
    assert got == expected_stream(frames, lead_in)
    assert overflow == 0


def test_capture_rgb444_byte_order():
    # One recognisable pixel: first byte 0xA3 (x=A, R=3), second 0x5C (G=5, B=C) -> 0x35C.
    frames = [[[(0x3, 0x5, 0xC)]]]
    got, _ = run_capture(frames, [], sync_period=20e-9, pclk_period=80e-9)
    assert got == [(0x35C, 1, 1)]


def test_fifo_overflow_is_flagged_and_does_not_hang():
    # A design clock far slower than the pixel rate: the FIFO must overflow, be flagged, and
    # what does come out is a subsequence of the real stream.
    frames = camera_frames(seed=3, width=8, height=4, frames=1)
    got, overflow = run_capture(frames, [], sync_period=400e-9, pclk_period=20e-9, fifo_depth=4)
    assert overflow == 1
    expected = expected_stream(frames, [])
    assert 0 < len(got) < len(expected)
    it = iter(expected)
    assert all(any(p == e for e in it) for p in got)
