"""HC-SR04 physics (sim/world/ultrasound.py) against distances and echo widths computed by hand:
the cone, the beam's height, the range limits, the module's timing (time-out, short and busy
triggers) and the speed of sound's temperature."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.ultrasound import HCSR04Module, HCSR04Params, range_to, speed_of_sound

F = 50e6  # the design's clock
QUIET = HCSR04Params(noise_std=0.0)


def _world(width=4.0, furniture=(), people=()):
    return World.from_config(
        {
            "room": {"width": width, "depth": 6.0, "furniture": list(furniture)},
            "robot": {"start": [1.0, 3.0]},
            "people": list(people),
        }
    )


def test_speed_of_sound_is_the_linear_fit():
    assert speed_of_sound(20.0) == pytest.approx(343.42)
    assert speed_of_sound(0.0) == pytest.approx(331.3)


def test_a_wall_straight_ahead_is_at_its_perpendicular_distance():
    world = _world()
    assert range_to(world, 1.1, 3.0, 0.0, 0.1, QUIET) == pytest.approx(2.9, abs=1e-12)
    # Turned by 5 degrees (inside the 7.5 degree half cone) the perpendicular is still in the
    # beam: the range is the same.
    assert range_to(world, 1.1, 3.0, math.radians(5), 0.1, QUIET) == pytest.approx(2.9, abs=1e-12)
    # Turned by 20 degrees the nearest wall point in the beam is on the cone's edge.
    d = range_to(world, 1.1, 3.0, math.radians(20), 0.1, QUIET)
    assert d == pytest.approx(2.9 / math.cos(math.radians(12.5)), abs=1e-12)


@pytest.mark.parametrize("margin_deg, seen", [(-0.3, True), (0.3, False)])
def test_a_person_at_the_cone_edge(margin_deg, seen):
    # The person's circle touches bearing 7.5 - margin degrees: inside the cone or just out.
    r, dist = 0.2, 1.5
    bearing = math.radians(7.5 + margin_deg) + math.asin(r / dist)
    px, py = 1.0 + dist * math.cos(bearing), 3.0 + dist * math.sin(bearing)
    world = _world(people=[{"waypoints": [[px, py]], "radius": r}])
    d = range_to(world, 1.0, 3.0, 0.0, 0.1, QUIET)
    if seen:
        assert dist - r < d < dist
    else:
        assert d == pytest.approx(3.0, abs=1e-12)  # the wall behind


def test_a_low_box_counts_only_where_the_beam_comes_down_to_it():
    # Sensor at 0.2 m; a box from x = 2.0 to 3.0 m. A tall one is met at its face; a 0.05 m
    # high one where the beam's lower edge comes down to 0.05 m: r = 0.15 / tan(7.5 deg).
    tall = {"name": "tall", "center": [2.5, 3.0], "size": [1.0, 0.6], "height": 0.75}
    assert range_to(_world(furniture=[tall]), 1.0, 3.0, 0.0, 0.2, QUIET) == pytest.approx(1.0)
    box = dict(tall, name="low", height=0.05)
    world = _world(furniture=[box])
    reach = 0.15 / math.tan(math.radians(7.5))
    assert range_to(world, 1.0, 3.0, 0.0, 0.2, QUIET) == pytest.approx(reach, abs=1e-9)
    assert range_to(world, 1.5, 3.0, 0.0, 0.2, QUIET) == pytest.approx(reach, abs=1e-9)
    # A sensor above the box, 0.8 m from its far end: the beam does not come down to the
    # box before it ends (0.8 < 1.139 m), so the wall is what answers.
    assert range_to(world, 2.2, 3.0, 0.0, 0.2, QUIET) == pytest.approx(1.8, abs=1e-12)
    # A box shorter than the beam for its whole length is never seen: the wall behind it.
    short = dict(box, size=[0.2, 0.6], center=[1.8, 3.0])
    world = _world(furniture=[short])
    assert range_to(world, 1.5, 3.0, 0.0, 0.2, QUIET) == pytest.approx(2.5)


def test_the_range_limits():
    # 5.9 m to the wall of an 8 m room: beyond 4 m, nothing in range.
    assert range_to(_world(width=8.0), 2.1, 3.0, 0.0, 0.1, QUIET) is None
    # 1 cm from a wall: nearer than 2 cm.
    assert range_to(_world(), 3.99, 3.0, 0.0, 0.1, QUIET) is None
    assert range_to(_world(), 3.97, 3.0, 0.0, 0.1, QUIET) == pytest.approx(0.03)


def test_echo_width_is_the_round_trip_in_edges():
    module = HCSR04Module(QUIET)
    d = 2.9
    echo = module.on_trigger(1000, 1500, d, F)
    delay = round(QUIET.echo_delay_s * F)
    assert echo == (1500 + delay, 1500 + delay + round(2 * d / 343.42 * F))


def test_nothing_in_range_gives_the_time_out_pulse():
    module = HCSR04Module(QUIET)
    rise, fall = module.on_trigger(0, 500, None, F)
    assert fall - rise == round(0.038 * F) == 1_900_000


def test_a_short_trigger_and_one_during_a_measurement_are_ignored():
    module = HCSR04Module(QUIET)
    assert module.on_trigger(0, 499, 1.0, F) is None  # 9.98 us
    rise, fall = module.on_trigger(0, 500, 1.0, F)  # 10 us
    assert module.on_trigger(rise + 10, rise + 600, 1.0, F) is None  # during the echo
    assert module.on_trigger(fall - 600, fall - 1, 1.0, F) is None  # still busy
    again = module.on_trigger(fall, fall + 500, 1.0, F)  # free again
    assert again is not None and again[1] - again[0] == fall - rise


def test_temperature_changes_the_width_as_the_formula_says():
    d = 1.234
    widths = {}
    for t in (-10.0, 0.0, 40.0):
        params = HCSR04Params(noise_std=0.0, temperature_c=t)
        rise, fall = HCSR04Module(params).on_trigger(0, 500, d, F)
        widths[t] = fall - rise
        assert widths[t] == round(2 * d / (331.3 + 0.606 * t) * F)
    assert widths[-10.0] > widths[0.0] > widths[40.0]


def test_noise_is_seeded_and_of_the_given_spread():
    params = HCSR04Params(noise_std=0.01)

    def widths(seed):
        module = HCSR04Module(params, np.random.default_rng(seed))
        return np.array([module.echo_width(1.0, F) for _ in range(2000)])

    a, b = widths(3), widths(3)
    np.testing.assert_array_equal(a, b)
    metres = a / F * params.speed_of_sound / 2
    assert abs(metres.mean() - 1.0) < 4 * 0.01 / math.sqrt(len(a))
    assert metres.std() == pytest.approx(0.01, rel=0.1)


@pytest.mark.parametrize("margin_deg, seen", [(-0.2, True), (0.2, False)])
def test_a_box_corner_at_the_cone_edge(margin_deg, seen):
    # A tall box whose nearest corner is 1 m away at bearing b = 7.5 + margin degrees, turned
    # by b so that one edge runs radially out from the corner and the box lies at bearings
    # >= b: inside the cone's edge the corner is seen, outside nothing of the box is.
    b = math.radians(7.5 + margin_deg)
    cx, cy = 1.0 + math.cos(b), 3.0 + math.sin(b)
    centre = [cx + 0.25 * (math.cos(b) - math.sin(b)), cy + 0.25 * (math.sin(b) + math.cos(b))]
    box = {
        "name": "box",
        "center": centre,
        "size": [0.5, 0.5],
        "height": 1.0,
        "angle_deg": math.degrees(b),
    }
    d = range_to(_world(furniture=[box]), 1.0, 3.0, 0.0, 0.1, QUIET)
    if seen:
        assert d == pytest.approx(1.0, abs=1e-12)  # the corner itself
    else:
        assert d == pytest.approx(3.0, abs=1e-12)
