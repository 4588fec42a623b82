"""Real-clock timing end to end: the design's cycles at world time, connectors acting at the
edges where pins change, against physics computed by hand."""

import math

import numpy as np
import pytest

from fpga_robotics.checks.summary import TIMING_FIELDS
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sim.models.ultrasound_driver import UltrasoundModel
from fpga_robotics.sim.world.ultrasound import speed_of_sound

CLOCK = 50e6


def _wall_scenario(distance, temperature=20.0):
    """follow_target_safe facing the wall x = 4 m, its ultrasound ``distance`` m from it
    (mounted 0.1 m ahead of the robot's centre), nobody in the room, no sensor noise."""
    x = 4.0 - distance - 0.1
    return load_scenario(
        "obstacle_between",
        [
            "sim.duration=0.1",
            "people=[]",
            "room.furniture=[]",
            "room.width=4.0",
            f"robot.start=[{x}, 2.0]",
            "robot.sensors.0.noise_std=0.0",
            f"robot.sensors.0.temperature_c={temperature}",
            "checks={}",
        ],
    )


@pytest.mark.parametrize("distance, temperature", [(1.0, 20.0), (0.5, 0.0), (2.2, 35.0)])
def test_echo_width_for_a_wall_is_2d_over_c_to_the_cycle(distance, temperature):
    s = _wall_scenario(distance, temperature)
    r = run_scenario(s, backend="cxxrtl")
    c = speed_of_sound(temperature)
    assert c == pytest.approx(331.3 + 0.606 * temperature)
    width = round(2 * distance / c * CLOCK)
    t = r.trajectory
    assert t["front.echo_edges"][-1] == width
    assert t["front.range_m"][-1] == pytest.approx(distance, abs=1e-9)
    # The design converts the width it counted at its own speed of sound (343 m/s).
    params = s.design_tables["ultrasound"]
    assert t["design.distance_mm"][-1] == UltrasoundModel(params).distance(width)
    assert abs(t["design.distance_mm"][-1] - distance * 1000 * 343.0 / c) <= 1


def test_nothing_in_range_gives_the_time_out_pulse_and_no_distance():
    s = _wall_scenario(0.3).with_overrides(
        ["room.width=9.0", "robot.start=[1.0, 2.0]", "sim.duration=0.2"]
    )
    r = run_scenario(s, backend="cxxrtl")
    t = r.trajectory
    assert t["front.timeout"][-1] == 1
    assert t["front.echo_edges"][-1] == round(0.038 * CLOCK)
    from fpga_robotics.hw.sensor_params import DISTANCE_NONE

    assert t["design.distance_mm"][-1] == DISTANCE_NONE


def test_the_interlock_stops_the_robot_at_its_threshold_and_releases_it():
    s = load_scenario(
        "obstacle_between",
        ["robot.start=[1.7, 2.0]", "sim.duration=9", "room.furniture.0.present_until=6.0"],
    )
    r = run_scenario(s, backend="cxxrtl")
    t, stop_mm = r.trajectory, s.design_tables["interlock"].stop_mm
    stopped = np.flatnonzero(t["design.obstacle"] > 0)
    assert len(stopped), "the interlock never engaged"
    k = stopped[0]
    # The first measurement under the threshold: at most one period of travel below it.
    v = max(t["v"][:k])
    period = s.design_tables["ultrasound"].period_us * 1e-6
    assert stop_mm - 1000 * v * period - 5 <= t["design.distance_mm"][k] < stop_mm
    # The wheels were commanded to 0 and the robot stopped short of the box, untouched.
    before = t["t"] < 6.0
    hold = np.flatnonzero(before & (t["t"] > t["t"][k] + 0.5))
    assert np.all(t["motor_left"][hold] == 0) and np.all(t["motor_right"][hold] == 0)
    assert np.all(np.abs(t["v"][hold]) < 0.005)
    spec_accel = 1500.0 / 360 * math.pi * 0.0665  # GoPiGo3's wheel ramp, m/s^2
    braking = v * v / (2 * spec_accel)
    assert (
        stop_mm / 1000 - v * period - braking - 0.02 <= t["front.range_m"][hold[0]] < stop_mm / 1000
    )
    assert r.summary["collisions"].get("furniture", 0) == 0
    # Removed at 6 s: the next measurement sees the person beyond and releases the wheels.
    released = [e for e in r.events if e[2].startswith("interlock: clear")]
    assert released and 6.0 <= released[0][1] <= 6.0 + period + 0.05
    assert r.summary["resumed_after_s"] is not None


def test_modes_agree_while_the_robot_has_not_moved():
    s = load_scenario("follow_person", ["sim.duration=0.1"])
    a = run_scenario(s, backend="model")
    b = run_scenario(s.with_overrides(["sim.timing=real_clock"]), backend="cxxrtl")
    assert a.summary["timing"] == "compressed" and b.summary["timing"] == "real_clock"
    for name in (
        "found",
        "proximity",
        "centroid_x",
        "centroid_leds",
        "motor_left",
        "motor_right",
        "x",
        "y",
    ):
        assert np.array_equal(a.trajectory[name][:2], b.trajectory[name][:2]), name
    assert b.summary["sim_cycles"] == round(0.1 * CLOCK)


@pytest.mark.slow
def test_real_clock_backends_agree_bit_for_bit():
    s = load_scenario("line_track", ["sim.duration=1.0", "sim.clock_hz=100000"])
    runs = [run_scenario(s, backend=name) for name in ("pysim", "cxxrtl", "verilator")]
    for r in runs[1:]:
        for name, column in runs[0].trajectory.items():
            assert np.array_equal(column, r.trajectory[name], equal_nan=True), name
        untimed = {k: v for k, v in r.summary.items() if k not in TIMING_FIELDS + ("backend",)}
        assert untimed == {
            k: v for k, v in runs[0].summary.items() if k not in TIMING_FIELDS + ("backend",)
        }


def test_a_buggy_variant_fails_its_named_check():
    s = load_scenario(
        "line_track",
        [
            "sim.duration=8",
            "design.variant=line_inverted_polarity",
            "checks={max_off_line_s = 1.0}",
        ],
    )
    r = run_scenario(s, backend="cxxrtl")
    assert [c["name"] for c in r.summary["checks"] if c["passed"] is False] == ["max_off_line_s"]
    good = load_scenario("line_track", ["sim.duration=8", "checks={max_off_line_s = 1.0}"])
    assert run_scenario(good, backend="cxxrtl").passed


def test_the_ultrasound_variant_drives_into_the_box():
    s = load_scenario(
        "obstacle_between",
        [
            "robot.start=[1.7, 2.0]",
            "sim.duration=6",
            "design.variant=us_echo_inverted",
            "checks={max_furniture_collisions = 0}",
        ],
    )
    r = run_scenario(s, backend="cxxrtl")
    assert [c["name"] for c in r.summary["checks"] if c["passed"] is False] == [
        "max_furniture_collisions"
    ]


@pytest.mark.parametrize(
    "overrides, message",
    [
        (
            ["robot.sensors=[]"],
            (
                "nothing drives its input 'line'; declare a [[robot.sensors]] "
                'table with kind = "line_sensors"'
            ),
        ),
        (["design.line.n_sensors=2"], "the line_sensors table must list as many sensors"),
        # Two sensors on the three-bit input: the third bit was left undriven, silently.
        (
            ["robot.sensors[0].sensors=[{forward=0.0,left=0.018},{forward=0.0,left=-0.018}]"],
            "pin 'line' is in 2 bit.s. but port 'line' of design 'follow_line' is in 3 bit",
        ),
    ],
)
def test_binding_errors_say_what_to_declare(overrides, message):
    s = load_scenario("line_track", overrides)
    with pytest.raises(UsageError, match=message.replace("[", r"\[").replace("]", r"\]")):
        run_scenario(s, backend="cxxrtl")


def test_compressed_timing_refuses_a_design_with_pins():
    with pytest.raises(ScenarioError, match='needs sim.timing = "real_clock"'):
        load_scenario("line_track", ["sim.timing=compressed"])


def test_the_model_backend_cannot_run_real_clock():
    with pytest.raises(UsageError, match="needs a backend that simulates every clock"):
        run_scenario(load_scenario("line_track", ["sim.duration=0.1"]), backend="model")


def test_a_pin_design_is_generated_once_per_process(monkeypatch):
    import collections

    from fpga_robotics.loop.real_clock import pin_design_source
    from fpga_robotics.sim.pins import design

    monkeypatch.setattr(design, "_KEPT", collections.OrderedDict())
    generated = []
    generate = design.generate_cxxrtl
    monkeypatch.setattr(design, "generate_cxxrtl", lambda c: generated.append(c) or generate(c))
    first = pin_design_source(load_scenario("obstacle_between", ["design.diff_min=7"]))
    # Another run of the same design (its world changed) reuses the generated text.
    again = load_scenario("obstacle_between", ["design.diff_min=7", "robot.start=[1.0, 2.0]"])
    assert pin_design_source(again).cxxrtl == first.cxxrtl
    assert len(generated) == 1
    # Other parameters are another design.
    other = pin_design_source(load_scenario("obstacle_between", ["design.diff_min=8"]))
    assert other.cxxrtl != first.cxxrtl
    assert len(generated) == 2
