"""FollowLine against the Python model (sim/models/follow_line.py) cycle for cycle, the control
law's table by hand, its timing, the GoPiGo3's turn radii, and the inverted-polarity
variant's wrong commands."""

import math

import numpy as np
import pytest
from hwsim import WithReset, run_testbench

from fpga_robotics.hw.follow_line import FollowLine
from fpga_robotics.hw.sensor_params import FollowLineParams
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.sim.models.follow_line import FollowLineModel, action, wheel_command
from fpga_robotics.sim.world.robots import GOPIGO3


def run_line(params, lines, *, reset_at=None):
    """Drive ``lines[i]`` for edge i + 1; returns ``[(line_seen, left, right)]`` after each
    edge (with a reset pulse sampled at edge ``reset_at + 1``)."""
    dut = FollowLine(params)
    top = WithReset(dut)
    out = []

    async def bench(ctx):
        assert (ctx.get(dut.motor_left), ctx.get(dut.motor_right), ctx.get(dut.line_seen)) == (
            0,
            0,
            0,
        )
        for i, value in enumerate(lines):
            ctx.set(dut.line, value)
            ctx.set(top.rst, int(i == reset_at))
            await ctx.tick()
            out.append((ctx.get(dut.line_seen), ctx.get(dut.motor_left), ctx.get(dut.motor_right)))

    run_testbench(top, bench, watchdog=len(lines) + 50)
    return out


def model_run(params, lines, *, reset_at=None):
    model = FollowLineModel(params)
    out = []
    for i, value in enumerate(lines):
        if i == reset_at:
            model.reset()
            out.append((0, 0, 0))
            continue
        o = model.step(value)
        out.append((o.line_seen, o.motor_left, o.motor_right))
    return out


def random_lines(n, rng, length):
    """Values held for 1..6 edges (so that single-cycle glitches occur too)."""
    lines = []
    while len(lines) < length:
        lines += [int(rng.integers(0, 1 << n))] * int(rng.integers(1, 7))
    return lines[:length]


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"n_sensors": 2},
        {"n_sensors": 1},
        {"n_sensors": 1, "edge_side": "right", "gentle_turn_dps": 40},
        {"active_high": False},
        {"base_dps": -100, "search_dps": -20, "sharp_turn_dps": 32667, "gentle_turn_dps": 0},
    ],
)
def test_random_line_sequences_match_the_model(changes):
    p = FollowLineParams(**changes)
    rng = np.random.default_rng(len(str(changes)))
    lines = random_lines(p.n_sensors, rng, 300)
    assert run_line(p, lines, reset_at=150) == model_run(p, lines, reset_at=150)


def test_three_sensor_law_by_hand():
    # Defaults: base 250, gentle 100, sharp 250, search 150. Bits: sensor 0 (left) is bit 0.
    p = FollowLineParams()
    expected = {
        0b010: (250, 250),
        0b111: (250, 250),
        0b101: (250, 250),
        0b001: (0, 500),
        0b011: (150, 350),  # left only: sharp left; left + centre: gentle
        0b100: (500, 0),
        0b110: (350, 150),
    }
    for bits, command in expected.items():
        lines = [bits] * 4
        assert run_line(p, lines)[-1] == (bits, *command), bin(bits)
    # Lost after the line was last seen on the right: search right, turning in place.
    assert run_line(p, [0b100] * 4 + [0b000] * 4)[-1] == (0, 150, -150)
    # ... after it was seen on the left: search left, even via the centre.
    assert run_line(p, [0b001] * 4 + [0b010] * 4 + [0] * 4)[-1] == (0, -150, 150)


def test_timing_after_reset_and_latency():
    p = FollowLineParams()
    out = run_line(p, [0b010] * 3 + [0b011] * 4)
    # Edge 1: line_seen is still 0 (two flops), so the first command is the search left.
    assert out[0] == (0, -150, 150)
    assert out[1] == (0b010, -150, 150)  # line_seen after edge 2
    assert out[2] == (0b010, 250, 250)  # command after edge 3
    # 0b011 sampled at edge 4: line_seen after edge 5, the gentle left after edge 6.
    assert out[3] == (0b010, 250, 250)
    assert out[4] == (0b011, 250, 250)
    assert out[5] == (0b011, 150, 350)


def test_two_and_one_sensor_laws_by_hand():
    two = FollowLineParams(n_sensors=2)
    assert [run_line(two, [b] * 3)[-1][1:] for b in range(4)] == [
        (250, 250),
        (0, 500),
        (500, 0),
        (250, 250),
    ]
    one = FollowLineParams(n_sensors=1)  # on the line's left edge: the line lies to the right
    assert run_line(one, [1] * 3)[-1][1:] == (150, 350)  # over the line: back to the left
    assert run_line(one, [0] * 3)[-1][1:] == (350, 150)  # off it: towards it, right


def test_turns_are_tighter_than_the_track_on_a_gopigo3():
    p = FollowLineParams()
    half_base = GOPIGO3.wheel_separation / 2
    for name in ("gentle_left", "sharp_left"):
        left, right = wheel_command(p, name)
        radius = half_base * (right + left) / (right - left)
        assert radius < 0.3, name
        assert max(abs(left), abs(right)) <= GOPIGO3.max_wheel_dps
    speed = p.base_dps * math.pi / 180 * GOPIGO3.wheel_radius
    assert speed == pytest.approx(0.145, abs=0.001)  # m/s


def test_inverted_polarity_variant_steers_the_wrong_way():
    p = variant_params("line_inverted_polarity")
    assert p == FollowLineParams.inverted_polarity() and not p.active_high
    # Line under the left and centre sensors: the design sees the right sensor only and
    # turns sharp right instead of gently left; on no line at all it drives straight on.
    assert run_line(p, [0b011] * 3)[-1] == (0b100, 500, 0)
    assert run_line(FollowLineParams(), [0b011] * 3)[-1] == (0b011, 150, 350)
    assert run_line(p, [0b000] * 3)[-1] == (0b111, 250, 250)
    assert action(p, (1, 1, 1), "left") == ("straight", "left")


def test_bad_parameters_are_refused():
    for changes, message in (
        ({"n_sensors": 4}, "n_sensors must be <= 3"),
        ({"edge_side": "middle"}, "edge_side must be one of"),
        ({"active_high": "yes"}, "active_high must be True or False"),
        ({"base_dps": 30000, "sharp_turn_dps": 5000}, "does not fit"),
    ):
        with pytest.raises((TypeError, ValueError), match=message):
            FollowLineParams(**changes)
    with pytest.raises(ValueError, match="known presets: default, inverted_polarity"):
        FollowLineParams.preset("upside_down")
    with pytest.raises(TypeError, match="FollowLineParams"):
        FollowLine(3)
