"""MotorController against the golden model's ``MotorModel``: steering, saturation, lost
counter, search direction, reset state and latency."""

import numpy as np
import pytest
from hwsim import WithReset, run_testbench, small_params

from fpga_robotics.hw.motor import MotorController
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.model import MotorModel, TrackerResult


def tracker_result(found, proximity, centroid_x):
    return TrackerResult(found=bool(found), proximity=proximity, centroid_x=centroid_x,
                         centroid_leds=0, count=0, bins=(0,) * 8, sum_x=0)


def run_motor(params, frames, *, idle=3, reset_after=None):
    """Present each ``(found, proximity, centroid_x)`` with a one-cycle ``update``; return,
    per frame, the outputs during the update cycle and right after its edge, plus state."""
    dut = MotorController(params)
    top = WithReset(dut)
    out = []
    limit = (len(frames) + 2) * (idle + 3) + 50

    async def bench(ctx):
        for i, (found, proximity, cx) in enumerate(frames):
            if reset_after is not None and i == reset_after:
                ctx.set(top.rst, 1)
                await ctx.tick()
                ctx.set(top.rst, 0)
            ctx.set(dut.found, found)
            ctx.set(dut.proximity, proximity)
            ctx.set(dut.centroid_x, cx)
            ctx.set(dut.update, 1)
            before = (ctx.get(dut.left), ctx.get(dut.right))
            await ctx.tick()
            ctx.set(dut.update, 0)
            after = (ctx.get(dut.left), ctx.get(dut.right))
            side = "right" if ctx.get(dut.last_side) else "left"
            out.append((before, after, side, ctx.get(dut.lost_count)))
            # Garbage on the inputs without `update` must change nothing.
            ctx.set(dut.found, 1 - found)
            ctx.set(dut.centroid_x, (cx * 7 + 3) % params.width)
            await ctx.tick().repeat(idle)
            assert (ctx.get(dut.left), ctx.get(dut.right)) == after

    run_testbench(top, bench, watchdog=limit)
    return out


def model_outputs(params, frames, reset_after=None):
    model = MotorModel(params)
    out = []
    for i, (found, proximity, cx) in enumerate(frames):
        if reset_after is not None and i == reset_after:
            model.reset()
        before = (model.left, model.right)
        after = model.step(tracker_result(found, proximity, cx))
        out.append((before, after, model.last_side, model.lost_count))
    return out


def random_frames(params, rng, n, p_found=0.6):
    frames = []
    for _ in range(n):
        found = int(rng.random() < p_found)
        frames.append((found, int(rng.integers(0, 8)), int(rng.integers(0, params.width))))
    return frames


@pytest.mark.parametrize("changes", [
    {},
    {"kp_num": 7, "kp_shift": 2},
    {"kp_num": -5, "kp_shift": 1},  # negative gain: arithmetic shift of negative products
    {"kp_num": 200, "max_dps": 300},  # saturation on both sides
    {"max_dps": 0},
    {"base_dps": (-500, 32767, -32768, 0, 1, -1, 250, -250), "max_dps": 32767},
    {"lost_frames": 1, "search_dps": -120},
])
def test_random_sequences_match_the_model(changes):
    p = FollowTargetParams(**changes)
    rng = np.random.default_rng(len(str(changes)))
    frames = random_frames(p, rng, 60, p_found=0.5)
    # Runs of lost frames long enough to search, both after left and right sightings.
    frames += [(1, 3, 10)] + [(0, 0, 0)] * (p.lost_frames + 2)
    frames += [(1, 3, 150)] + [(0, 0, 0)] * (p.lost_frames + 2)
    assert run_motor(p, frames) == model_outputs(p, frames)


def test_outputs_are_zero_after_reset_until_the_first_update():
    p = FollowTargetParams()
    out = run_motor(p, [(1, 1, 150), (1, 2, 20)])
    assert out[0][0] == (0, 0)  # before the first update
    assert out[0][1] != (0, 0)  # loaded at the update's edge: motor latency 1


def test_search_starts_exactly_at_lost_frames_towards_the_last_side():
    p = small_params(lost_frames=3, search_dps=250)
    frames = [(1, 2, 40)] + [(0, 0, 0)] * 4 + [(1, 2, 2)] + [(0, 0, 0)] * 3
    out = run_motor(p, frames)
    tracking = out[0][1]
    assert [o[1] for o in out[1:3]] == [tracking, tracking]  # lost 1, 2: hold
    assert out[3][1] == (250, -250)  # 3rd lost frame: turn right (target was right)
    assert out[4][1] == (250, -250)
    assert out[8][1] == (-250, 250)  # after a sighting on the left: turn left
    assert [o[3] for o in out] == [0, 1, 2, 3, 3, 0, 1, 2, 3]
    assert out == model_outputs(p, frames)


def test_last_side_is_left_after_reset_and_set_by_the_sign_of_e():
    # The published design set "last seen left" from the right half.
    p = small_params(lost_frames=1)
    half = p.width // 2
    frames = [(0, 0, 0), (1, 1, half - 1), (0, 0, 0), (1, 1, half), (0, 0, 0)]
    out = run_motor(p, frames)
    assert [o[2] for o in out] == ["left", "left", "left", "right", "right"]
    assert out[0][1] == (-p.search_dps, p.search_dps)  # never saw it: search left
    assert out[2][1] == (-p.search_dps, p.search_dps)
    assert out[4][1] == (p.search_dps, -p.search_dps)
    assert out == model_outputs(p, frames)


def test_reset_returns_to_the_power_on_state():
    p = small_params(lost_frames=2)
    frames = [(1, 1, 40), (0, 0, 0), (0, 0, 0), (1, 5, 40), (0, 0, 0), (0, 0, 0)]
    out = run_motor(p, frames, reset_after=3)
    assert out[3][0] == (0, 0)
    assert out == model_outputs(p, frames, reset_after=3)
