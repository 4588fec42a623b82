"""``python -m fpga_robotics.run``: arguments, errors (one line, exit 2) and the summary file."""

import json
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main

SHIPPED = ("follow_person", "divider", "lighting", "heavy_robot", "lost_target")
REQUIRED = (
    "scenario",
    "backend",
    "resolution",
    "seed",
    "sim_time_s",
    "frames",
    "wall_time_s",
    "ms_per_frame",
    "realtime_factor",
    "min_distance_m",
    "mean_distance_m",
    "target_in_view_fraction",
    "collisions",
    "verdict",
    "checks",
)


def run(argv, capsys):
    """Call the CLI as ``python -m`` does; return (exit code, stdout, stderr)."""
    with pytest.raises(SystemExit) as info:
        run_cli(main, argv, prog="fpga-robotics run")
    out, err = capsys.readouterr()
    return info.value.code, out, err


def usage_error(argv, capsys):
    code, _out, err = run(argv, capsys)
    assert code == 2, err
    assert "Traceback" not in err
    return err


def test_unknown_scenario_lists_the_shipped_ones(capsys):
    err = usage_error(["--scenario", "folow_person"], capsys)
    assert "unknown scenario 'folow_person'" in err
    assert all(name in err for name in SHIPPED)
    assert len(err.strip().splitlines()) == 1


def test_malformed_scenario_file_names_its_line(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n[sim]\nduration = = 3\n')
    err = usage_error(["--scenario", str(path)], capsys)
    assert "malformed TOML" in err and "line 3" in err and str(path) in err


def test_unknown_set_key_shows_close_matches(capsys):
    err = usage_error(["--set", "design.kp_nm=2", "--rerun", "off"], capsys)
    assert "design.kp_nm" in err and "design.kp_num" in err


def test_bad_set_value_names_the_key(capsys):
    err = usage_error(["--set", "robot.mass=-3", "--rerun", "off"], capsys)
    assert "robot.mass" in err


@pytest.mark.parametrize("res", ["160", "160x", "x120", "axb", "0x120"])
def test_bad_resolution(res, capsys):
    err = usage_error(["--resolution", res, "--rerun", "off"], capsys)
    assert "resolution must look like WIDTHxHEIGHT" in err


def test_resolution_the_design_cannot_take_is_a_clear_error(capsys):
    # A window of 161 - 2*16 = 129 columns cannot be split into 8 equal bins.
    err = usage_error(["--resolution", "161x120", "--rerun", "off"], capsys)
    assert "divisible by 8" in err


def test_unopenable_camera(capsys):
    err = usage_error(["--source", "camera:97", "--rerun", "off"], capsys)
    assert "cannot open camera 97" in err


def test_missing_and_undecodable_video(tmp_path, capsys):
    err = usage_error(["--source", str(tmp_path / "none.avi"), "--rerun", "off"], capsys)
    assert "no such file" in err
    junk = tmp_path / "junk.avi"
    junk.write_bytes(b"not a video at all" * 10)
    err = usage_error(["--source", str(junk), "--rerun", "off"], capsys)
    assert "cannot read video" in err


def test_bad_duration_and_log_every(capsys):
    assert "--duration" in usage_error(["--duration", "0", "--rerun", "off"], capsys)
    err = usage_error(["--log-every", "0", "--duration", "0.1", "--backend", "model"], capsys)
    assert "log-every" in err or "log_every" in err


def test_a_summary_over_the_scenario_file_is_refused(tmp_path, capsys):
    scenario = tmp_path / "mine.toml"
    text = (resources.files("fpga_robotics.scenario") / "shipped" / "divider.toml").read_text()
    scenario.write_text(text)
    argv = ["--scenario", str(scenario), "--backend", "model", "--duration", "0.1"]
    err = usage_error([*argv, "--rerun", "off", "--summary", str(scenario)], capsys)
    assert "is the same path as the input --scenario" in err and len(err.splitlines()) == 1
    assert scenario.read_text() == text
    assert [p.name for p in tmp_path.iterdir()] == ["mine.toml"]


@pytest.mark.parametrize("target", ["wall_stop.py", "speeds.py"])
def test_a_summary_over_the_scenario_s_design_source_is_refused(target, tmp_path, capsys):
    # The scenario names the design (no --design): its file, and a module it imports beside
    # it, are inputs as the scenario is.
    data = Path(__file__).parent / "data" / "user_designs"
    (tmp_path / "speeds.py").write_text("SPEED = 300\n")
    design = (data / "wall_stop.py").read_text()
    (tmp_path / "wall_stop.py").write_text("from speeds import SPEED  # noqa: F401\n" + design)
    (tmp_path / "wall_stop.toml").write_text((data / "wall_stop.toml").read_text())
    before = {f.name: f.read_text() for f in tmp_path.iterdir()}
    argv = ["--scenario", str(tmp_path / "wall_stop.toml"), "--duration", "0.1", "--rerun", "off"]
    err = usage_error([*argv, "--summary", str(tmp_path / target)], capsys)
    assert len(err.splitlines()) == 1
    source = "design.top" if target == "wall_stop.py" else "design.top's module"
    assert f"is the same path as the input {source} {str(tmp_path / target)!r}" in err
    assert {f.name: f.read_text() for f in tmp_path.iterdir()} == before


def test_list_scenarios(capsys):
    code, out, _ = run(["--list-scenarios"], capsys)
    assert code == 0
    names = [line.split()[0] for line in out.splitlines()]
    assert set(SHIPPED) <= set(names)


def test_a_short_run_writes_its_summary_atomically(tmp_path, capsys):
    path = tmp_path / "out" / "s.json"
    code, out, _ = run(
        [
            "--backend",
            "model",
            "--duration",
            "2",
            "--seed",
            "4",
            "--rerun",
            "off",
            "--color",
            "red",
            "--summary",
            str(path),
            "--quiet",
        ],
        capsys,
    )
    assert code == 0
    s = json.loads(path.read_text())
    for key in REQUIRED:
        assert key in s, key
    assert (s["scenario"], s["backend"], s["resolution"], s["seed"]) == (
        "follow_person",
        "model",
        "160x120",
        4,
    )
    assert s["frames"] == 60 and s["sim_time_s"] == pytest.approx(2.0)
    assert s["verdict"] == "pass" and all(c["passed"] for c in s["checks"])
    assert s["realtime_factor"] == pytest.approx(s["sim_time_s"] / s["wall_time_s"], rel=1e-2)
    assert list(path.parent.iterdir()) == [path]  # no temporary file left behind
    assert "verdict: PASS" in out


def test_a_failing_check_exits_1(tmp_path, capsys):
    path = tmp_path / "s.json"
    code, out, _ = run(
        [
            "--backend",
            "model",
            "--duration",
            "1",
            "--rerun",
            "off",
            "--quiet",
            "--set",
            "checks.max_wheel_command_dps=1",
            "--summary",
            str(path),
        ],
        capsys,
    )
    assert code == 1
    s = json.loads(path.read_text())
    bad = [c for c in s["checks"] if not c["passed"]]
    assert s["verdict"] == "fail" and [c["name"] for c in bad] == ["max_wheel_command_dps"]
    assert "[FAIL] max_wheel_command_dps" in out


def test_saves_a_recording_where_asked(tmp_path, capsys):
    rrd = tmp_path / "run.rrd"
    code, out, _ = run(
        [
            "--backend",
            "model",
            "--duration",
            "0.5",
            "--rerun",
            f"save:{rrd}",
            "--log-every",
            "5",
            "--quiet",
        ],
        capsys,
    )
    assert code == 0
    assert rrd.exists() and rrd.stat().st_size > 0
    assert str(rrd) in out


def test_module_entry_point_prints_one_line_and_exits_2():
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.run", "--scenario", "nope", "--rerun", "off"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith("fpga-robotics run: error: unknown scenario 'nope'")
    assert "Traceback" not in proc.stderr


def test_negative_seed(capsys):
    assert "--seed" in usage_error(["--seed", "-1", "--rerun", "off"], capsys)


@pytest.mark.parametrize("color", ["green", "blue", "cyan"])
def test_target_color_dresses_the_target_and_follows_it(color, tmp_path, capsys):
    path = tmp_path / "s.json"
    code, _out, err = run(
        [
            "--backend",
            "model",
            "--duration",
            "4",
            "--rerun",
            "off",
            "--quiet",
            "--target-color",
            color,
            "--summary",
            str(path),
        ],
        capsys,
    )
    assert code == 0, err
    s = json.loads(path.read_text())
    assert s["color"] == color and s["found_fraction"] > 0.9
    # Without the matching colour select the same person is invisible to the design.
    code, _out, _err = run(
        [
            "--backend",
            "model",
            "--duration",
            "4",
            "--rerun",
            "off",
            "--quiet",
            "--target-color",
            color,
            "--set",
            'color.initial="red"',
            "--summary",
            str(path),
        ],
        capsys,
    )
    s = json.loads(path.read_text())
    assert s["color"] == color  # --target-color sets the colour select last


@pytest.mark.parametrize("order", [0, 1])
def test_color_is_the_select_when_the_target_wears_another(order, tmp_path, capsys):
    # The target in blue, the design looking for green: it does not see the target.
    path = tmp_path / "s.json"
    options = [["--target-color", "blue"], ["--color", "green"]]
    argv = ["--backend", "model", "--duration", "1", "--rerun", "off", "--quiet"]
    run([*argv, *options[order], *options[1 - order], "--summary", str(path)], capsys)
    s = json.loads(path.read_text())
    assert s["color"] == "green" and s["found_fraction"] == 0.0
    assert [o for o in s["overrides"] if o.startswith("color.")] == ['color.initial="green"']


def test_target_color_red_clothes_are_invisible_to_green(tmp_path, capsys):
    path = tmp_path / "s.json"
    code, _out, _err = run(
        [
            "--backend",
            "model",
            "--duration",
            "3",
            "--rerun",
            "off",
            "--quiet",
            "--color",
            "green",
            "--summary",
            str(path),
        ],
        capsys,
    )
    assert code == 1
    assert json.loads(path.read_text())["found_fraction"] == 0.0


@pytest.mark.parametrize(
    "people",
    [
        "",  # no [[people]]: the world's default person is the target
        '[[people]]\nname = "walker"\nwaypoints = [[4.0, 2.0], [4.5, 2.0]]\nspeed = 0.2\n',
    ],
)
def test_target_color_dresses_an_implied_target(people, tmp_path, capsys):
    """The target is the first person when no person says ``target``, or the default person
    of a file without people: --target-color dresses it as it dresses an explicit one."""
    scenario = tmp_path / "implied.toml"
    scenario.write_text(f'name = "implied"\n[sim]\nduration = 3.0\n{people}')
    path = tmp_path / "s.json"
    args = ["--scenario", str(scenario), "--backend", "model", "--rerun", "off", "--quiet"]
    code, _out, err = run([*args, "--target-color", "green", "--summary", str(path)], capsys)
    assert code in (0, 1), err
    green = json.loads(path.read_text())
    assert green["color"] == "green" and green["found_fraction"] > 0.5
    # Undressed, the (red) person is invisible to a green colour select.
    code, _out, err = run([*args, "--color", "green", "--summary", str(path)], capsys)
    assert json.loads(path.read_text())["found_fraction"] == 0.0


def test_target_color_refuses_a_scenario_whose_first_person_is_not_the_target(tmp_path, capsys):
    scenario = tmp_path / "none.toml"
    scenario.write_text(
        '[[people]]\nname = "passer"\ntarget = false\nwaypoints = [[4.0, 2.0], [4.5, 2.0]]\n'
    )
    err = usage_error(
        ["--scenario", str(scenario), "--target-color", "green", "--rerun", "off"], capsys
    )
    assert "has no target person" in err


@pytest.mark.parametrize(
    "shorthand,item",
    [
        (["--duration", "2"], "sim.duration=3"),
        (["--resolution", "320x240"], "camera.resolution=80x60"),
        (["--color", "green"], "color.initial=blue"),
    ],
)
def test_a_shorthand_beside_a_set_of_its_key_is_refused(shorthand, item, capsys):
    # Either order: the shorthand used to win silently over the --set.
    for argv in ([*shorthand, "--set", item], ["--set", item, *shorthand]):
        err = usage_error([*argv, "--rerun", "off"], capsys)
        assert f"{shorthand[0]} and --set {item} both set {item.split('=')[0]}" in err


def test_the_options_table_of_running_md_has_a_row_per_option():
    """docs/running.md's "Options" table is the reference a user reads: every option of
    `run --help` has its row there, and every row is an option."""
    import re
    from pathlib import Path

    from fpga_robotics.cli.run import build_parser

    page = (Path(__file__).resolve().parent.parent / "docs" / "running.md").read_text()
    table = page.split("\n## Options\n", 1)[1].split("\n\n", 1)[0]
    documented = set(re.findall(r"^\| `(--[\w-]+)", table, re.MULTILINE))
    options = {a.option_strings[-1] for a in build_parser()._actions if a.option_strings}
    assert documented == options - {"--help"}
