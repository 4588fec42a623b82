"""The pin backends on small designs written here: scheduled inputs, poke, peek and watch
stop at the hand-computed edges (sim/pins/base.py's cycle numbering), and a seeded script of
schedules, pokes, watches and runs gives identical stops and peeks on pysim, cxxrtl and
verilator. Every ``run`` is bounded (the watchdog of these testbenches).
"""

import numpy as np
import pytest
from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature
from fpga_robotics.sim.pins import (
    FILTERED_PORTS,
    PIXEL_PORTS,
    PinDesignSource,
    PinError,
    PixelTiming,
    Stop,
    get_pin_backend,
)

BACKENDS = ["pysim", "cxxrtl", "verilator"]


class BurstCounter(wiring.Component):
    """``cnt`` counts the edges that sample ``a`` high; the edge that samples ``a`` low after a
    burst latches the count into ``last``, clears ``cnt`` and raises ``done`` for one cycle.
    ``total = cnt + b`` and ``neg = -cnt`` are combinational."""

    a: In(1)
    b: In(4)
    cnt: Out(8)
    last: Out(8)
    done: Out(1)
    total: Out(8)
    neg: Out(signed(8))

    def elaborate(self, platform):
        m = Module()
        was = Signal()
        m.d.sync += [was.eq(self.a), self.done.eq(0)]
        with m.If(self.a):
            m.d.sync += self.cnt.eq(self.cnt + 1)
        with m.Elif(was):
            m.d.sync += [self.last.eq(self.cnt), self.cnt.eq(0), self.done.eq(1)]
        m.d.comb += [self.total.eq(self.cnt + self.b), self.neg.eq(-self.cnt)]
        return m


class StreamProbe(wiring.Component):
    """A pixel stream in, ``filtered`` out, ``beats`` counting the valid input beats.
    ``mode``: 0 ``filtered`` is the input one edge later; 1 the input itself
    (combinational); 2 as 0 with the ``first`` flag cleared; 3 ``valid`` always high."""

    pixels: In(pixel_stream_signature())
    mode: In(2)
    filtered: Out(pixel_stream_signature())
    beats: Out(16)

    def elaborate(self, platform):
        m = Module()
        valid, payload = Signal(), Signal(14)
        m.d.sync += [valid.eq(self.pixels.valid), payload.eq(self.pixels.payload)]
        with m.If(self.pixels.valid):
            m.d.sync += self.beats.eq(self.beats + 1)
        comb = self.mode == 1
        m.d.comb += [
            self.filtered.valid.eq(Mux(comb, self.pixels.valid, valid) | (self.mode == 3)),
            self.filtered.payload.eq(
                Mux(comb, self.pixels.payload, Mux(self.mode == 2, payload & ~(1 << 12), payload))
            ),
        ]
        return m


BURST = PinDesignSource(BurstCounter, "test_pins_burst_counter")
PROBE = PinDesignSource(
    StreamProbe,
    "test_pins_stream_probe",
    pixels=PIXEL_PORTS,
    filtered=FILTERED_PORTS,
    frame_size=(4, 3),
)


@pytest.fixture(scope="module", params=BACKENDS)
def burst(request):
    with get_pin_backend(request.param, BURST) as pins:
        yield pins


@pytest.fixture(scope="module", params=BACKENDS)
def probe(request):
    with get_pin_backend(request.param, PROBE) as pins:
        yield pins


def test_ports_from_the_signature():
    ports = BURST.ports
    assert list(ports) == ["a", "b", "cnt", "last", "done", "total", "neg"]
    assert (ports["b"].width, ports["b"].direction) == (4, "in")
    assert ports["neg"].signed and ports["neg"].direction == "out"
    assert set(list(PROBE.ports)[:3]) == {"pixels__valid", "pixels__payload", "mode"}


def test_scheduled_burst_stops_at_the_hand_computed_edges(burst):
    pins = burst
    pins.reset()
    assert pins.cycle == 0
    pins.watch(["done"])
    pins.schedule(3, "a", 1)  # edges 3..7 sample a high: cnt 5
    pins.schedule(8, "a", 0)  # edge 8 samples it low: last 5, done
    assert pins.run(100) == Stop(8, "done", 1)
    assert (pins.peek("last"), pins.peek("cnt"), pins.cycle) == (5, 0, 8)
    assert pins.run(100) == Stop(9, "done", 0)
    # poke: effective from edge cycle + 1 = 10; four edges count four.
    pins.poke("a", 1)
    assert pins.run(4) == Stop(13)
    assert (pins.peek("cnt"), pins.peek("total"), pins.peek("neg")) == (4, 4, -4)
    pins.poke("b", 7)  # the combinational output follows without an edge
    assert pins.peek("total") == 11 and pins.peek("b") == 7
    pins.watch(["total"])
    pins.poke("a", 0)  # edge 14: burst over, cnt 0, total 0 + 7
    assert pins.run(10) == Stop(14, "total", 7)
    assert pins.peek("last") == 4


def test_same_edge_changes_are_reported_in_watch_order(burst):
    pins = burst
    pins.reset()
    pins.schedule(20, "a", 1)
    pins.schedule(23, "a", 0)  # edges 20..22 count 3; edge 23 latches it
    pins.watch(["done", "last"])
    assert pins.run(50) == Stop(23, "done", 1)
    assert pins.run(50) == Stop(23, "last", 3)  # the second change, without an edge
    assert pins.run(50) == Stop(24, "done", 0)


def test_a_combinational_output_shows_the_next_edges_inputs(burst):
    pins = burst
    pins.reset()
    pins.watch(["total"])
    pins.schedule(6, "b", 1)
    pins.schedule(6, "b", 2)  # the last value given for an edge wins
    # b for edge 6 is on after edge 5: total = cnt + b changes in state 5.
    assert pins.run(20) == Stop(5, "total", 2)
    pins.schedule(pins.cycle + 1, "b", 3)  # the next edge: applied at once
    assert pins.peek("total") == 3


def _script(pins, seed):
    """A seeded mix of every operation; returns what the backend answered."""
    rng = np.random.default_rng(seed)
    outputs = ["cnt", "last", "done", "total", "neg"]
    pins.reset()
    log = []
    for _ in range(60):
        op = rng.integers(4)
        if op == 0:
            pins.schedule(pins.cycle + int(rng.integers(1, 12)), "a", int(rng.integers(2)))
        elif op == 1:
            pins.poke("b", int(rng.integers(16)))
        elif op == 2:
            pins.watch(
                [str(n) for n in rng.choice(outputs, int(rng.integers(0, 4)), replace=False)]
            )
        stop = pins.run(int(rng.integers(0, 25)))
        log.append((stop, [pins.peek(n) for n in pins.ports]))
    return log


@pytest.mark.slow
def test_a_seeded_script_is_the_same_on_every_backend():
    logs = {}
    for name in BACKENDS:
        with get_pin_backend(name, BURST) as pins:
            logs[name] = _script(pins, 7)
    assert any(stop.port for stop, _ in logs["pysim"])  # the script does stop on changes
    assert logs["cxxrtl"] == logs["pysim"]
    assert logs["verilator"] == logs["pysim"]


FRAME = np.arange(12, dtype=np.uint16).reshape(3, 4) * 341 + 7  # 12-bit values


def test_each_pixel_is_sampled_at_its_edge(probe):
    pins = probe
    pins.reset()
    timing = PixelTiming(start=4, line_period=11, pixel_period=3)
    pins.stream_frame(FRAME, timing)
    assert pins.frame_pending
    pins.watch(["beats"])
    edges = []
    for _ in range(12):
        stop = pins.run(200)
        assert stop.port == "beats"
        edges.append(stop.cycle)
    assert edges == [timing.edge_of(y, x) for y in range(3) for x in range(4)]
    assert not pins.frame_pending
    pins.watch([])
    pins.run(3)
    np.testing.assert_array_equal(pins.filtered_frame(), FRAME)


def test_combinational_stream_from_the_next_edge(probe):
    pins = probe
    pins.reset()
    pins.poke("mode", 1)
    pins.stream_frame(FRAME, PixelTiming(start=1, line_period=4))
    assert pins.filtered_frame() is None
    pins.run(12)
    np.testing.assert_array_equal(pins.filtered_frame(), FRAME)


def test_rgb888_frames_are_packed_as_the_camera_does(probe):
    pins = probe
    pins.reset()
    rgb = np.zeros((3, 4, 3), np.uint8)
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = 0xAF, 0x5C, 0x17  # each channel's top 4 bits
    pins.stream_frame(rgb, PixelTiming(start=1, line_period=4))
    pins.run(14)
    np.testing.assert_array_equal(pins.filtered_frame(), np.full((3, 4), 0xA51))


def test_back_to_back_frames_keep_their_filtered_streams_apart(probe):
    pins = probe
    pins.reset()
    frames = [FRAME, 4095 - FRAME, FRAME // 3]
    for i, frame in enumerate(frames):
        timing = PixelTiming(start=pins.cycle + 1, line_period=4)
        pins.stream_frame(frame, timing)
        pins.run(timing.last_edge(4, 3) - pins.cycle)
        if i:  # the previous frame's last beat comes out during this frame
            np.testing.assert_array_equal(pins.filtered_frame(), frames[i - 1])
    pins.run(2)
    np.testing.assert_array_equal(pins.filtered_frame(), frames[-1])


@pytest.mark.parametrize(
    "mode, message",
    [(2, "wrong first/last framing flags"), (3, "more filtered pixels than the frames")],
)
def test_a_badly_framed_filtered_stream_is_an_error(probe, mode, message):
    pins = probe
    pins.reset()
    pins.poke("mode", mode)
    if mode == 2:
        pins.stream_frame(FRAME, PixelTiming(start=2, line_period=5))
    with pytest.raises(PinError, match=message):
        pins.run(100)


def test_many_changes_scheduled_ahead(burst):
    """A queue that never empties (changes scheduled far ahead) keeps its order: bursts of
    1, 2, 3, ... edges, each latched into ``last`` by the edge that samples ``a`` low."""
    pins = burst
    pins.reset()
    starts = [10 * k + 5 for k in range(150)]
    for k, start in enumerate(starts):
        pins.schedule(start, "a", 1)
        pins.schedule(start + 1 + k % 7, "a", 0)
    pins.schedule(100_000, "b", 1)  # stays queued throughout
    pins.watch(["last"])
    latched = []
    while pins.cycle < 1600:
        stop = pins.run(1600 - pins.cycle)
        if stop.port:
            latched.append(stop.value)
    assert latched == [k % 7 + 1 for k in range(150)]  # neighbours differ: each one stops


def _bursts():
    """Bursts of 1, 2, 3, ... edges of ``a`` high, as (edges, values): burst k starts at
    edge 10 k + 5 and is latched into ``last`` at the edge that samples ``a`` low."""
    edges, values = [], []
    for k in range(150):
        start = 10 * k + 5
        edges += [start, start + 1 + k % 7]
        values += [1, 0]
    return np.array(edges), np.array(values)


def test_schedule_many_and_record_changes_give_the_hand_computed_latches(burst):
    pins = burst
    pins.reset()
    pins.schedule_many("a", *_bursts())
    changes = pins.record_changes(1600, ["last", "done"])
    # Burst k (length k % 7 + 1) is latched at edge 10 k + 5 + length; done pulses there.
    latch = [(10 * k + 5 + k % 7 + 1, k % 7 + 1) for k in range(150)]
    assert changes["last"] == latch
    assert changes["done"] == [c for at, _ in latch for c in ((at, 1), (at + 1, 0))]
    assert pins.cycle == 1600
    assert pins.stops == 3 * 150


def test_schedule_many_after_a_change_of_the_same_edge_wins(burst):
    pins = burst
    pins.reset()
    pins.schedule(6, "b", 1)
    pins.schedule_many("b", [6, 9], [2, 5])
    pins.schedule_many("b", [1], [3])  # the next edge: applied at once
    assert pins.peek("total") == 3
    # ``total`` = cnt + b shows the next edge's b: the later 2 from state 5, 5 from state 8.
    assert pins.record_changes(10, ["total"])["total"] == [(5, 2), (8, 5)]


def test_record_changes_in_small_chunks(burst, monkeypatch):
    """The compiled backends write changes in chunks; a chunk smaller than the changes
    gives the same list."""
    from fpga_robotics.sim.pins import compiled

    monkeypatch.setattr(compiled, "_RECORD_CHUNK", 4)
    pins = burst
    pins.reset()
    pins.schedule_many("a", *_bursts())
    assert [v for _, v in pins.record_changes(1600, ["last"])["last"]] == [
        k % 7 + 1 for k in range(150)
    ]


@pytest.mark.parametrize(
    ("edges", "values", "message"),
    [
        ([5, 5], [1, 0], "strictly increasing"),
        ([0, 4], [1, 0], "in the past"),
        ([3, 4], [1, 2], "does not fit port 'a'"),
        ([3, 4], [1], "one length"),
        ([3.5], [1], "must be ints"),
    ],
)
def test_schedule_many_refuses_bad_changes(burst, edges, values, message):
    burst.reset()
    with pytest.raises(PinError, match=message):
        burst.schedule_many("a", edges, values)


@pytest.mark.slow
def test_a_seeded_bulk_stimulus_is_recorded_the_same_on_every_backend():
    rng = np.random.default_rng(11)
    a_edges = np.flatnonzero(rng.random(3000) < 0.2) + 1
    b_edges = np.flatnonzero(rng.random(3000) < 0.1) + 1
    records = {}
    for name in BACKENDS:
        with get_pin_backend(name, BURST) as pins:
            pins.reset()
            pins.schedule_many("a", a_edges, np.arange(len(a_edges)) % 2)
            pins.schedule_many("b", b_edges, (b_edges * 7) % 16)
            records[name] = pins.record_changes(3000, ["cnt", "last", "neg", "total"])
    assert len(records["pysim"]["neg"]) > 100  # signed, and it moves
    assert min(v for _, v in records["pysim"]["neg"]) < 0
    assert records["cxxrtl"] == records["pysim"]
    assert records["verilator"] == records["pysim"]


def test_record_changes_refuses_a_bad_number_of_cycles(burst):
    burst.reset()
    with pytest.raises(PinError, match="cycles >= 0"):
        burst.record_changes(-1, ["last"])
