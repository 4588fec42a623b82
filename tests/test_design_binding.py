"""How a design of one's own meets the connectors (docs/your_design.md): wheel ports narrower
than the connector's 16 bits are read sign-extended, wider or unsigned ones are refused in
one line; a camera stream declared under the design's own port name is streamed to it."""

from pathlib import Path

import pytest

from fpga_robotics import cli
from fpga_robotics.designs.reference import DesignError, resolve_design
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

DESIGNS = Path(__file__).parent / "data" / "user_designs"
NARROW = f"{DESIGNS / 'narrow_wheels.py'}:NarrowWheels"

#: A room to stand in; the design drives constant wheel commands.
STRAIGHT = """
name = "narrow"
people = []
[sim]
duration = 0.5
clock_hz = 10000.0
[design]
top = "{top}"
[room]
width = 4.0
depth = 2.0
[robot]
model = "gopigo3"
start = [2.0, 1.0]
"""


def test_narrow_signed_wheels_are_read_sign_extended(tmp_path):
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=NARROW))
    result = run_scenario(load_scenario(str(tmp_path / "s.toml")), backend="pysim")
    traj = result.trajectory
    # -100 in 8 bits is 0x9C: read unsigned it would be 156.
    assert (traj["motor_left"][1:] == -100).all() and (traj["motor_right"][1:] == 60).all()
    # The left wheel backwards, the right forwards: the robot turns left (heading grows).
    assert traj["heading"][-1] > traj["heading"][0]


@pytest.mark.parametrize(
    "params, message",
    [
        (
            {"width": 17},
            "port 'motor_left' (the wheels' motor_left pin) is an output of signed(17)",
        ),
        (
            {"width": 16, "signed_wheels": False},
            "is an output of unsigned(16); the wheels take a signed output of at most 16 bits",
        ),
    ],
)
def test_wide_or_unsigned_wheels_are_one_line_errors(params, message, tmp_path, capsys):
    with pytest.raises(DesignError, match=message.replace("(", r"\(").replace(")", r"\)")):
        resolve_design(NARROW, params)
    # Every command that resolves the design says the same: designs, run.
    argv = [NARROW] + [f"--param={k}={str(v).lower()}" for k, v in params.items()]
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=NARROW))
    sets = [a for k, v in params.items() for a in ("--set", f"design.params.{k}={str(v).lower()}")]
    for command in (
        ["designs", *argv],
        ["run", "--scenario", str(tmp_path / "s.toml"), "--rerun", "off", *sets],
    ):
        with pytest.raises(SystemExit) as info:
            cli.main(command)
        err = capsys.readouterr().err
        assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
        assert message in err
