"""The bumper connector: contact inside its arc, hand-placed against a wall."""

import math

import numpy as np
import pytest

from fpga_robotics.loop.connectors import ConnectorError
from fpga_robotics.loop.connectors.bumper import BumperConnector
from fpga_robotics.scenario.connectors import parse_connectors
from fpga_robotics.sim.world import World


class FakeIO:
    def __init__(self):
        self.pokes = []

    def poke(self, pin, value):
        self.pokes.append((pin, value))


def _bumper(x, heading, margin=0.005, arc=120.0):
    """A GoPiGo3 (radius 0.11 m) at (x, 1) in a 4 x 2 m room: the wall x = 4 is 4 - x away."""
    world = World.from_config(
        {
            "room": {"width": 4.0, "depth": 2.0},
            "robot": {"model": "gopigo3", "start": [x, 1.0], "heading_deg": math.degrees(heading)},
            "people": [],
        }
    )
    (spec,) = parse_connectors({"sensors": [{"kind": "bumper", "margin": margin, "arc_deg": arc}]})
    return BumperConnector(
        spec.name, spec.mount, spec.params, world=world, rng=np.random.default_rng(0)
    )


def test_pressed_within_the_margin_of_a_wall_ahead_only():
    near = 4.0 - 0.11 - 0.003  # 3 mm from the wall: inside the 5 mm margin
    far = 4.0 - 0.11 - 0.01  # 10 mm: outside
    assert _bumper(near, 0.0).touching()
    assert not _bumper(far, 0.0).touching()
    # Facing away: the wall is behind, outside the 120 degree arc.
    assert not _bumper(near, math.pi).touching()
    # Turned 50 degrees: the nearest wall point is 50 degrees off, inside +-60 ...
    assert _bumper(near, math.radians(50)).touching()
    # ... and outside a 90 degree bumper (+-45).
    assert not _bumper(near, math.radians(50), arc=90.0).touching()


def test_the_pin_is_poked_only_when_it_changes():
    bumper, io = _bumper(4.0 - 0.11 - 0.003, 0.0), FakeIO()
    bumper.before_step(io, 0.0, 0.01)
    bumper.before_step(io, 0.01, 0.01)
    assert io.pokes == [("pressed", 1)]
    assert bumper.measurement() == {"pressed": 1}


@pytest.mark.parametrize(
    "table, message",
    [
        ({"kind": "bumper", "margin": -1}, "robot.sensors[0].margin must be a number in 0..0.1"),
        ({"kind": "bumper", "colour": 1}, "unknown key 'colour' for a bumper"),
        # The mount keys it names are the ones a bumper takes (yaw_deg, not yaw).
        (
            {"kind": "bumper", "yaw": 10},
            (
                "unknown key 'yaw' for a bumper; its keys: margin, arc_deg "
                "(and the mount: forward, left, height, yaw_deg)"
            ),
        ),
        ({"kind": "bumpr"}, "unknown connector kind 'bumpr'"),
        (
            {"kind": "servo"},
            "a 'servo' connector is an actuator; declare it in [[robot.actuators]]",
        ),
        ({"kind": "wheels"}, "robot.sensors[0].kind: the wheels are always there"),
        ({"kind": "bumper", "yaw_deg": 999}, "robot.sensors[0].yaw_deg must be a number"),
        ({"kind": "bumper", "ports": {"pushed": "x"}}, "has no pin 'pushed'"),
    ],
)
def test_bad_tables_name_the_key(table, message):
    with pytest.raises(
        ConnectorError,
        match=message.replace("[", r"\[")
        .replace("]", r"\]")
        .replace("(", r"\(")
        .replace(")", r"\)")
        .replace(".", r"\."),
    ):
        parse_connectors({"sensors": [table]})
