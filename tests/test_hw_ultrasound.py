"""UltrasoundDriver against the Python model (sim/models/ultrasound_driver.py) edge for edge, against
distances computed by hand, and its seeded variants' wrong readings."""

import numpy as np
import pytest
from hwsim import run_testbench

from fpga_robotics.hw.sensor_params import DISTANCE_NONE, UltrasoundParams
from fpga_robotics.hw.ultrasound import UltrasoundDriver
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.sim.models.ultrasound_driver import Measurement, UltrasoundModel, echo_cycles_of
from fpga_robotics.sim.world.ultrasound import HCSR04Module, HCSR04Params

#: A 1 MHz clock and a 2.4 ms period keep pysim fast: T = 12, W = 500, M = 1749 cycles.
SMALL = {"clock_hz": 1_000_000, "period_us": 2400, "wait_us": 500, "max_range_mm": 300}


def run_driver(params, pulses, periods):
    """Clock the driver through ``periods`` periods with ECHO high at edges a..b-1 of each
    pulse ``(a, b)``; returns ``(trig after each edge, [Measurement])``."""
    dut = UltrasoundDriver(params)
    n = periods * params.period_cycles
    level = np.zeros(n + 2, np.int8)
    for a, b in pulses:
        level[a : min(b, n + 2)] = 1
    trig, measured = [], []

    async def bench(ctx):
        for e in range(1, n + 1):
            ctx.set(dut.echo, int(level[e]))
            await ctx.tick()
            trig.append(ctx.get(dut.trig))
            if ctx.get(dut.measured):
                measured.append(
                    Measurement(e, ctx.get(dut.distance_mm), bool(ctx.get(dut.no_echo)))
                )

    run_testbench(dut, bench, watchdog=n + 100)
    return np.array(trig), measured


def edges_of(trig):
    """(rises, falls): the edges after which TRIG went high / low."""
    change = np.diff(np.concatenate([[0], trig]))
    return list(np.flatnonzero(change == 1) + 1), list(np.flatnonzero(change == -1) + 1)


def test_default_constants_by_hand():
    p = UltrasoundParams()
    assert p.clock_hz == 50_000_000
    assert p.trigger_cycles == 600  # 12 us, above the datasheet's 10 us
    assert p.period_cycles == 3_000_000  # 60 ms
    assert p.wait_cycles == 500_000  # 10 ms
    # 4 m there and back at 343 m/s: 8 / 343 s = 23.3236 ms = 1,166,180.76 cycles.
    assert p.max_echo_cycles == 1_166_180
    assert p.full_echo_bits == p.counter_bits == 21  # 2**20 = 1,048,576 < 1,166,180 < 2**21
    # K = 343,000 mm/s / (2 * 50 MHz) * 2**24 = 57,545.85, rounded: 57,546; 2**25 would
    # give 115,092, wider than 16 bits.
    assert (p.distance_shift, p.distance_k) == (24, 57_546)
    # A wall at 1 m: 2 / 343 s = 291,545.19 cycles; 291,545 * 57,546 = 16,777,248,570 and
    # 1000 * 2**24 = 16,777,216,000, less by 32,570 < 2**24: 1000 mm exactly.
    assert echo_cycles_of(1000, 343_000, 50_000_000) == 291_545
    assert p.distance_of(291_545) == 1000
    # The longest echo: 1,166,180 * 57,546 = 67,108,994,280 = 4000 * 2**24 + 130,280.
    assert p.distance_of(1_166_180) == 4000


def test_trigger_timing_after_reset_and_every_period():
    p = UltrasoundParams(**SMALL)
    trig, _ = run_driver(p, [], periods=3)
    rises, falls = edges_of(trig)
    model = UltrasoundModel(p)
    assert list(zip(rises, falls)) == [model.trigger(k) for k in range(3)]
    # By hand: high after edges 1..12, then 2401..2412, 4801..4812 (12 cycles = 12 us).
    assert (rises, falls) == ([1, 2401, 4801], [13, 2413, 4813])
    assert trig.sum() == 3 * 12


def test_one_metre_wall_to_the_millimetre():
    # 1 MHz: 2 / 343 s = 5830.9 cycles -> 5831; K = 0.1715 * 2**18 = 44,957.7 -> 44,958;
    # 5831 * 44,958 = 262,150,098 = 1000 * 2**18 + 6,098: 1000 mm.
    p = UltrasoundParams(clock_hz=1_000_000, period_us=7600, wait_us=500, max_range_mm=1200)
    assert (p.distance_shift, p.distance_k) == (18, 44_958)
    width = echo_cycles_of(1000, 343_000, 1_000_000)
    assert width == 5831
    start = 13 + 150  # 150 us after TRIG falls
    _, measured = run_driver(p, [(start, start + width)], periods=1)
    # Shown two synchroniser flops and one register after ECHO's fall.
    assert measured == [Measurement(start + width + 2, 1000, False)]


def test_boundaries_and_random_echoes_match_the_model():
    p = UltrasoundParams(**SMALL)
    P, T, W, M = p.period_cycles, p.trigger_cycles, p.wait_cycles, p.max_echo_cycles
    fall = [k * P + T + 1 for k in range(12)]
    pulses = [
        (fall[0] - 1, fall[0] + 40),  # seen at E0 + 1: the first edge that counts
        (fall[1] + W - 2, fall[1] + W - 2 + M),  # seen at E0 + W, the longest echo measured
        (fall[2] + 5, fall[2] + 5 + M + 1),  # one cycle too long: no echo
        (fall[3] + W - 1, fall[3] + W + 10),  # starts one edge too late: no echo
        # period 4: nothing at all
        (fall[5] - 30, fall[5] + 100),  # high before TRIG falls: no rising edge, no echo
        (fall[6] + 10, fall[6] + 11),  # one cycle
        (fall[6] + 20, fall[6] + 300),  # a second pulse in the same period is ignored
    ]
    rng = np.random.default_rng(21)
    for k in range(7, 12):
        start = fall[k] + int(rng.integers(0, W))
        pulses.append((start, start + int(rng.integers(1, M + 1))))
    trig, measured = run_driver(p, pulses, periods=12)
    model = UltrasoundModel(p)
    assert measured == model.measurements(12, pulses)
    # ECHO never disturbs TRIG.
    assert list(zip(*edges_of(trig))) == [model.trigger(k) for k in range(12)]
    # The hand-known ones.
    assert measured[0] == Measurement(fall[0] + 42, (41 * p.distance_k) >> 18, False)
    assert measured[1].distance_mm == p.distance_of(M) == 299  # 300 mm, floored
    assert measured[2] == Measurement(fall[2] + 5 + M + 2, DISTANCE_NONE, True)
    assert measured[3] == Measurement(fall[3] + W, DISTANCE_NONE, True)
    assert measured[4] == Measurement(fall[4] + W, DISTANCE_NONE, True)
    assert measured[5].no_echo
    assert measured[6] == Measurement(fall[6] + 13, 0, False)  # 1 cycle = 0.17 mm


def test_outputs_hold_between_measurements_and_start_at_zero():
    p = UltrasoundParams(**SMALL)
    dut = UltrasoundDriver(p)
    seen = []

    async def bench(ctx):
        assert (ctx.get(dut.distance_mm), ctx.get(dut.no_echo), ctx.get(dut.measured)) == (0, 0, 0)
        for e in range(1, 2 * p.period_cycles + 1):
            ctx.set(dut.echo, int(100 <= e < 700))
            await ctx.tick()
            seen.append((ctx.get(dut.distance_mm), ctx.get(dut.no_echo), ctx.get(dut.measured)))

    run_testbench(dut, bench, watchdog=2 * p.period_cycles + 50)
    distance = p.distance_of(600)
    assert distance == 102  # 600 * 0.1715 = 102.9
    strobes = [e + 1 for e, s in enumerate(seen) if s[2]]
    assert strobes == [702, p.period_cycles + 13 + 500]
    assert all(s[:2] == (0, 0) for s in seen[:701])
    assert all(s[:2] == (102, 0) for s in seen[701 : strobes[1] - 1])
    assert seen[-1][:2] == (DISTANCE_NONE, 1)


def test_narrow_counter_variant_wraps_to_a_false_near_reading():
    p = variant_params("us_echo_counter_narrow", UltrasoundParams(**SMALL))
    assert p.counter_bits == 10 and p.full_echo_bits == 11  # M = 1749 needs 11 bits
    fall = [k * p.period_cycles + 13 for k in range(3)]
    # 1100 cycles (a surface 188.6 mm away... as read by the correct design: 188 mm) wraps
    # to 76 cycles: 13 mm; 2000 cycles (beyond the range: no echo) reads 976 cycles, 167 mm.
    pulses = [
        (fall[0] + 50, fall[0] + 50 + 1100),
        (fall[1] + 50, fall[1] + 50 + 2000),
        (fall[2] + 50, fall[2] + 50 + 300),
    ]
    _, measured = run_driver(p, pulses, periods=3)
    assert [(m.distance_mm, m.no_echo) for m in measured] == [
        ((76 * 44_958) >> 18, False),
        ((976 * 44_958) >> 18, False),
        (51, False),
    ]
    assert [m.distance_mm for m in measured[:2]] == [13, 167]
    assert measured == UltrasoundModel(p).measurements(3, pulses)
    correct = UltrasoundModel(UltrasoundParams(**SMALL)).measurements(3, pulses)
    assert [(m.distance_mm, m.no_echo) for m in correct] == [
        (188, False),
        (DISTANCE_NONE, True),
        (51, False),
    ]


def test_narrow_counter_at_50_mhz_by_hand():
    p = variant_params("us_echo_counter_narrow")
    assert p.counter_bits == 20
    # A wall at 3.7 m: 1,078,717 cycles, minus 2**20 = 30,141 -> 30,141 * 57,546 >> 24 = 103.
    cycles = echo_cycles_of(3700, 343_000, 50_000_000)
    assert cycles == 1_078_717
    assert p.distance_of(cycles) == 103
    # The 38 ms time-out pulse: 1,900,000 - 2**20 = 851,424 cycles -> 2920 mm, not no echo.
    assert p.distance_of(1_900_000) == 2920


def test_narrow_counter_in_the_world_at_20_c():
    # The world's HC-SR04 sends sound at 331.3 + 0.606 * 20 = 343.42 m/s (docs/sensor_designs.md
    # quotes the narrow counter's band at that speed): the count wraps from 3.601 m on, a wall
    # at 3.7 m reads 98 mm, and readings stay below stop_mm = 300 up to 3.90 m.
    p = variant_params("us_echo_counter_narrow")
    world = HCSR04Module(HCSR04Params(noise_std=0.0))
    clock = p.clock_hz

    def reads(d):
        return p.distance_of(world.echo_width(d, clock))

    c = 331.3 + 0.606 * 20
    assert 2**20 / clock * c / 2 == pytest.approx(3.601, abs=5e-4)
    assert reads(3.6) > 3500 and reads(3.602) < 5
    assert reads(3.7) == 98
    assert reads(3.9) < 300 <= reads(3.905)
    assert reads(1.0) == 998  # 0.12 % short of the design's 343 m/s


def test_inverted_echo_variant_never_measures():
    p = variant_params("us_echo_inverted", UltrasoundParams(**SMALL))
    fall = [k * p.period_cycles + 13 for k in range(3)]
    pulses = [(fall[k] + 50, fall[k] + 50 + w) for k, w in enumerate((300, 600, 100))]
    _, measured = run_driver(p, pulses, periods=3)
    assert measured == UltrasoundModel(p).measurements(3, pulses)
    # An echo that ends within the wait starts the count of the low gap after it, which
    # outlasts M: no echo, M + 2 edges after the echo's fall is seen. One that ends later
    # (50 + 600 > W = 500) leaves no rising edge in the wait: no echo at its end.
    M, W = p.max_echo_cycles, p.wait_cycles
    assert measured == [
        Measurement(fall[0] + 50 + 300 + M + 2, DISTANCE_NONE, True),
        Measurement(fall[1] + W, DISTANCE_NONE, True),
        Measurement(fall[2] + 50 + 100 + M + 2, DISTANCE_NONE, True),
    ]
    correct = UltrasoundModel(UltrasoundParams(**SMALL)).measurements(3, pulses)
    assert [m.distance_mm for m in correct] == [51, 102, 17]


@pytest.mark.parametrize(
    "changes,message",
    [
        ({"trigger_us": 9}, "trigger_us must be >= 10"),
        ({"period_us": 20_000}, "period_us=20000 is too short"),
        ({"max_range_mm": 0}, "max_range_mm must be >= 1"),
        ({"clock_hz": 50e6}, "clock_hz must be an int"),
        ({"echo_active_high": 1}, "echo_active_high must be True or False"),
        ({"clock_hz": 100_000, "wait_us": 10}, "too slow"),
    ],
)
def test_bad_parameters_are_refused(changes, message):
    with pytest.raises((TypeError, ValueError), match=message):
        UltrasoundParams(**changes)


def test_driver_refuses_other_params():
    with pytest.raises(TypeError, match="UltrasoundParams"):
        UltrasoundDriver({"clock_hz": 1})
