"""The shipped scenarios at the durations a user tries (the default, 30, 60 and 120 s), on the
model backend (bit exact with the compiled ones; the real-clock scenarios on the fastest pin
backend), and why their people yield to the robot."""

import math

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario, shipped_scenarios
from fpga_robotics.sim.world import TURTLEBOT2

SHIPPED = sorted(shipped_scenarios())
#: Real-clock scenarios simulate 50 M design cycles a second of world time: 30 and 60 s only.
REAL_CLOCK = ("line_track", "obstacle_between")
#: The edit-test loop keeps the 30 s runs of the compressed scenarios; the rest is slow-tier.
RUNS = [
    (name, 30) if name not in REAL_CLOCK else pytest.param(name, 30, marks=pytest.mark.slow)
    for name in SHIPPED
] + [
    pytest.param(name, duration, marks=pytest.mark.slow)
    for name in SHIPPED
    for duration in (60, 120)
    if not (duration == 120 and name in REAL_CLOCK)
]


@pytest.mark.parametrize("name, duration", RUNS)
def test_shipped_scenarios_pass_on_long_runs(name, duration):
    s = load_scenario(name, [f"sim.duration={duration}"])
    r = run_scenario(s, backend="model" if s.sim.timing == "compressed" else "auto")
    failed = [c["text"] for c in r.summary["checks"] if not c["passed"]]
    assert r.summary["verdict"] == "pass", failed


def test_without_yielding_the_person_walks_into_the_reversing_robot():
    """The finding behind ``yield_gap``: after a minute the looping person comes back along
    their path towards the robot, which reverses at the design's fastest (level 7: -150 DPS,
    0.09 m/s); a 0.3 m/s walker catches it up."""
    s = load_scenario("follow_person", ["sim.duration=60", "people.0.yield_gap=0"])
    r = run_scenario(s, backend="model")
    assert r.summary["collisions"]["person"] >= 1
    person = r.summary["collision_summary"]["person"]
    assert person["episodes"] == r.summary["collisions"]["person"]
    assert person["contact_s"] > 0 and person["max_impulse_ns"] > 0
    assert r.summary["robot_at_fault_collisions"] == 0  # it was reversing away
    (frame, _t, _text) = next(
        e for e in r.events if e[2].startswith("collision with person 'target'")
    )
    t = r.trajectory
    reverse = 150 * math.pi / 180 * TURTLEBOT2.wheel_radius  # m/s
    before = slice(frame - 30, frame)  # the second before the contact
    assert np.all(t["proximity"][before] == 7)
    assert np.allclose(t["cmd_v"][before], -reverse, atol=0.005)
    # The distance shrinks by the person's speed less the robot's.
    closing = -np.diff(t["target_distance"][before]).mean() * 30  # m/s
    assert closing > 0.15


def test_yielding_keeps_the_person_off_the_robot():
    s = load_scenario("follow_person", ["sim.duration=60"])
    assert s.world["people"][0]["yield_gap"] == 0.3
    r = run_scenario(s, backend="model")
    contact = 0.2 + TURTLEBOT2.body_radius
    assert r.summary["collisions"]["person"] == 0
    # They came as close as the gap allows (one frame of walking under it at most).
    assert contact + 0.3 - 0.01 < r.summary["min_distance_m"] < contact + 0.31
