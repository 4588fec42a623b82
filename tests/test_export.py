"""Verilog export: the port table of docs/contract.md, Verilator lint, the CLI and its errors."""

import hashlib
import os
import re
import subprocess
import sys

import pytest

from fpga_robotics.cli.export import main
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.backends.toolchain import verilator_root
from fpga_robotics.sim.files import default_file_mode

#: The port table of docs/contract.md: port -> (direction, width) at 160x120.
SPEC_PORTS = {
    "clk": ("input", 1),
    "rst": ("input", 1),
    "pixels__valid": ("input", 1),
    "pixels__payload": ("input", 14),
    "color_sel": ("input", 3),
    "filtered__valid": ("output", 1),
    "filtered__payload": ("output", 14),
    "frame_done": ("output", 1),
    "found": ("output", 1),
    "proximity": ("output", 3),
    "centroid_x": ("output", 8),
    "centroid_leds": ("output", 8),
    "motor_left": ("output", 16),
    "motor_right": ("output", 16),
}

#: Warnings of -Wall that Amaranth/Yosys output always has, and why they are harmless:
#: DECLFILENAME (submodules share the file), UNUSEDSIGNAL (debug aliases of struct fields),
#: WIDTHEXPAND (comparisons with narrower constants, zero-extended as intended),
#: PROCASSINIT (yosys initialises always-block variables).
LINT_WAIVERS = ("DECLFILENAME", "UNUSEDSIGNAL", "WIDTHEXPAND", "PROCASSINIT")


def top_ports(verilog):
    """{port: (direction, width)} of module follow_target, from its declarations."""
    header = re.search(r"module follow_target\((.*?)\);(.*?)endmodule", verilog, re.DOTALL)
    assert header, "no module follow_target"
    names = [n.strip() for n in header.group(1).split(",")]
    ports = {}
    for direction, msb, name in re.findall(
        r"^\s*(input|output)\s+(?:signed\s+)?(?:\[(\d+):0\]\s+)?(\w+);",
        header.group(2),
        re.MULTILINE,
    ):
        ports[name] = (direction, int(msb) + 1 if msb else 1)
    assert sorted(ports) == sorted(names)
    return ports


def test_ports_match_the_hardware_contract():
    assert top_ports(generate_verilog()) == SPEC_PORTS


def test_widths_follow_the_geometry():
    ports = top_ports(generate_verilog(FollowTargetParams(width=320, height=240)))
    assert ports["centroid_x"] == ("output", 9)
    assert {k: v for k, v in ports.items() if k != "centroid_x"} == {
        k: v for k, v in SPEC_PORTS.items() if k != "centroid_x"
    }


def verilator_lint(path, top="follow_target"):
    root = verilator_root()
    env = dict(os.environ, VERILATOR_ROOT=str(root))
    argv = [
        str(root / "bin" / "verilator"),
        "--lint-only",
        "-Wall",
        *(f"-Wno-{w}" for w in LINT_WAIVERS),
        "--top-module",
        top,
        str(path),
    ]
    return subprocess.run(argv, capture_output=True, text=True, env=env, timeout=120, check=False)


@pytest.mark.parametrize(
    "params",
    [
        FollowTargetParams(),
        FollowTargetParams(width=640, height=480),
        FollowTargetParams(
            kp_num=-7,
            kp_shift=3,
            base_dps=(1, -2, 3, -4, 5, -6, 7, -8),
            max_dps=9,
            lost_frames=1,
            search_dps=-5,
            min_pixels=1,
            proximity_thresholds=(0, 0, 1, 2, 3, 4, 1 << 31),
        ),
    ],
)
def test_verilator_lints_the_export_cleanly(tmp_path, params):
    path = tmp_path / "follow_target.v"
    path.write_text(generate_verilog(params))
    result = verilator_lint(path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "%Warning" not in result.stderr and "%Error" not in result.stderr


def test_cli_writes_one_file_and_creates_the_directory(tmp_path, capsys):
    out = tmp_path / "new" / "dir" / "ft.v"
    with pytest.raises(SystemExit) as exit_info:
        from fpga_robotics.cli.errors import run_cli

        run_cli(
            main,
            [
                "-o",
                str(out),
                "--width",
                "320",
                "--height",
                "240",
                "--kp-num",
                "2",
                "--base-dps",
                "0,100,90,80,70,60,-10,-20",
            ],
        )
    assert exit_info.value.code == 0
    text = out.read_text()
    assert "module follow_target(" in text and text.count("endmodule") >= 1
    assert top_ports(text)["centroid_x"] == ("output", 9)
    assert os.listdir(out.parent) == ["ft.v"]  # no temporary file left behind
    assert out.stat().st_mode & 0o777 == default_file_mode()  # not mkstemp's private 0600
    assert "wrote" in capsys.readouterr().out


def test_module_is_runnable_with_python_m(tmp_path):
    out = tmp_path / "ft.v"
    result = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.export", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert top_ports(out.read_text()) == SPEC_PORTS


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--width", "7"], "width must be >= 16"),
        (["--width", "104"], "divisible by 8"),
        (["--diff-min", "16"], "diff_min must be <= 15"),
        (["--base-dps", "0,1,2"], "base_dps needs 8 values"),
        (["--proximity-thresholds", "5,4,3,2,1,0,0"], "non-decreasing"),
        (["--kp-shift", "-1"], "kp_shift must be >= 0"),
    ],
)
def test_bad_parameters_exit_2_with_a_clear_message(tmp_path, argv, message):
    out = tmp_path / "ft.v"
    result = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.export", "-o", str(out), *argv],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists() and os.listdir(tmp_path) == []


def test_malformed_list_is_an_argparse_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["-o", str(tmp_path / "x.v"), "--base-dps", "0,fast"])
    assert exit_info.value.code == 2
    assert "comma-separated integers" in capsys.readouterr().err


def test_output_is_deterministic_across_processes():
    # Same parameters, same text in every process (build caches key on it): another
    # interpreter with another hash seed gives the very same bytes.
    here = hashlib.sha256(generate_verilog().encode()).hexdigest()
    code = (
        "import hashlib; from fpga_robotics.hw.verilog import generate_verilog; "
        "print(hashlib.sha256(generate_verilog().encode()).hexdigest())"
    )
    for hash_seed in ("1", "2"):
        other = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            timeout=300,
            check=True,
            env=dict(os.environ, PYTHONHASHSEED=hash_seed),
        )
        assert other.stdout.strip() == here


def test_output_path_errors_are_usage_errors(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    for out, message in ((tmp_path, "is a directory"), (blocker / "x.v", "cannot write")):
        result = subprocess.run(
            [sys.executable, "-m", "fpga_robotics.export", "-o", str(out)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert result.returncode == 2 and message in result.stderr, result.stderr
        assert "Traceback" not in result.stderr
