"""``--shadow-continue``: the shadow design's own run, from where it would have driven
differently, equals its full run; an identical shadow's equals the primary's."""

import json
from pathlib import Path

import numpy as np
import pytest
from run_equality import assert_same_run

from fpga_robotics.cli.run import main as run_main
from fpga_robotics.loop.continuation import run_continued
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import read_rrd


def _without_shadow(summary):
    return {k: v for k, v in summary.items() if k != "shadow"}


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("lost_target", ["sim.duration=6", "camera.noise_std=4"])


def test_an_identical_shadow_continues_as_the_primary(scenario):
    with ModelBackend(scenario.params) as design, ModelBackend(scenario.params) as shadow:
        continued = run_continued(scenario, design=design, shadow=shadow, checkpoint_every=10)
        lockstep = run_scenario(scenario, backend=design, shadow=shadow)
    assert continued.parted is None
    assert continued.main.summary["shadow"]["first_divergence"] is None
    assert_same_run(continued.main, lockstep)
    plain = run_scenario(scenario, backend="model")
    assert_same_run(continued.shadow, plain)


def test_a_shadow_with_other_parameters_continues_as_its_full_run(scenario):
    other = scenario.with_overrides(["design.lost_frames=5", "design.search_dps=-300"])
    with ModelBackend(scenario.params) as design, ModelBackend(other.params) as shadow:
        continued = run_continued(
            scenario,
            design=design,
            shadow=shadow,
            shadow_scenario=other,
            checkpoint_every=10,
            shadow_label="lost_frames=5",
        )
        lockstep = run_scenario(
            scenario, backend=design, shadow=shadow, shadow_label="lost_frames=5"
        )
        full = run_scenario(other, backend=shadow)
    assert_same_run(continued.main, lockstep)
    assert_same_run(continued.shadow, full)
    # It parts after the target has been out of view for 5 frames, not at the start.
    assert 10 < continued.parted < continued.main.summary["frames"]
    assert not any(e[2].startswith("shadow design") for e in continued.shadow.events)
    assert not np.array_equal(
        continued.shadow.trajectory["heading"], continued.main.trajectory["heading"]
    )


def test_a_pin_shadow_continues_as_its_full_run():
    s = load_scenario("line_track", ["sim.duration=1.5"])
    slower = s.with_overrides(["design.line.base_dps=300"])
    with make_pin_backend("cxxrtl", s) as design, make_pin_backend("cxxrtl", slower) as shadow:
        continued = run_continued(
            s, design=design, shadow=shadow, shadow_scenario=slower, checkpoint_every=7
        )
        lockstep = run_scenario(s, backend=design, shadow=shadow)
        full = run_scenario(slower, backend=shadow)
    assert continued.main.summary["shadow"]["first_divergence"] is not None
    assert_same_run(continued.main, lockstep)
    assert_same_run(continued.shadow, full)
    assert continued.parted == 1
    assert full.summary["path_length_m"] < continued.main.summary["path_length_m"]


def test_the_command_prints_and_saves_the_shadow_run(tmp_path, capsys):
    path = tmp_path / "s.json"
    code = run_main(
        [
            "--scenario",
            "lost_target",
            "--backend",
            "model",
            "--duration",
            "6",
            "--set",
            "camera.noise_std=4",
            "--shadow",
            "lost_frames=5;search_dps=-300",
            "--shadow-continue",
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(path),
        ]
    )
    out = capsys.readouterr().out
    saved = json.loads(path.read_text())
    continued = saved["shadow_continued"]
    assert "shadow lost_frames=5;search_dps=-300" in out and "on its own (drives from frame" in out
    full = run_scenario(
        load_scenario(
            "lost_target",
            [
                "sim.duration=6",
                "camera.noise_std=4",
                "design.lost_frames=5",
                "design.search_dps=-300",
            ],
        ),
        backend="model",
    )
    for key in ("path_length_m", "verdict", "checks", "frames", "searches"):
        assert continued[key] == full.summary[key], key
    assert code == (0 if saved["verdict"] == "pass" else 1)


def test_shadow_continue_needs_a_shadow(capsys):
    with pytest.raises(SystemExit) as exc:
        from fpga_robotics.cli.errors import run_cli

        run_cli(
            run_main,
            ["--scenario", "lost_target", "--shadow-continue", "--rerun", "off"],
            "fpga-robotics run",
        )
    assert exc.value.code == 2
    assert "--shadow-continue" in capsys.readouterr().err


def test_the_recording_holds_the_shadow_path(tmp_path, capsys):
    rrd = tmp_path / "run.rrd"
    args = ["--scenario", "lost_target", "--backend", "model", "--duration", "6"]
    args += ["--set", "camera.noise_std=4", "--quiet", "--rerun", f"save:{rrd}"]
    run_main([*args, "--shadow", "lost_frames=5;search_dps=-300", "--shadow-continue"])
    capsys.readouterr()
    data = read_rrd(str(rrd))
    points = np.asarray(data.static[f"{P.TRAILS}/shadow"]["LineStrips2D:strips"][0])
    full = run_scenario(
        load_scenario(
            "lost_target",
            [
                "sim.duration=6",
                "camera.noise_std=4",
                "design.lost_frames=5",
                "design.search_dps=-300",
            ],
        ),
        backend="model",
    )
    x, y = full.trajectory["x"], full.trajectory["y"]
    assert np.allclose(points.reshape(-1, 2), np.column_stack([x, -y]).astype(np.float32))


def _continued_summary(tmp_path, argv):
    path = tmp_path / "s.json"
    run_main([*argv, "--shadow-continue", "--rerun", "off", "--quiet", "--summary", str(path)])
    return json.loads(path.read_text())


def test_each_design_s_summary_lists_its_own_overrides(tmp_path, capsys):
    # --set gives the primary 20 lost frames, --shadow the shadow 5: the shadow's list names
    # 5 alone, and loading the scenario with it gives the shadow's design.
    argv = ["--scenario", "lost_target", "--backend", "model", "--duration", "1"]
    argv += ["--set", "design.lost_frames=20", "--shadow", "lost_frames=5"]
    saved = _continued_summary(tmp_path, argv)
    capsys.readouterr()
    assert saved["overrides"] == ["design.lost_frames=20", "sim.duration=1.0"]
    own = saved["shadow_continued"]["overrides"]
    assert sorted(own) == ["design.lost_frames=5", "sim.duration=1.0"]
    assert load_scenario("lost_target", own).params.lost_frames == 5


def test_a_pin_shadow_s_summary_lists_its_own_parameters(tmp_path, capsys):
    # wall_stop.toml gives stop_mm = 250; --shadow-param gives the shadow 100.
    data = Path(__file__).parent / "data" / "user_designs"
    argv = ["--scenario", str(data / "wall_stop.toml"), "--backend", "cxxrtl"]
    argv += ["--duration", "0.2", "--shadow", f"{data}/wall_stop.py:WallStop"]
    saved = _continued_summary(tmp_path, [*argv, "--shadow-param", "stop_mm=100"])
    capsys.readouterr()
    own = saved["shadow_continued"]["overrides"]
    assert not any("250" in item for item in own), own
    keys = [item.partition("=")[0] for item in own]
    assert len(keys) == len(set(keys)), own
    shadow = load_scenario(data / "wall_stop.toml", own)
    assert shadow.design_params == {"speed": 300, "stop_mm": 100}
