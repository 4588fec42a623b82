"""The robot's logic end to end, as on the board but without pins: a simulated OV7670 sends
frames byte by byte; the GoPiGo3 messages decoded from the SPI wires and the LEDs must match
the golden model of ``FollowTarget`` (speeds x 2 in ticks), so the board path adds no error."""

import gc
import warnings

import numpy as np
import pytest
from amaranth.hdl import ClockDomain, Fragment, Module, UnusedElaboratable
from amaranth.sim import Simulator

from fpga_robotics.hw.board.color_select import SwitchColorSelect
from fpga_robotics.hw.board.gopigo3_spi import GoPiGo3Motors, SPIByteMaster
from fpga_robotics.hw.board.ov7670_capture import OV7670Capture
from fpga_robotics.hw.board.robot_core import RobotCore, RobotTiming
from fpga_robotics.hw.board.sccb import RegisterWrite, SCCBInit
from fpga_robotics.hw.board.ulx3s_top import ULX3SFollowTarget
from fpga_robotics.hw.divider import SequentialDivider
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.models.follow_target import FollowTargetModel

PARAMS = FollowTargetParams(width=48, height=16)
TIMING = RobotTiming.from_cycles(
    xclk_half=2, sccb_quarter=2, spi_half=2, camera_wait=5, reset_wait=8000, motor_wait=30
)
# A short table with a long reset wait: the SCCB phase outlasts one camera frame.
TABLE = [RegisterWrite(0x12, 0x80, "reset", True), RegisterWrite(0x8C, 0x02, "rgb444")]
HBLANK, VSYNC_CYCLES = 4, 6


def red_blob_frame(x0, x1, y0, y1, seed):
    rng = np.random.default_rng(seed)
    # Dull background (never red: r - max(g, b) < 6), a saturated red rectangle.
    r = rng.integers(0, 6, (PARAMS.height, PARAMS.width))
    g = rng.integers(4, 10, (PARAMS.height, PARAMS.width))
    b = rng.integers(4, 10, (PARAMS.height, PARAMS.width))
    r[y0:y1, x0:x1], g[y0:y1, x0:x1], b[y0:y1, x0:x1] = 15, 2, 3
    return ((r << 8) | (g << 4) | b).astype(np.uint16)


def ticks_bytes(dps):
    t = max(-32768, min(32767, 2 * dps)) & 0xFFFF
    return [t >> 8, t & 0xFF]


def test_camera_to_gopigo3_matches_golden_model():
    frames = [
        red_blob_frame(26, 44, 2, 14, seed=1),
        red_blob_frame(6, 20, 3, 13, seed=2),
        red_blob_frame(0, 0, 0, 0, seed=3),
    ]
    model = FollowTargetModel(PARAMS)
    expected_msgs = [[0x08, 0x0F, port, 0, 0x04, 0x00] for port in (1, 2)]
    expected_leds = []
    for frame in frames:
        out = model.process(frame, 0b100)
        expected_msgs += [
            [0x08, 0x0E, 1, *ticks_bytes(out.motor_left)],
            [0x08, 0x0E, 2, *ticks_bytes(out.motor_right)],
        ]
        expected_leds.append(out.tracker.centroid_leds)
    # The scene must exercise the controller: found on one side, then the other, then lost.
    assert expected_leds[0] != 0 and expected_leds[1] != 0 and expected_leds[2] == 0

    core = RobotCore(PARAMS, TIMING, sccb_table=TABLE)
    m = Module()
    m.domains.sync = ClockDomain("sync")
    m.domains.pclk = ClockDomain("pclk")
    m.submodules.core = core
    sim = Simulator(m)
    sim.add_clock(20e-9, domain="sync")
    sim.add_clock(80e-9, domain="pclk", phase=31e-9)
    msgs, leds_after_frame, xclk_edges = [], [], []
    state = {"camera_done": False}

    async def camera(ctx):
        ctx.set(core.switches, 0)  # all switches off: follow red
        # While the registers are being written the camera already sends frames (in its
        # power-on format); here a whole-red frame that would make the robot back off if it
        # reached the design. It must be ignored.
        assert not ctx.get(core.camera_ready)
        await send_frame(ctx, np.full((PARAMS.height, PARAMS.width), 0xF00, np.uint16), blank=0)
        assert not ctx.get(core.camera_ready), "the junk frame must fit in the SCCB time"
        while not ctx.get(core.camera_ready):
            await ctx.tick("pclk")
        for frame in frames:
            await send_frame(ctx, frame, blank=400)  # blanking long enough for the SPI messages
            leds_after_frame.append(ctx.get(core.leds))
        state["camera_done"] = True

    async def send_frame(ctx, frame, blank):
        ctx.set(core.cam_vsync, 1)
        for _ in range(VSYNC_CYCLES):
            await ctx.tick("pclk")
        ctx.set(core.cam_vsync, 0)
        for row in frame:
            for p in row.tolist():
                for byte in ((p >> 8) & 0xF, p & 0xFF):
                    ctx.set(core.cam_href, 1)
                    ctx.set(core.cam_data, byte)
                    await ctx.tick("pclk")
            ctx.set(core.cam_href, 0)
            for _ in range(HBLANK):
                await ctx.tick("pclk")
        for _ in range(blank):
            await ctx.tick("pclk")

    async def spi_peripheral(ctx):
        prev_sclk, prev_cs, prev_xclk, cycle = 0, 0, 0, 0
        current, shift, nbits = [], 0, 0
        async for _clk, _rst, sclk, copi, cs, xclk in ctx.tick("sync").sample(
            core.spi_sclk, core.spi_copi, core.spi_cs, core.xclk
        ):
            cycle += 1
            if cs and not prev_cs:
                current, shift, nbits = [], 0, 0
            if sclk and not prev_sclk and cs:
                shift, nbits = (shift << 1) | copi, nbits + 1
                if nbits == 8:
                    current.append(shift)
                    shift, nbits = 0, 0
            if prev_cs and not cs:
                msgs.append(current)
            if xclk != prev_xclk:
                xclk_edges.append(cycle)
            prev_sclk, prev_cs, prev_xclk = sclk, cs, xclk

    sim.add_testbench(camera)
    sim.add_process(spi_peripheral)
    bytes_per_frame = PARAMS.height * (2 * PARAMS.width + HBLANK) + VSYNC_CYCLES + 400
    sccb_cycles = TIMING.reset_wait + 1000
    sim.run_until(
        ((len(frames) + 1) * bytes_per_frame + 200) * 80e-9 * 1.2 + sccb_cycles * 20e-9
    )  # watchdog
    assert state["camera_done"], "the simulated camera did not finish in time"
    assert msgs == expected_msgs
    assert leds_after_frame == expected_leds
    # XCLK toggles every xclk_half design clock cycles.
    assert set(np.diff(xclk_edges[5:]).tolist()) == {TIMING.xclk_half}


def test_robot_timing_from_clock():
    t = RobotTiming(50e6)
    assert (t.xclk_half, t.sccb_quarter, t.spi_half) == (2, 125, 50)
    assert t.reset_wait == 500_000
    with pytest.raises(ValueError, match="even multiple"):
        RobotTiming(60e6)


@pytest.mark.parametrize(
    "make",
    [
        lambda: ULX3SFollowTarget(FollowTargetParams(width=320, height=240)),
        lambda: ULX3SFollowTarget(sys_clk_freq=60e6),
        # Rejected (the GoPiGo3 SPI clock) before FollowTarget is built.
        lambda: RobotCore(
            PARAMS,
            RobotTiming.from_cycles(
                xclk_half=2, sccb_quarter=2, spi_half=0, camera_wait=5, reset_wait=8, motor_wait=3
            ),
        ),
        lambda: RobotCore(
            PARAMS,
            RobotTiming.from_cycles(
                xclk_half=0, sccb_quarter=2, spi_half=2, camera_wait=5, reset_wait=8, motor_wait=3
            ),
        ),
        lambda: RobotCore(PARAMS, TIMING, sccb_table=[]),
        lambda: SCCBInit(iter(TABLE), quarter_period=2, reset_wait=0),
        lambda: GoPiGo3Motors(half_period=0),
        lambda: SPIByteMaster(half_period=1.5),
        lambda: OV7670Capture(fifo_depth=2),
        lambda: SequentialDivider(8, 8, 0),
    ],
)
def test_a_rejected_constructor_leaves_no_unused_elaboratable(make):
    # Amaranth reports unused elaboratables only once something has been elaborated.
    Fragment.get(SwitchColorSelect(), None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises((TypeError, ValueError)):
            make()
        gc.collect()
    assert [w for w in caught if issubclass(w.category, UnusedElaboratable)] == []


def test_gopigo3_speed_limit_is_the_designs_capped_at_what_the_message_carries():
    from fpga_robotics.hw.board.gopigo3_spi import GOPIGO3_MAX_DPS_LIMIT
    from fpga_robotics.hw.board.robot_core import gopigo3_dps_limit

    assert gopigo3_dps_limit(FollowTargetParams()) == 512
    assert gopigo3_dps_limit(FollowTargetParams(max_dps=600)) == 600
    # The published preset does not saturate (max_dps 32767): the controller's maximum.
    assert gopigo3_dps_limit(FollowTargetParams.published()) == GOPIGO3_MAX_DPS_LIMIT == 16383
