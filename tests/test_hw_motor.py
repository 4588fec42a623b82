"""MotorController against the golden model's ``MotorModel``: steering, saturation, lost
counter, search direction, reset state and latency; the published design's table law, lost
motion and search side (``FollowTargetParams.published()``) against the published facts."""

import numpy as np
import pytest
from hwsim import WithReset, run_testbench, small_params

from fpga_robotics.hw.motor import MotorController
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.models.follow_target import MotorModel, TrackerResult


def tracker_result(found, proximity, centroid_x, leds=0):
    return TrackerResult(
        found=bool(found),
        proximity=proximity,
        centroid_x=centroid_x,
        centroid_leds=leds,
        count=0,
        bins=(0,) * 8,
        sum_x=0,
    )


def run_motor(params, frames, *, idle=3, reset_after=None):
    """Present each ``(found, proximity, centroid_x[, leds])`` with a one-cycle ``update``;
    return, per frame, the outputs during the update cycle and right after its edge, plus
    state."""
    dut = MotorController(params)
    top = WithReset(dut)
    out = []
    limit = (len(frames) + 2) * (idle + 3) + 50

    async def bench(ctx):
        for i, (found, proximity, cx, *leds) in enumerate(frames):
            if reset_after is not None and i == reset_after:
                ctx.set(top.rst, 1)
                await ctx.tick()
                ctx.set(top.rst, 0)
            ctx.set(dut.found, found)
            ctx.set(dut.proximity, proximity)
            ctx.set(dut.centroid_x, cx)
            if params.motor_uses_leds:
                ctx.set(dut.leds, leds[0] if leds else 0)
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
            if params.motor_uses_leds:
                ctx.set(dut.leds, 0x5A)
            await ctx.tick().repeat(idle)
            assert (ctx.get(dut.left), ctx.get(dut.right)) == after

    run_testbench(top, bench, watchdog=limit)
    return out


def model_outputs(params, frames, reset_after=None):
    model = MotorModel(params)
    out = []
    for i, (found, proximity, cx, *leds) in enumerate(frames):
        if reset_after is not None and i == reset_after:
            model.reset()
        before = (model.left, model.right)
        after = model.step(tracker_result(found, proximity, cx, *leds))
        out.append((before, after, model.last_side, model.lost_count))
    return out


def random_frames(params, rng, n, p_found=0.6):
    frames = []
    for _ in range(n):
        found = int(rng.random() < p_found)
        frames.append((found, int(rng.integers(0, 8)), int(rng.integers(0, params.width))))
    return frames


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"kp_num": 7, "kp_shift": 2},
        {"kp_num": -5, "kp_shift": 1},  # negative gain: arithmetic shift of negative products
        {"kp_num": 200, "max_dps": 300},  # saturation on both sides
        {"max_dps": 0},
        {"base_dps": (-500, 32767, -32768, 0, 1, -1, 250, -250), "max_dps": 32767},
        {"lost_frames": 1, "search_dps": -120},
    ],
)
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


# --- The published design's motor law (FollowTargetParams.published()) ----------------------
# Expected values from the published design's measured behaviour: speed by proximity on the
# fast wheel, the slow wheel slower by 275 / 225 / 175 / 125 DPS from the outermost LED to the
# innermost (towards 0 when the speed is negative), no saturation; lost frames 1..14 drive on
# at the frame's proximity speed with the last steering, from the 15th it turns in place at
# 250 DPS to the last seen side (right after a centred sighting; left before any sighting).

PUBLISHED_SPEED = (600, 550, 450, 350, 250, 150, -250, -450)
#: LED code -> (target on the left, DPS the slow wheel loses); centred is 0b0001_1000.
PUBLISHED_STEER = {
    0x01: (True, 275),
    0x02: (True, 225),
    0x04: (True, 175),
    0x08: (True, 125),
    0x10: (False, 125),
    0x20: (False, 175),
    0x40: (False, 225),
    0x80: (False, 275),
}
CENTRED = 0b0001_1000


def published_command(speed, leds):
    """(left, right) of the published table law, written from the facts above."""
    if leds == CENTRED:
        return speed, speed
    left_side, d = PUBLISHED_STEER[leds]
    if speed >= 0:  # forwards: the wheel on the target's side is the slow one
        return (speed - d, speed) if left_side else (speed, speed - d)
    # backwards: the other wheel gets the speed plus the steering (slower backwards)
    return (speed, speed + d) if left_side else (speed + d, speed)


def test_published_command_examples_from_the_facts():
    assert published_command(600, 0x01) == (325, 600)  # far left, full speed: turn left
    assert published_command(350, 0x80) == (350, 75)
    assert published_command(-450, 0x01) == (-450, -175)  # backwards, target far left
    assert published_command(-250, 0x10) == (-125, -250)
    assert published_command(150, CENTRED) == (150, 150)


def test_table_law_every_led_code_and_proximity():
    p = FollowTargetParams.published()
    frames, expected = [], []
    for proximity in range(8):
        for leds in (*PUBLISHED_STEER, CENTRED):
            # centroid_x is ignored by the table law: give it a misleading value.
            frames.append((1, proximity, 150 if leds & 0x0F else 3, leds))
            expected.append(published_command(PUBLISHED_SPEED[proximity], leds))
    out = run_motor(p, frames, idle=1)
    assert [o[1] for o in out] == expected
    assert all(o[3] == 0 for o in out)  # found: the lost count is 0
    assert out == model_outputs(p, frames)


@pytest.mark.parametrize("sighting,side", [(0x02, "left"), (0x40, "right"), (CENTRED, "right")])
@pytest.mark.parametrize("run", [1, 14, 15])
@pytest.mark.parametrize("lost_proximity", [0, 3])  # an empty frame; N = 128 exactly
def test_table_law_lost_runs(sighting, side, run, lost_proximity):
    p = FollowTargetParams.published()
    seen = (1, 4, 80, sighting)
    frames = [seen] + [(0, lost_proximity, 0, 0)] * run + [seen]
    out = run_motor(p, frames, idle=1)
    tracking = published_command(PUBLISHED_SPEED[4], sighting)
    driving = published_command(PUBLISHED_SPEED[lost_proximity], sighting)
    search = (250, -250) if side == "right" else (-250, 250)
    assert out[0][1] == tracking
    expected = [driving if k < 14 else search for k in range(run)]
    assert [o[1] for o in out[1:-1]] == expected
    assert [o[3] for o in out] == [0, *range(1, run + 1), 0]
    assert [o[2] for o in out[1:-1]] == [side] * run
    assert out[-1][1] == tracking  # found again: tracking again
    assert out == model_outputs(p, frames)


def test_table_law_before_any_sighting_stops_then_searches_left():
    p = FollowTargetParams.published()
    frames = [(0, 0, 0, 0)] * 16
    out = run_motor(p, frames, idle=1)
    assert [o[1] for o in out] == [(0, 0)] * 14 + [(-250, 250)] * 2
    assert out == model_outputs(p, frames)


def test_search_side_from_the_leds_is_not_the_sign_of_e():
    # A target left of centre by its LEDs but right of it by its centroid: the published
    # side follows the LEDs; the default follows the centroid.
    frames = [(1, 3, 150, 0x08), (0, 0, 0, 0)]
    published = FollowTargetParams.published(lost_frames=1)
    ours = FollowTargetParams(lost_frames=1)
    assert run_motor(published, frames)[1][1] == (-250, 250)
    assert run_motor(ours, frames)[1][1] == (250, -250)
    left = published.replace(centred_search_side="left")
    assert run_motor(left, [(1, 3, 150, CENTRED), (0, 0, 0, 0)])[1][1] == (-250, 250)


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {
            "steer_dps": (0, 1, 32767, 400),
            "base_dps": (0, 500, -300, 200, -32768, 32767, -1, 0),
            "max_dps": 450,
        },  # saturation of the table's values
        {
            "steer_dps": (10, 20, 30, 40),
            "max_dps": 32767,
            "base_dps": (-32768, 32767, 0, 1, -1, 100, -100, 5),
        },
        {"lost_motion": "hold", "lost_frames": 3},
        {"centred_search_side": "left", "lost_frames": 2, "search_dps": -120},
        {"motor_law": "p_control", "lost_motion": "hold", "kp_num": 5, "max_dps": 300},
        {"motor_law": "p_control", "lost_motion": "hold", "search_side_from": "centroid"},
        {"search_side_from": "centroid", "lost_frames": 1},
    ],
)
def test_published_knobs_random_sequences_match_the_model(changes):
    p = FollowTargetParams.published(**changes)
    rng = np.random.default_rng(len(str(changes)) + 1)
    codes = (0, *PUBLISHED_STEER, CENTRED, 0x81, 0x24, 0xFF)  # and some impossible ones
    frames = []
    for _ in range(80):
        found = int(rng.random() < 0.5)
        frames.append(
            (
                found,
                int(rng.integers(0, 8)),
                int(rng.integers(0, p.width)),
                int(rng.choice(codes)) if found else int(rng.choice(codes[:3])),
            )
        )
    for leds in (0x01, 0x80, CENTRED):
        frames += [(1, 6, 40, leds)] + [(0, 7, 0, 0)] * (p.lost_frames + 1)
    assert run_motor(p, frames, idle=1) == model_outputs(p, frames)
