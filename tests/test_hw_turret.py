"""TurretAim (the turret channel of TurretTracker) against hand-computed angles and the numpy
model, frame by frame in Amaranth's simulator; TurretTracker exports to Verilog with both
channels' ports."""

import numpy as np
from amaranth.sim import Simulator
from hwsim import PERIOD, WatchdogTimeout, frame_schedule

from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.hw.turret_params import TurretParams
from fpga_robotics.hw.turret_tracker import TurretAim, TurretTracker
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.models.turret import TurretAimModel

SMALL = TurretParams(width=80, height=40)  # centre column 40


def blob(p, cx, seed=0, color="blue"):
    rgb = synthetic.blob_frame(
        p.width,
        p.height,
        color,
        cx=cx,
        cy=p.height / 2,
        radius=p.height / 3,
        rng=np.random.default_rng(seed),
    )
    return to_rgb444(rgb, p.width, p.height)


def run_aim(params, frames, color="blue"):
    """Stream ``frames`` through TurretAim; per frame (found, centroid_x, angle) read one
    cycle after its frame_done."""
    dut = TurretAim(params)
    schedule = []
    for frame in frames:
        schedule += frame_schedule(frame, line_blank=2)
    edges = len(schedule) + 200
    seen = []

    async def bench(ctx):
        ctx.set(dut.color_sel, COLOR_SELECT[color])
        pending = None
        for e in range(edges):
            entry = schedule[e] if e < len(schedule) else None
            ctx.set(dut.pixels.valid, entry is not None)
            if entry is not None:
                ctx.set(dut.pixels.payload.as_value(), entry)
            await ctx.tick()
            if pending is not None:
                seen.append((*pending, ctx.get(dut.angle)))
                pending = None
            if ctx.get(dut.frame_done):
                pending = (ctx.get(dut.found), ctx.get(dut.centroid_x))

    async def watchdog(ctx):
        await ctx.delay((edges + 50) * PERIOD)
        raise WatchdogTimeout("TurretAim simulation hung")

    sim = Simulator(dut)
    sim.add_clock(PERIOD)
    sim.add_testbench(bench)
    sim.add_testbench(watchdog, background=True)
    sim.run()
    return seen


def test_angle_follows_the_hand_computed_law():
    # Blobs right of the centre (40), left of it, then an empty frame (the angle holds).
    frames = [blob(SMALL, 55), blob(SMALL, 25, seed=1), blob(SMALL, 60, seed=2)]
    empty = to_rgb444(np.full((SMALL.height, SMALL.width, 3), 90, np.uint8), 80, 40)
    seen = run_aim(SMALL, [*frames, empty])
    assert len(seen) == 4
    angle = 0
    for found, cx, got in seen[:3]:
        assert found
        angle -= (5 * (cx - 40)) >> 2  # kp 5/4, floor, camera turns towards the blob
        assert got == angle
    assert seen[0][1] > 40 and seen[0][2] < 0  # target right of centre: turn right
    assert seen[3][:1] == (0,) and seen[3][2] == angle  # lost: holds
    model = TurretAimModel(SMALL)
    expected = [model.process(f, COLOR_SELECT["blue"]) for f in [*frames, empty]]
    assert [(int(e.tracker.found), e.tracker.centroid_x, e.angle) for e in expected] == seen


def test_saturation_and_the_inverted_variant():
    strong = SMALL.replace(kp_num=200, kp_shift=0, angle_limit=300)
    frames = [blob(strong, 60), blob(strong, 60, seed=1)]
    assert [s[2] for s in run_aim(strong, frames)] == [-300, -300]
    inverted = SMALL.replace(inverted=True)
    seen = run_aim(inverted, frames[:1])
    assert seen[0][2] == (5 * (seen[0][1] - 40)) >> 2 > 0  # turns away from the target


def test_a_lost_target_is_searched_for_by_a_hand_computed_sweep():
    # Lost from reset: the side is left, so after lost_frames = 2 the angle climbs 100 a
    # frame, stops at the limit 250 and turns, and stops at -250 and turns again.
    search = SMALL.replace(lost_frames=2, search_step=100, angle_limit=250)
    empty = to_rgb444(np.full((SMALL.height, SMALL.width, 3), 90, np.uint8), 80, 40)
    frames = [empty] * 10 + [blob(search, 60)] + [empty] * 3
    seen = run_aim(search, frames)
    sweep = [0, 100, 200, 250, 150, 50, -50, -150, -250, -150]
    assert [s[2] for s in seen[:10]] == sweep
    assert not any(s[0] for s in seen[:10])
    found, cx, angle = seen[10]
    assert found and cx > 40 and angle == -150 - ((5 * (cx - 40)) >> 2)
    # Found right of the centre: the search now starts rightwards after two lost frames,
    # reaches the limit at once (angle - 100 < -250), stops there and turns back.
    assert angle - 100 < -250
    assert [s[2] for s in seen[11:]] == [angle, -250, -150]
    model = TurretAimModel(search)
    expected = [model.process(f, COLOR_SELECT["blue"]) for f in frames]
    assert [(int(e.tracker.found), e.tracker.centroid_x, e.angle) for e in expected] == seen


def test_search_step_zero_holds_the_angle_for_ever():
    still = SMALL.replace(lost_frames=1, search_step=0)
    empty = to_rgb444(np.full((SMALL.height, SMALL.width, 3), 90, np.uint8), 80, 40)
    seen = run_aim(still, [blob(still, 25), empty, empty])
    assert seen[0][2] > 0 and [s[2] for s in seen[1:]] == [seen[0][2]] * 2


def test_turret_tracker_exports_with_both_channels():
    text = generate_verilog(component=TurretTracker())
    for port in ("turret_pixels__payload", "turret_color_sel", "servo_angle", "motor_left"):
        assert port in text
    assert "input [13:0] turret_pixels__payload" in text
    assert "output [9:0] servo_angle" in text


def test_export_writes_turret_tracker_and_its_variant(tmp_path, capsys):
    import os

    import pytest

    from fpga_robotics.cli.errors import run_cli
    from fpga_robotics.cli.export import main

    def export(argv, name):
        with pytest.raises(SystemExit) as exit_info:
            run_cli(main, ["-o", str(tmp_path / name), "--top", "turret_tracker", *argv])
        return exit_info.value.code

    assert export([], "plain.v") == 0
    assert export(["--variant", "turret_pan_inverted"], "inverted.v") == 0
    plain, inverted = ((tmp_path / n).read_text() for n in ("plain.v", "inverted.v"))
    assert "module turret_tracker" in plain and plain != inverted
    capsys.readouterr()
    assert export(["--variant", "us_echo_inverted"], "bad.v") == 2
    err = capsys.readouterr().err
    assert "no variant of --top turret_tracker; known variants: turret_pan_inverted" in err
    assert sorted(os.listdir(tmp_path)) == ["inverted.v", "plain.v"]
