"""The ``published`` preset everywhere it can be named: ``FollowTargetParams.published()``, a
scenario's ``design.preset``, ``export --preset`` and ``run --shadow published``."""

import numpy as np
import pytest
from test_export import verilator_lint

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.export import main as export_main
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.hw.params import PRESETS, FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sim.backends import get_backend

#: The published design at 160x120 (docs/published.md).
PUBLISHED = {
    "min_pixels": 128,
    "found_rule": "gt",
    "proximity_thresholds": (128, 128, 128, 3072, 3840, 4096, 6144),
    "group_column_offset": 1,
    "motor_law": "table",
    "base_dps": (600, 550, 450, 350, 250, 150, -250, -450),
    "steer_dps": (125, 175, 225, 275),
    "lost_motion": "drive",
    "search_side_from": "leds",
    "centred_search_side": "right",
    "max_dps": 32767,
    "lost_frames": 15,
    "search_dps": 250,
    # The colour filter and the window are the defaults.
    "diff_min": 6,
    "similar_max": 2,
    "white_min": 12,
    "margin_x": 16,
    "margin_y": 8,
}


def test_published_classmethod_holds_the_published_values():
    p = FollowTargetParams.published()
    assert (p.width, p.height) == (160, 120)
    assert {k: getattr(p, k) for k in PUBLISHED} == PUBLISHED
    assert p == FollowTargetParams.preset("published") == FollowTargetParams(**PUBLISHED)


def test_published_changes_go_on_top_and_counts_scale_with_the_area():
    p = FollowTargetParams.published(max_dps=400, kp_num=2)
    assert (p.max_dps, p.kp_num, p.motor_law) == (400, 2, "table")
    big = FollowTargetParams.published(width=320, height=240)
    assert big.min_pixels == 512
    assert big.proximity_thresholds == (512, 512, 512, 12288, 15360, 16384, 24576)
    assert FollowTargetParams.published(width=320, height=240, min_pixels=7).min_pixels == 7


def test_unknown_preset_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown design preset 'paper'; known presets: published"):
        FollowTargetParams.preset("paper")
    assert list(PRESETS) == ["published"]


def test_defaults_are_not_the_published_design():
    ours, published = FollowTargetParams(), FollowTargetParams.published()
    differ = {k for k in PUBLISHED if getattr(ours, k) != getattr(published, k)}
    assert differ == {
        "found_rule",
        "proximity_thresholds",
        "group_column_offset",
        "motor_law",
        "base_dps",
        "lost_motion",
        "search_side_from",
        "max_dps",
    }


# --- Scenarios ------------------------------------------------------------------------------


def test_scenario_preset_then_the_other_design_keys():
    s = load_scenario("follow_person", ["design.preset=published"])
    assert s.params == FollowTargetParams.published()
    s = load_scenario("follow_person", ["design.max_dps=300", "design.preset=published"])
    assert s.params == FollowTargetParams.published(max_dps=300)  # on top, in any order
    s = load_scenario("follow_person", ["design.preset=published", 'camera.resolution="320x240"'])
    assert s.params == FollowTargetParams.published(width=320, height=240)


def test_scenario_file_with_a_preset(tmp_path):
    path = tmp_path / "paper.toml"
    path.write_text(
        'name = "paper"\n[room]\nwidth = 6.0\ndepth = 5.0\n[robot]\n'
        'start = [1.0, 2.5]\n[design]\npreset = "published"\n'
        'found_rule = "ge"\nsteer_dps = [100, 150, 200, 250]\n'
    )
    s = load_scenario(str(path))
    assert s.params == FollowTargetParams.published(found_rule="ge", steer_dps=(100, 150, 200, 250))


@pytest.mark.parametrize(
    "override,message",
    [
        ("design.preset=paper", "design.preset must be one of 'published', got 'paper'"),
        ("design.found_rule=1", "design.found_rule must be a string, one of ge, gt"),
        ('design.motor_law="pid"', "design.motor_law must be one of p_control, table"),
        ("design.steer_dps=[1, 2, 3]", "design.steer_dps must be an array of 4 integers"),
        ("design.group_column_offset=2", "design.group_column_offset must be <= 1"),
        ("design.lost_motion=drive", "lost_motion='drive' needs motor_law='table'"),
    ],
)
def test_scenario_design_errors_name_the_key(override, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [override])
    assert message in str(info.value)
    assert len(str(info.value).splitlines()) == 1


# --- Export ---------------------------------------------------------------------------------


def export(argv, capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(export_main, argv, prog="export")
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_export_preset_writes_the_presets_verilog(tmp_path, capsys):
    out = tmp_path / "published.v"
    code, stdout, _ = export(["--preset", "published", "-o", str(out)], capsys)
    assert code == 0 and "preset published" in stdout
    assert out.read_text() == generate_verilog(FollowTargetParams.published())
    on_top = tmp_path / "on_top.v"
    assert (
        export(
            ["--preset", "published", "--max-dps", "400", "--found-rule", "ge", "-o", str(on_top)],
            capsys,
        )[0]
        == 0
    )
    expected = FollowTargetParams.published(max_dps=400, found_rule="ge")
    assert on_top.read_text() == generate_verilog(expected)


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--preset", "paper"], "unknown --preset 'paper'; known presets: published"),
        (["--found-rule", "gte"], "found_rule must be one of ge, gt; got 'gte'"),
        (["--group-column-offset", "2"], "group_column_offset must be <= 1"),
        (["--steer-dps", "1,2"], "steer_dps needs 4 values"),
        (["--lost-motion", "drive"], "lost_motion='drive' needs motor_law='table'"),
    ],
)
def test_export_bad_preset_or_knob_is_one_line(tmp_path, capsys, argv, message):
    out = tmp_path / "x.v"
    code, _, err = export([*argv, "-o", str(out)], capsys)
    assert code == 2 and message in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_verilator_lints_the_preset_export_cleanly(tmp_path):
    path = tmp_path / "follow_target.v"
    path.write_text(generate_verilog(FollowTargetParams.published()))
    result = verilator_lint(path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "%Warning" not in result.stderr and "%Error" not in result.stderr


# --- Shadow runs ----------------------------------------------------------------------------


@pytest.mark.parametrize("shadow_backend", ["model", "cxxrtl"])
def test_shadow_published_first_differs_at_the_first_sighting(shadow_backend):
    # The robot starts facing away from the person. Until it sees them both designs agree:
    # nothing found (N < 128, level 0 for both), motors 0 for 14 frames (ours holds the reset
    # value, the published design has no LED code to steer by), then both search left at
    # 250 DPS. The first frame with N >= 128 is found by ours and at least level 1 for it;
    # the published design drives the speed table there, ours base_dps +- turn: they part.
    s = load_scenario("follow_person", ["robot.heading_deg=180", "sim.duration=4"])
    published = s.with_overrides(['design.preset="published"']).params
    assert published == FollowTargetParams.published()
    with get_backend(shadow_backend, published) as shadow:
        r = run_scenario(s, backend="model", shadow=shadow, shadow_label="published")
    found = np.asarray(r.trajectory["found"])
    first_seen = int(np.argmax(found))
    assert found.any() and first_seen > 15  # the search ran first
    motors = list(zip(r.trajectory["motor_left"], r.trajectory["motor_right"]))
    assert motors[:14] == [(0, 0)] * 14 and set(motors[14:first_seen]) == {(-250, 250)}
    first = r.summary["shadow"]["first_divergence"]
    assert first["frame"] == first_seen
    assert {"motor_left", "motor_right"} <= set(first["outputs"])
    assert first["outputs"]["motor_left"]["primary"] == r.trajectory["motor_left"][first_seen]
    assert r.summary["shadow"]["differing_frames"]["filtered"] == 0  # the same colour filter


def test_run_shadow_published_prints_where_the_designs_part(capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(
            run_main,
            [
                "--backend",
                "model",
                "--rerun",
                "off",
                "--shadow",
                "published",
                "--duration",
                "2",
                "--quiet",
            ],
            prog="run",
        )
    out, err = capsys.readouterr()
    assert info.value.code == 0, err
    # follow_person sees the person from the first frame: the designs part at once.
    assert "shadow published: first differs at frame 0" in out


def test_run_with_the_preset_as_the_design(capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(
            run_main,
            [
                "--backend",
                "model",
                "--rerun",
                "off",
                "--set",
                "design.preset=published",
                "--duration",
                "2",
                "--quiet",
            ],
            prog="run",
        )
    out, err = capsys.readouterr()
    assert info.value.code == 0, err
    assert "verdict: PASS" in out
