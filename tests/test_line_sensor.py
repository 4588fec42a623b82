"""KY-033 physics (sim/world/line_sensor.py): HIGH over a dark line, LOW over the floor, the
threshold, seeded noise, and a robot driven straight across a line of known width: the bit
is high for width / speed seconds, to within one physics step."""

import math

import numpy as np
import pytest

from fpga_robotics.loop.connectors.base import Mount
from fpga_robotics.loop.connectors.line_sensors import LineSensorsConnector
from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.kinematics import DEG
from fpga_robotics.sim.world.line_sensor import KY033, KY033Params, luminance, spot_offsets

FLOOR = (0.55, 0.55, 0.5)
QUIET = KY033Params(noise_std=0.0)


def _world(lines, start=(1.0, 3.0)):
    return World.from_config(
        {
            "room": {"floor_color": list(FLOOR), "lines": lines},
            "robot": {"model": "gopigo3", "start": list(start)},
            "people": [],
        }
    )


def test_dark_line_high_floor_low_and_the_threshold():
    world = _world([{"points": [[2.0, 1.0], [2.0, 5.0]], "width": 0.019}])
    sensor = KY033(QUIET)
    assert sensor.reflectance(world, 1.5, 3.0) == pytest.approx(luminance(FLOOR))
    assert sensor.reflectance(world, 2.0, 3.0) == 0.0
    assert sensor.output(world, 2.0, 3.0) == 1 and sensor.output(world, 1.5, 3.0) == 0
    # The spot's centre just inside the tape's edge: the centre and the three points on the
    # tape's side (x offsets +r/3, +r/3, +2r/3) are on the tape, 3 of 7 see the floor.
    edge = 2.0 - 0.0095 + 1e-6
    assert sensor.reflectance(world, edge, 3.0) == pytest.approx(3 / 7 * luminance(FLOOR))
    assert KY033(KY033Params(noise_std=0.0, threshold=0.2)).output(world, edge, 3.0) == 0
    assert KY033(KY033Params(noise_std=0.0, threshold=0.3)).output(world, edge, 3.0) == 1
    # Too high above the floor: no reflection, always HIGH.
    assert KY033(KY033Params(noise_std=0.0, height=0.02)).output(world, 1.5, 3.0) == 1


def test_spot_points_are_inside_the_spot():
    offsets = spot_offsets(0.003)
    assert len(offsets) == 7 and max(math.hypot(*o) for o in offsets) <= 0.003


def test_noise_is_seeded_and_flips_bits_near_the_threshold():
    world = _world([])
    params = KY033Params(noise_std=0.1, threshold=luminance(FLOOR))  # right at the floor's

    def bits(seed):
        sensor = KY033(params, np.random.default_rng(seed))
        return [sensor.output(world, 1.5, 3.0) for _ in range(400)]

    a = bits(1)
    assert a == bits(1) and a != bits(2)
    assert 0.4 < sum(a) / len(a) < 0.6  # at the threshold: high about half the time


class _IO:
    """The part of a PinIO the line sensors use: the poked values."""

    def __init__(self):
        self.poked = []

    def poke(self, pin, value):
        self.poked.append((pin, value))


@pytest.mark.parametrize("dps", [120.0, 300.0])
def test_crossing_a_line_at_known_speed(dps):
    width, dt = 0.019, 0.002
    world = _world([{"points": [[2.0, 1.0], [2.0, 5.0]], "width": width}], start=(1.5, 3.0))
    v = world.robot_spec.wheel_radius * dps * DEG  # the wheels' steady speed, m/s
    sensors = LineSensorsConnector.parse({"sensors": [{"forward": 0.05}], "noise_std": 0.0}, "s")
    conn = LineSensorsConnector("line", Mount(), sensors, world=world, rng=None)
    io = _IO()
    world.set_wheel_dps(dps, dps)
    high_steps, speeds = 0, []
    while world.robot_pose()[0] + 0.05 < 2.0 + 0.05:
        conn.before_step(io, world.time, dt)
        if io.poked[-1][1]:
            high_steps += 1
            speeds.append(world.robot_velocity()[0])
        world.step(dt)
    assert speeds and max(abs(s - v) for s in speeds) < 1e-3 * v  # steady when crossing
    assert abs(high_steps * dt - width / v) <= dt + 1e-9
    assert io.poked[0] == ("line", 0)
