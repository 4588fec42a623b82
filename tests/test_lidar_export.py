"""Verilog export of the LIDAR designs (``export --design corridor_follow``,
``corridor_follow_uart``): their ports as the designs declare them, Verilator lint clean."""

import pytest
from test_export import verilator_lint
from test_export_sensor_designs import module_ports

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.export import main

COMMON = {
    "clk": ("input", 1),
    "rst": ("input", 1),
    "motor_left": ("output", 16),
    "motor_right": ("output", 16),
    "nearest_mm": ("output", 14),
    "bearing_q6": ("output", 15),
    "found": ("output", 1),
}
PORTS = {
    # The sample stream: valid, and the 38-bit payload (angle_q6 15, distance_q2 16,
    # quality 6, start 1).
    "corridor_follow": {
        **COMMON,
        "lidar__valid": ("input", 1),
        "lidar__payload": ("input", 38),
    },
    "corridor_follow_uart": {
        **COMMON,
        "lidar_rx": ("input", 1),
        "framing_errors": ("output", 8),
        "resyncs": ("output", 8),
    },
}


@pytest.mark.parametrize("top", sorted(PORTS))
def test_ports_and_lint(tmp_path, top):
    out = tmp_path / f"{top}.v"
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["--design", top, "-o", str(out)])
    assert exit_info.value.code == 0
    assert module_ports(out.read_text(), top) == PORTS[top]
    lint = verilator_lint(out, top)
    assert lint.returncode == 0, lint.stderr


def test_export_top_takes_the_lidar_designs_parameters_and_variant(tmp_path, capsys):
    a = tmp_path / "a.v"
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main, ["--top", "corridor_follow", "--variant", "lidar_bearing_mirrored", "-o", str(a)]
        )
    assert exit_info.value.code == 0
    assert "keep 420 mm, stop 300 mm, variant lidar_bearing_mirrored" in capsys.readouterr().out
    assert module_ports(a.read_text(), "corridor_follow") == PORTS["corridor_follow"]
    b = tmp_path / "b.v"
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main,
            ["--top", "corridor_follow_uart", "--uart-clock-hz", "1000000", "-o", str(b)],
        )
    assert exit_info.value.code == 0
    assert "115200 baud at 1000000 Hz" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, message",
    [
        (
            ["--top", "corridor_follow", "--uart-baud", "9600"],
            "--uart-baud applies to --top corridor_follow_uart",
        ),
        (["--top", "corridor_follow", "--width", "80"], "not to --top corridor_follow"),
        (
            ["--top", "corridor_follow_uart", "--uart-clock-hz", "300000"],
            "a bit must last at least 4 cycles",
        ),
        (
            ["--top", "corridor_follow_uart", "--variant", "lidar_bearing_mirrored"],
            "is a variant of --top corridor_follow,",
        ),
    ],
)
def test_export_top_errors(tmp_path, capsys, argv, message):
    out = tmp_path / "x.v"
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, [*argv, "-o", str(out)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and not out.exists()
