"""NearestObstacle against its numpy model (sim/models/nearest_obstacle.py) on random scans,
its outputs by hand on a tiny one, and CorridorFollow's wheel commands against the control
law by hand and against its model (sim/models/corridor_follow.py) on random scans, the
mirrored-bearing variant's commands included."""

import numpy as np
import pytest
from hwsim import WithReset, run_testbench

from fpga_robotics.hw.corridor_follow import CorridorFollow, corridor_command
from fpga_robotics.hw.lidar_params import CorridorParams, NearestParams
from fpga_robotics.hw.lidar_sample import pack_sample, unpack_sample
from fpga_robotics.hw.nearest_obstacle import NearestObstacle
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.sim.models.corridor_follow import corridor_commands
from fpga_robotics.sim.models.nearest_obstacle import nearest_per_revolution
from fpga_robotics.sim.world.lidar import LidarSample


def _payload(angle_q6, distance_q2, quality, start):
    return pack_sample(LidarSample(0, angle_q6, distance_q2, quality, bool(start)))


def run_nearest(params, samples, gap=2):
    """Feed ``samples`` ((angle_q6, distance_q2, quality, start) each) one every ``gap``
    cycles; returns the outputs ``(found, nearest_mm, bearing_q6)`` after each edge at which
    ``updated`` is high, and how many cycles after its sample each came."""
    dut = NearestObstacle(params)
    top = WithReset(dut)
    out = []

    async def bench(ctx):
        assert ctx.get(dut.updated) == 0 and ctx.get(dut.found) == 0
        for sample in samples:
            ctx.set(dut.samples.payload.as_value(), _payload(*sample))
            ctx.set(dut.samples.valid, 1)
            await ctx.tick()
            ctx.set(dut.samples.valid, 0)
            if ctx.get(dut.updated):
                out.append((ctx.get(dut.found), ctx.get(dut.nearest_mm), ctx.get(dut.bearing_q6)))
            for _ in range(gap - 1):
                await ctx.tick()
                assert ctx.get(dut.updated) == 0  # one cycle only

    run_testbench(top, bench, watchdog=len(samples) * gap + 50)
    return out


def random_scan(rng, n):
    """Revolutions of 5..40 samples; some dropouts (0, 0), some low quality, equal minima."""
    out = []
    while len(out) < n:
        size = int(rng.integers(5, 40))
        for j in range(size):
            dropout = rng.random() < 0.2
            d = 0 if dropout else int(rng.choice([rng.integers(600, 48000), 2000]))
            q = 0 if dropout else int(rng.integers(0, 64))
            out.append((int(rng.integers(0, 23040)), d, q, int(j == 0)))
    return out[:n]


@pytest.mark.parametrize(
    "params",
    [NearestParams(), NearestParams(min_quality=20, min_mm=1000)],
    ids=["default", "strict"],
)
def test_random_scans_match_the_model(params):
    samples = random_scan(np.random.default_rng(7), 400)
    assert run_nearest(params, samples) == nearest_per_revolution(samples, params)


def test_a_tiny_scan_by_hand():
    samples = [
        (0, 4000, 15, 1),  # revolution 1: 1000 mm at 0 degrees
        (64, 0, 0, 0),  # a dropout: distance 0 never counts
        (5760, 2000, 15, 0),  # 500 mm at 90 degrees: the nearest
        (11520, 2000, 15, 0),  # as near, later: the first one stays
        (0, 8000, 15, 1),  # revolution 2 starts: revolution 1 published
        (64, 0, 0, 0),
        (0, 0, 0, 1),  # revolution 2 published: 2000 mm at 0 degrees
        (64, 0, 0, 0),
        (0, 0, 0, 1),  # revolution 3 had no return: found 0, the rest kept
    ]
    assert run_nearest(NearestParams(), samples, gap=1) == [
        (0, 0, 0),  # the first start ends an empty revolution
        (1, 500, 5760),
        (1, 2000, 0),
        (0, 2000, 0),
    ]


def test_payload_fields_from_bit_zero_up():
    value = _payload(23039, 65535, 63, 1)
    assert value == (1 << 38) - 1 - (23039 ^ 0x7FFF)  # every field full but the angle
    assert unpack_sample(_payload(63, 12000, 15, 0)) == {
        "angle_q6": 63,
        "distance_q2": 12000,
        "quality": 15,
        "start": 0,
    }
    assert _payload(1, 0, 0, 0) == 1 and _payload(0, 1, 0, 0) == 1 << 15
    assert _payload(0, 0, 1, 0) == 1 << 31 and _payload(0, 0, 0, 1) == 1 << 37


def run_corridor(params, revolutions):
    """Each of ``revolutions`` is (distance_q2, angle_q6) of one sample; a start sample of
    nothing after it ends it. Returns the wheel command two edges after each end."""
    dut = CorridorFollow(params)
    top = WithReset(dut)
    out = []

    async def bench(ctx):
        assert (ctx.get(dut.motor_left), ctx.get(dut.motor_right)) == (0, 0)
        for distance_q2, angle_q6 in revolutions:
            for sample in ((0, 0, 0, 1), (angle_q6, distance_q2, 15, 0)):
                ctx.set(dut.lidar.payload.as_value(), _payload(*sample))
                ctx.set(dut.lidar.valid, 1)
                await ctx.tick()
                ctx.set(dut.lidar.valid, 0)
        ctx.set(dut.lidar.payload.as_value(), _payload(0, 0, 0, 1))
        ctx.set(dut.lidar.valid, 1)
        await ctx.tick()
        ctx.set(dut.lidar.valid, 0)
        await ctx.tick()
        out.append((ctx.get(dut.motor_left), ctx.get(dut.motor_right)))

    run_testbench(top, bench, watchdog=len(revolutions) * 2 + 50)
    return out[0]


#: (nearest mm, bearing degrees clockwise) -> the command, by hand at the defaults
#: (base 300, steer 90, turn 200, keep 420 mm, stop 300 mm, front 30, side 120 degrees).
CASES = [
    ((1000, 90), (300, 300)),  # far: straight
    ((400, 90), (210, 390)),  # near on the right: steer left
    ((400, 270), (390, 210)),  # near on the left: steer right
    ((400, 120), (210, 390)),  # 120 degrees off ahead: still steered
    ((400, 150), (300, 300)),  # behind the side arc: ignored
    ((250, 10), (-200, 200)),  # close ahead, a little right: turn left in place
    ((250, 350), (200, -200)),  # close ahead, a little left: turn right in place
    ((250, 40), (210, 390)),  # close but outside the front arc: steer
]


@pytest.mark.parametrize("seen, command", CASES)
def test_corridor_law_by_hand(seen, command):
    mm, deg = seen
    p = CorridorParams()
    assert corridor_command(p, 1, mm, deg * 64) == command
    assert run_corridor(p, [(mm * 4, deg * 64)]) == command


def test_the_mirrored_variant_steers_towards_the_wall():
    bug = variant_params("lidar_bearing_mirrored", CorridorParams())
    # A wall 400 mm away on the right: the right way is left (210, 390); the bug turns right.
    assert corridor_command(bug, 1, 400, 90 * 64) == (390, 210)
    assert run_corridor(bug, [(1600, 90 * 64)]) == (390, 210)
    assert run_corridor(bug, [(1000, 250 * 64)]) == (210, 390)


def run_corridor_scan(params, samples):
    """CorridorFollow fed ``samples`` two cycles apart; its wheel command two edges after each
    start sample (the revolution it ends published, then the command loaded)."""
    dut = CorridorFollow(params)
    top = WithReset(dut)
    out = []

    async def bench(ctx):
        for sample in samples:
            ctx.set(dut.lidar.payload.as_value(), _payload(*sample))
            ctx.set(dut.lidar.valid, 1)
            await ctx.tick()
            ctx.set(dut.lidar.valid, 0)
            await ctx.tick()
            if sample[3]:
                out.append((ctx.get(dut.motor_left), ctx.get(dut.motor_right)))

    run_testbench(top, bench, watchdog=len(samples) * 2 + 50)
    return out


def corridor_scan(rng, n):
    """Revolutions of 3..12 samples, near and far, at any bearing: every case of the law."""
    out = []
    while len(out) < n:
        for j in range(int(rng.integers(3, 12))):
            mm = int(rng.choice([rng.integers(150, 320), rng.integers(280, 450), 2000]))
            dropout = rng.random() < 0.15
            out.append((int(rng.integers(0, 23040)), 0 if dropout else mm * 4, 15, int(j == 0)))
    return out[:n]


@pytest.mark.parametrize("variant", [None, "lidar_bearing_mirrored"])
def test_corridor_follow_matches_its_model(variant):
    p = CorridorParams() if variant is None else variant_params(variant, CorridorParams())
    samples = corridor_scan(np.random.default_rng(3), 400)
    expected = corridor_commands(samples, p)
    assert run_corridor_scan(p, samples) == expected
    assert len(set(expected)) >= 5  # straight, both steers, both turns seen
