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
