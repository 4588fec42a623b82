"""Verilog export of the sensor designs (``--top follow_target_safe``, ``--top follow_line``):
their ports as docs/sensor_designs.md lists them, Verilator lint, the CLI and its errors;
``follow_target``'s export unchanged."""

import os
import re
import subprocess
import sys

import pytest
from test_export import SPEC_PORTS, verilator_lint

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.export import main
from fpga_robotics.flow.export import generate_top_verilog
from fpga_robotics.hw.follow_line import FollowLine
from fpga_robotics.hw.safe_follow import FollowTargetSafe
from fpga_robotics.hw.sensor_params import FollowLineParams, UltrasoundParams
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.hw.verilog import generate_verilog

SAFE_PORTS = {
    **SPEC_PORTS,
    "us_trig": ("output", 1),
    "us_echo": ("input", 1),
    "distance_mm": ("output", 16),
    "obstacle": ("output", 1),
}


def line_ports(n):
    return {
        "clk": ("input", 1),
        "rst": ("input", 1),
        "line": ("input", n),
        "motor_left": ("output", 16),
        "motor_right": ("output", 16),
        "line_seen": ("output", n),
    }


def module_ports(verilog, name):
    """{port: (direction, width)} of module ``name``, from its declarations."""
    found = re.search(rf"module {name}\((.*?)\);(.*?)endmodule", verilog, re.DOTALL)
    assert found, f"no module {name}"
    names = [n.strip() for n in found.group(1).split(",")]
    ports = {}
    for direction, msb, port in re.findall(
        r"^\s*(input|output)\s+(?:signed\s+)?(?:\[(\d+):0\]\s+)?(\w+);",
        found.group(2),
        re.MULTILINE,
    ):
        ports[port] = (direction, int(msb) + 1 if msb else 1)
    assert sorted(ports) == sorted(names)
    return ports


def export(tmp_path, argv, name="out.v"):
    out = tmp_path / name
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["-o", str(out), *argv])
    assert exit_info.value.code == 0
    return out.read_text()


def test_follow_target_safe_ports(tmp_path):
    text = export(tmp_path, ["--top", "follow_target_safe"])
    assert module_ports(text, "follow_target_safe") == SAFE_PORTS


@pytest.mark.parametrize("n", [1, 2, 3])
def test_follow_line_ports(tmp_path, n):
    text = export(tmp_path, ["--top", "follow_line", "--line-n-sensors", str(n)])
    assert module_ports(text, "follow_line") == line_ports(n)


def test_follow_target_export_is_unchanged(tmp_path):
    default = export(tmp_path, [], "a.v")
    explicit = export(tmp_path, ["--top", "follow_target"], "b.v")
    assert default == explicit == generate_verilog()


@pytest.mark.parametrize(
    "name,component",
    [
        ("follow_target_safe", lambda: FollowTargetSafe()),
        (
            "follow_target_safe",
            lambda: FollowTargetSafe(
                None,
                variant_params(
                    "us_echo_inverted",
                    UltrasoundParams(
                        clock_hz=1_000_000, period_us=2400, wait_us=500, max_range_mm=300
                    ),
                ),
            ),
        ),
        (
            "follow_target_safe",
            lambda: FollowTargetSafe(None, variant_params("us_echo_counter_narrow")),
        ),
        ("follow_line", lambda: FollowLine()),
        ("follow_line", lambda: FollowLine(FollowLineParams(n_sensors=1, edge_side="right"))),
        (
            "follow_line",
            lambda: FollowLine(
                variant_params("line_inverted_polarity", FollowLineParams(n_sensors=2))
            ),
        ),
    ],
)
def test_verilator_lints_the_sensor_designs_cleanly(tmp_path, name, component):
    path = tmp_path / f"{name}.v"
    path.write_text(generate_top_verilog(component(), name))
    result = verilator_lint(path, top=name)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "%Warning" not in result.stderr and "%Error" not in result.stderr


def test_default_output_is_named_after_the_top(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main,
            [
                "--top",
                "follow_line",
                "--line-base-dps",
                "180",
                "--variant",
                "line_inverted_polarity",
            ],
        )
    assert exit_info.value.code == 0
    assert os.listdir(tmp_path / "build") == ["follow_line.v"]
    assert capsys.readouterr().out.strip() == (
        "wrote build/follow_line.v (3 sensors, variant line_inverted_polarity, module follow_line)"
    )


def test_options_reach_the_design(tmp_path):
    # The interlock's thresholds are constants of the comparisons; the variant's narrower
    # echo counter is a narrower register.
    plain = export(tmp_path, ["--top", "follow_target_safe"], "a.v")
    stop = export(tmp_path, ["--top", "follow_target_safe", "--stop-mm", "257"], "b.v")
    narrow = export(
        tmp_path, ["--top", "follow_target_safe", "--variant", "us_echo_counter_narrow"], "c.v"
    )
    assert "9'h101" in stop and "9'h101" not in plain  # 257
    assert re.search(r"reg \[20:0\] count\b", plain)
    assert re.search(r"reg \[19:0\] count\b", narrow)


def test_turret_tracker_takes_the_follow_target_options_for_its_body_camera(tmp_path, capsys):
    """--width/--height size the body camera's channel; the pan camera's stays 160x120."""
    out = tmp_path / "t.v"
    assert (
        main(["--top", "turret_tracker", "--width", "320", "--height", "240", "-o", str(out)]) == 0
    )
    assert capsys.readouterr().out == (
        f"wrote {out} (body camera 320x240, pan camera 160x120 on a servo, module turret_tracker)\n"
    )
    text = out.read_text()
    assert re.search(r"output \[8:0\] centroid_x;", text)  # 320 columns
    assert re.search(r"output \[7:0\] turret_centroid_x;", text)  # 160 columns


@pytest.mark.parametrize(
    "argv,message",
    [
        (
            ["--top", "follow_line", "--width", "320"],
            (
                "--width applies to --top follow_target, follow_target_safe or turret_tracker (its "
                "body camera's channel), not to --top follow_line"
            ),
        ),
        (
            ["--top", "corridor_follow", "--preset", "published"],
            "--preset applies to --top follow_target, follow_target_safe or turret_tracker",
        ),
        (["--line-base-dps", "3"], "--line-base-dps applies to --top follow_line"),
        (
            ["--top", "follow_line", "--stop-mm", "3"],
            "--stop-mm applies to --top follow_target_safe",
        ),
        (
            ["--variant", "us_echo_inverted"],
            "--variant us_echo_inverted is a seeded bug of --top follow_target_safe",
        ),
        (["--variant", "lidar_bearing_mirrored"], "bug of --top corridor_follow: it needs --top"),
        (["--variant", "turret_pan_inverted"], "it needs --top turret_tracker"),
        (["--variant", "nope"], "unknown --variant 'nope'; known variants: line_inverted"),
        (
            ["--top", "follow_line", "--variant", "us_echo_inverted"],
            "is a variant of --top follow_target_safe",
        ),
        (["--top", "follow_line", "--variant", "nope"], "known variants: line_inverted_polarity"),
        (
            ["--top", "follow_target_safe", "--stop-mm", "500"],
            "resume_mm=400 must be >= stop_mm=500",
        ),
        (["--top", "follow_target_safe", "--us-trigger-us", "5"], "trigger_us must be >= 10"),
        (["--top", "follow_line", "--line-n-sensors", "4"], "n_sensors must be <= 3"),
        (
            ["--top", "follow_line", "--board", "ulx3s-85f"],
            "cannot be combined with --top follow_line",
        ),
    ],
)
def test_bad_options_exit_2_with_a_clear_message(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["-o", str(tmp_path / "x.v"), *argv])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_module_runs_with_python_m(tmp_path):
    out = tmp_path / "safe.v"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics.export",
            "--top",
            "follow_target_safe",
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert module_ports(out.read_text(), "follow_target_safe") == SAFE_PORTS
    bad = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics.export",
            "--top",
            "follow_line",
            "--line-n-sensors",
            "0",
            "-o",
            str(tmp_path / "x.v"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert bad.returncode == 2 and "n_sensors must be >= 1" in bad.stderr
    assert "Traceback" not in bad.stderr and not (tmp_path / "x.v").exists()
