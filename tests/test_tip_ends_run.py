"""Issue 14: a robot that tips over ends the run at the frame that reports the tip, with a
``tipped over`` event, a summary that says so, and a failing verdict (``max_tip_overs``)."""

import json

import pytest

from fpga_robotics.checks.summary import format_summary
from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main
from fpga_robotics.loop.compressed import TRAJECTORY_FIELDS, frame_count
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

TIPS = ["design.kp_num=32"]  # docs/stories.md, story (c)
# A TurtleBot2 whose motors ramp faster than it can take: it tips as soon as it drives off,
# between two frames (the physics, not a command jump).
RAMP_TIPS = ["robot.wheel_accel_dps2=12000", "robot.traction_force=100"]


def _tip_frames(result):
    return [(k, t) for k, t, text in result.events if text.startswith("tipped over")]


def _assert_ends_at_the_tip(result):
    s, traj = result.summary, result.trajectory
    ((k, t),) = _tip_frames(result)
    assert s["frames"] == k + 1
    assert result.events[-1][2].startswith("tipped over")
    assert {name: len(traj[name]) for name in TRAJECTORY_FIELDS} == dict.fromkeys(
        TRAJECTORY_FIELDS, k + 1
    )
    assert traj["t"][-1] == pytest.approx(t, abs=1e-6)
    assert s["sim_time_s"] == pytest.approx(t, abs=1e-6)
    assert s["ended_early"] == f"tipped over at {t:.2f} s"
    assert s["tip_overs"] == 1 and s["tipped_over_at_s"] == pytest.approx(t, abs=1e-4)
    assert s["verdict"] == "fail"
    (c,) = [c for c in s["checks"] if c["name"] == "max_tip_overs"]
    assert not c["passed"]


def test_the_unstable_gain_ends_the_erratic_run_at_the_tip():
    s = load_scenario("erratic", TIPS)
    records = []
    r = run_scenario(s, backend="model", on_frame=records.append)
    _assert_ends_at_the_tip(r)
    assert r.summary["frames"] == 96 and r.summary["ended_early"] == "tipped over at 3.17 s"
    assert r.summary["frames"] < frame_count(
        round(s.sim.duration / s.sim.physics_dt), s.camera.frame_period, s.sim.physics_dt
    )
    # The viewer and the callback see the same frames; the last one carries the tip.
    assert [rec.frame for rec in records] == list(range(96))
    assert records[-1].events[-1].startswith("tipped over: wheel command jumped 736 DPS")
    # The metrics and checks are evaluated on what ran: the 96 frames up to the fall.
    assert r.summary["found_fraction"] == round(float(r.trajectory["found"].mean()), 4)
    assert r.summary["target_in_view_fraction"] == round(
        float(r.trajectory["target_in_view"].mean()), 4
    )


def test_a_tip_between_frames_ends_the_run_at_the_frame_that_reports_it():
    r = run_scenario(load_scenario("approach", RAMP_TIPS), backend="model")
    _assert_ends_at_the_tip(r)
    assert r.summary["frames"] == 3
    assert r.events[-1][2].startswith("tipped over: longitudinal acceleration")


def test_the_default_run_goes_to_its_end():
    s = load_scenario("erratic", ["sim.duration=5"])
    r = run_scenario(s, backend="model")
    n = frame_count(round(5 / s.sim.physics_dt), s.camera.frame_period, s.sim.physics_dt)
    assert r.summary["ended_early"] is None and r.summary["tip_overs"] == 0
    assert r.summary["frames"] == n == 150 and r.summary["sim_time_s"] == pytest.approx(5.0)
    assert all(len(r.trajectory[name]) == n for name in TRAJECTORY_FIELDS)
    assert r.summary["verdict"] == "pass"
    assert "ended early" not in format_summary(r.summary)


def test_the_cli_reports_the_early_end_and_fails(tmp_path, capsys):
    path = tmp_path / "s.json"
    with pytest.raises(SystemExit) as info:
        run_cli(
            main,
            [
                "--scenario",
                "erratic",
                "--backend",
                "model",
                "--rerun",
                "off",
                "--quiet",
                "--set",
                TIPS[0],
                "--summary",
                str(path),
            ],
            prog="fpga-robotics run",
        )
    out, _ = capsys.readouterr()
    assert info.value.code == 1
    s = json.loads(path.read_text())
    assert (s["frames"], s["ended_early"], s["verdict"]) == (96, "tipped over at 3.17 s", "fail")
    assert "  run ended early: tipped over at 3.17 s" in out
    assert "[FAIL] max_tip_overs: the robot tipped over at 3.17 s (limit 0)" in out
