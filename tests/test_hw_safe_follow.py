"""FollowTargetSafe: follow_target's outputs unchanged (against the golden model), the
ultrasound driver inside it (against its model) and the interlock's hysteresis and timing
(against InterlockModel), with hand-built echoes."""

import numpy as np
import pytest
from amaranth.sim import Simulator
from hwsim import PERIOD, WatchdogTimeout, frame_schedule, small_params

from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.hw.safe_follow import FollowTargetSafe
from fpga_robotics.hw.sensor_params import DISTANCE_NONE, InterlockParams, UltrasoundParams
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.models.follow_target import FollowTargetModel
from fpga_robotics.sim.models.ultrasound_driver import InterlockModel, Measurement, UltrasoundModel

US = UltrasoundParams(clock_hz=1_000_000, period_us=2400, wait_us=500, max_range_mm=300)
LOCK = InterlockParams(stop_mm=120, resume_mm=200)
#: 0.1715 mm per cycle: echo widths (cycles) for the distances the interlock must tell apart.
MM = {"far": 1500, "stop": 600, "between": 900, "resume": 1166, "at_stop": 700}


def red_frame(p, cx, seed=0):
    rgb = synthetic.blob_frame(
        p.width,
        p.height,
        "red",
        cx=cx,
        cy=p.height / 2,
        radius=p.height / 3,
        rng=np.random.default_rng(seed),
    )
    return to_rgb444(rgb, p.width, p.height)


def run_safe(dut, frames, pulses, edges):
    """Stream ``frames`` (red selected) from edge 1, ECHO high at edges a..b-1 of each pulse;
    returns a dict of traces (entry j: right after edge j + 1)."""
    schedule = []
    for frame in frames:
        schedule += frame_schedule(frame, line_blank=2)
    level = np.zeros(edges + 2, np.int8)
    for a, b in pulses:
        level[a:b] = 1
    names = (
        "frame_done",
        "found",
        "proximity",
        "centroid_x",
        "centroid_leds",
        "motor_left",
        "motor_right",
        "obstacle",
        "distance_mm",
        "us_trig",
    )
    trace = {name: [] for name in names + ("ft_left", "ft_right", "measured", "no_echo")}
    probes = {name: getattr(dut, name) for name in names}
    probes.update(
        ft_left=dut.follow_target.motor_left,
        ft_right=dut.follow_target.motor_right,
        measured=dut.ultrasound.measured,
        no_echo=dut.ultrasound.no_echo,
    )

    async def bench(ctx):
        ctx.set(dut.color_sel, COLOR_SELECT["red"])
        for e in range(1, edges + 1):
            entry = schedule[e - 1] if e - 1 < len(schedule) else None
            ctx.set(dut.pixels.valid, entry is not None)
            if entry is not None:
                ctx.set(dut.pixels.payload.as_value(), entry)
            ctx.set(dut.us_echo, int(level[e]))
            await ctx.tick()
            for name, value in probes.items():
                trace[name].append(ctx.get(value))

    async def watchdog(ctx):
        await ctx.delay((edges + 100) * PERIOD)
        raise WatchdogTimeout("FollowTargetSafe simulation hung")

    sim = Simulator(dut)
    sim.add_clock(PERIOD)
    sim.add_testbench(bench)
    sim.add_testbench(watchdog, background=True)
    sim.run()
    return {name: np.array(values) for name, values in trace.items()}


def measurements_of(trace):
    return [
        Measurement(j + 1, int(trace["distance_mm"][j]), bool(trace["no_echo"][j]))
        for j in np.flatnonzero(trace["measured"])
    ]


def test_follow_target_outputs_are_unchanged_without_an_obstacle():
    p = small_params()
    frames = [red_frame(p, cx) for cx in (10, 24, 40)]
    dut = FollowTargetSafe(p, US, LOCK)
    trace = run_safe(dut, frames, [], edges=2 * US.period_cycles)
    model = FollowTargetModel(p)
    expected = [model.process(f, COLOR_SELECT["red"]) for f in frames]
    done = np.flatnonzero(trace["frame_done"])
    assert len(done) == 3
    for j, e in zip(done, expected):
        t = e.tracker
        assert (
            trace["found"][j],
            trace["proximity"][j],
            trace["centroid_x"][j],
            trace["centroid_leds"][j],
        ) == (t.found, t.proximity, t.centroid_x, t.centroid_leds)
        assert (trace["motor_left"][j + 1], trace["motor_right"][j + 1]) == (
            e.motor_left,
            e.motor_right,
        )
    # No echo at all: every measurement is "no echo", and the interlock never engages.
    assert not trace["obstacle"].any()
    assert measurements_of(trace) == UltrasoundModel(US).measurements(2, [])


def test_interlock_stops_and_releases_with_hysteresis():
    p = small_params()
    frame = red_frame(p, 30)
    periods = 9
    fall = [k * US.period_cycles + US.trigger_cycles + 1 for k in range(periods)]
    # Echo widths per period from period 1 on (period 0 streams the frame, no echo).
    widths = [
        MM["far"],
        MM["stop"],
        MM["between"],
        MM["resume"],
        MM["stop"],
        None,
        MM["at_stop"],
        MM["stop"],
    ]
    pulses = [(fall[k] + 40, fall[k] + 40 + w) for k, w in enumerate(widths, 1) if w]
    dut = FollowTargetSafe(p, US, LOCK)
    trace = run_safe(dut, [frame], pulses, edges=periods * US.period_cycles)

    measured = measurements_of(trace)
    assert measured == UltrasoundModel(US).measurements(periods, pulses)
    # By hand (K = 44,958, S = 18): 1500 -> 257 mm, 600 -> 102, 900 -> 154, 1166 -> 199,
    # 700 -> 120; period 6 has no echo.
    assert [m.distance_mm for m in measured] == [
        DISTANCE_NONE,
        257,
        102,
        154,
        199,
        102,
        DISTANCE_NONE,
        120,
        102,
    ]
    lock = InterlockModel(LOCK)
    states = [lock.step(m) for m in measured]
    # stop (102 < 120), hold at 154 and 199 (< 200), released by no echo, 120 is not < 120.
    assert states == [False, False, True, True, True, True, False, False, True]

    obstacle = trace["obstacle"].astype(bool)
    for m, state in zip(measured, states):
        # The interlock's decision shows one edge after the measurement's strobe.
        assert obstacle[m.edge] == state  # trace index m.edge: right after edge m.edge + 1
        assert obstacle[m.edge - 1] == (obstacle[m.edge - 2] if m.edge >= 2 else False)
    changes = np.flatnonzero(np.diff(obstacle.astype(int))) + 2  # edges after which it changed
    assert list(changes) == [measured[2].edge + 1, measured[6].edge + 1, measured[8].edge + 1]

    # Wheels: 0 exactly while the interlock holds, otherwise FollowTarget's own command
    # (here the frame's tracking command, held).
    held = FollowTargetModel(p).process(frame, COLOR_SELECT["red"])
    assert (held.motor_left, held.motor_right) != (0, 0)
    after_frame = np.flatnonzero(trace["frame_done"])[0] + 1
    left, right = trace["motor_left"][after_frame:], trace["motor_right"][after_frame:]
    stopped = obstacle[after_frame:]
    assert np.all(left[stopped] == 0) and np.all(right[stopped] == 0)
    assert np.all(left[~stopped] == held.motor_left)
    assert np.all(right[~stopped] == held.motor_right)
    assert np.array_equal(trace["ft_left"][after_frame:], np.full(len(left), held.motor_left))


def test_latching_variant_releases_only_on_no_echo():
    p = small_params()
    periods = 5
    fall = [k * US.period_cycles + US.trigger_cycles + 1 for k in range(periods)]
    # Period 0: nothing; then near (102 mm), far (257 mm) twice, nothing.
    pulses = [
        (fall[k] + 40, fall[k] + 40 + w)
        for k, w in ((1, MM["stop"]), (2, MM["far"]), (3, MM["far"]))
    ]
    lock = variant_params("interlock_latches", LOCK)
    dut = FollowTargetSafe(p, US, lock)
    trace = run_safe(dut, [], pulses, edges=periods * US.period_cycles)
    measured = measurements_of(trace)
    assert [m.distance_mm for m in measured] == [DISTANCE_NONE, 102, 257, 257, DISTANCE_NONE]
    got = [bool(trace["obstacle"][m.edge]) for m in measured]
    model = InterlockModel(lock)
    assert got == [model.step(m) for m in measured]
    # The correct interlock lets go at the first far reading; the variant holds on until
    # the view is empty.
    assert got == [False, True, True, True, False]
    correct = InterlockModel(LOCK)
    assert [correct.step(m) for m in measured] == [False, True, False, False, False]


@pytest.mark.parametrize(
    "stop,resume,message",
    [
        (400, 300, "resume_mm=300 must be >= stop_mm=400"),
        (0, 10, "stop_mm must be >= 1"),
    ],
)
def test_bad_interlock_parameters_are_refused(stop, resume, message):
    with pytest.raises(ValueError, match=message):
        InterlockParams(stop_mm=stop, resume_mm=resume)


def test_default_interlock_thresholds():
    assert (InterlockParams().stop_mm, InterlockParams().resume_mm) == (300, 400)
    with pytest.raises(TypeError, match="us_params must be a UltrasoundParams"):
        FollowTargetSafe(None, InterlockParams())
