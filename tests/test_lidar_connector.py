"""The LIDAR connectors with a stand-in PinIO: each sample's payload and valid pulse at the
edge of its instant (stream), and the serial line's levels decoded as a UART would, bit by
bit, against the protocol's framing (descriptor, 5-byte packets) and the walls by hand."""

import math
import re

import numpy as np
import pytest

from fpga_robotics.hw.lidar_sample import unpack_sample
from fpga_robotics.loop.connectors import ConnectorError, LidarConnector, LidarUartConnector
from fpga_robotics.scenario.connectors import parse_connectors
from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.world import World

CLOCK_HZ = 1_000_000


class FakeIO:
    """Records ``schedule``/``poke`` per pin; ``cycle`` follows the steps."""

    def __init__(self):
        self.clock_hz = CLOCK_HZ
        self.cycle = 0
        self.events = {}  # pin -> [(edge, value)]

    def time_of(self, edge):
        return edge / self.clock_hz

    def edge_at(self, t):
        return math.ceil(t * self.clock_hz - 1e-9)

    def poke(self, pin, value):
        self.events.setdefault(pin, []).append((self.cycle + 1, value))

    def schedule(self, edge, pin, value):
        assert edge > self.cycle
        self.events.setdefault(pin, []).append((edge, value))


def _connector(cls, **keys):
    """A LIDAR on a robot at (1, 1) facing +x in a 4 x 2 m room, without noise."""
    world = World.from_config(
        {
            "room": {"width": 4.0, "depth": 2.0},
            "robot": {"model": "gopigo3", "start": [1.0, 1.0], "heading_deg": 0.0},
            "people": [],
        }
    )
    table = {"kind": cls.kind, "height": 0.2, "noise_frac": 0, "dark_return": 0, **keys}
    (spec,) = parse_connectors({"sensors": [table]})
    return cls(spec.name, spec.mount, spec.params, world=world, rng=np.random.default_rng(0))


def _run(conn, seconds, dt=1 / 240, clock_hz=CLOCK_HZ):
    io = FakeIO()
    io.clock_hz = clock_hz
    conn.start(io)
    t = 0.0
    for _ in range(round(seconds / dt)):
        conn.before_step(io, t, dt)
        t += dt
        io.cycle = io.edge_at(t)
    return io


def _expected_q2(index):
    """The wall met by sample ``index`` (0.99 degrees clockwise a sample) from (1, 1) in the
    4 x 2 m room, in q2 (mm x 4), 0 beyond 80 degrees of incidence."""
    a = -math.radians(index * 0.99 % 360)
    d = (math.cos(a), math.sin(a))
    hits = []
    for axis, lo, hi in ((0, 0.0, 4.0), (1, 0.0, 2.0)):
        if abs(d[axis]) > 1e-12:
            wall = hi if d[axis] > 0 else lo
            hits.append(((wall - 1.0) / d[axis], abs(d[axis])))
    t, cos_i = min(hits)
    return round(t * 4000) if cos_i >= math.cos(math.radians(80)) else 0


def test_stream_samples_at_their_instants():
    io = _run(_connector(LidarConnector), 0.2)  # 400 samples: a revolution and a bit
    valid = io.events["valid"]
    payloads = io.events["payload"]
    assert valid[0] == (1, 0)  # low from the start
    rises = [e for e, v in valid[1:] if v]
    falls = [e for e, v in valid[1:] if not v]
    assert len(rises) == len(payloads) == 400
    # Sample i at i / 2000 s: edge 500 i at 1 MHz (sample 0 at the first edge after start).
    assert rises[:4] == [1, 500, 1000, 1500] and rises[399] == 399 * 500
    assert falls == [e + 1 for e in rises]
    fields = [unpack_sample(v) for _, v in payloads]
    assert [f["angle_q6"] for f in fields[:3]] == [0, 63, 126]
    assert [i for i, f in enumerate(fields) if f["start"]] == [0, 364]
    assert [f["distance_q2"] for f in fields] == [_expected_q2(i) for i in range(400)]
    assert fields[0]["distance_q2"] == 12000 and fields[0]["quality"] == 15


def _line_bytes(transitions, bit_edges, end):
    """Decode the rx line as an 8N1 receiver: wait for a fall, sample each bit's middle."""
    edges = np.array([e for e, _ in transitions], dtype=float)  # as the bit times: no casts
    levels = [v for _, v in transitions]

    def level(edge):
        k = np.searchsorted(edges, edge, side="right") - 1
        return 1 if k < 0 else levels[k]

    falls = [e for e, v in transitions if v == 0]
    out, pos, k = [], 0, 0
    while True:
        while k < len(falls) and falls[k] <= pos:
            k += 1
        if k == len(falls) or falls[k] + 10 * bit_edges > end:
            return out
        fall = falls[k]
        bits = [level(fall + (j + 0.5) * bit_edges) for j in range(10)]
        assert bits[0] == 0 and bits[9] == 1, f"framing error at edge {fall}"
        out.append(sum(b << i for i, b in enumerate(bits[1:9])))
        pos = fall + 9.5 * bit_edges


def test_uart_bytes_decode_to_the_scan():
    conn = _connector(LidarUartConnector)
    io = _run(conn, 0.2)
    line = io.events["rx"]
    assert line[0] == (1, 1)  # idle high from the start
    data = bytes(_line_bytes(line[1:], CLOCK_HZ / 115200, io.cycle))
    # The standard scan's response descriptor, then 5-byte packets.
    assert data[:7] == bytes.fromhex("A55A0500004081")
    body = data[7:]
    n = len(body) // 5
    assert n >= 398  # every sample taken in 0.2 s but the last on the wire
    for i in range(n):
        b = body[5 * i : 5 * i + 5]
        s = b[0] & 1
        assert (b[0] >> 1) & 1 == 1 - s and b[1] & 1 == 1  # !S and the check bit C
        assert s == (i in (0, 364))
        angle_q6 = (b[1] >> 1) | (b[2] << 7)
        assert angle_q6 == math.floor(i * 63.36 + 1e-9) % 23040
        assert b[3] | (b[4] << 8) == _expected_q2(i)
        assert b[0] >> 2 == (15 if _expected_q2(i) else 0)
    # Sample 0 by hand: quality 15, S = 1: 0x3D; angle 0: 0x01 0x00; 12000 = 0x2EE0.
    assert body[:5] == bytes((0x3D, 0x01, 0x00, 0xE0, 0x2E))
    # Sample 1: 63 q6 = 0.98 degrees: (63 << 1) | 1 = 0x7F; S = 0: 15 << 2 | 2 = 0x3E.
    assert body[5:8] == bytes((0x3E, 0x7F, 0x00))


def test_uart_packets_follow_their_samples():
    """A packet starts at its sample's instant when the line is free, else right after the
    bytes before it: the descriptor's 70 bits (608 us) delay the first packets, which catch
    up (434 us of bits every 500 us) from packet 10 on."""
    io = _run(_connector(LidarUartConnector), 0.0125)  # three steps of 1/240 s
    falls = [e for e, v in io.events["rx"][1:] if v == 0]
    for k in range(10):  # back to back after the descriptor: 70 + 50 k bit times
        assert math.ceil((70 + 50 * k) / 115200 * CLOCK_HZ - 1e-9) in falls
    assert 9 * 500 not in falls
    for k in range(10, 25):  # on time: sample k at 500 k us
        assert 500 * k in falls


@pytest.mark.parametrize(
    "table, message",
    [
        ({"scan_hz": 0.5}, "scan_hz must be a number in Hz >= 1 and <= 15, got 0.5"),
        ({"min_range": 0.9, "max_range": 0.8}, "max_range must be greater than min_range"),
        ({"sample_rate": 100, "scan_hz": 15}, "sample_rate must be at least 10 samples"),
        ({"quality": 2.5}, "quality must be a whole number"),
        # 16 bits of mm x 4: a farther return could not be reported.
        (
            {"max_range": 40},
            (
                "max_range must be a number in m >= 0.5 and <= 16.38 (a sample's distance_q2, "
                "16 bits of mm x 4, carries at most 16.38 m), got 40"
            ),
        ),
        ({"spin": 1}, "unknown key 'spin' for a 'lidar' connector"),
        # The serial link's rate: the stream binding has no use for it.
        ({"baud": 57600}, "unknown key 'baud' for a 'lidar' connector"),
    ],
)
def test_bad_keys_are_named(table, message):
    with pytest.raises(ConnectorError, match=re.escape(message)):
        parse_connectors({"sensors": [{"kind": "lidar", **table}]})


def test_the_farthest_range_reports_a_wall_beyond_it_as_no_return():
    """At max_range = 16.38 m (the most 16 bits of mm x 4 carry) a wall 16 m away is
    reported at its distance, one 19 m away as no return (distance 0, quality 0)."""
    world = World.from_config(
        {
            "room": {"width": 20.0, "depth": 32.0},
            "robot": {"model": "gopigo3", "start": [1.0, 16.0], "heading_deg": 0.0},
            "people": [],
        }
    )
    table = {"kind": "lidar", "height": 0.2, "noise_frac": 0, "dark_return": 0, "max_range": 16.38}
    (spec,) = parse_connectors({"sensors": [table]})
    conn = LidarConnector(
        spec.name, spec.mount, spec.params, world=world, rng=np.random.default_rng(0)
    )
    samples = conn.scan.samples(world, 0, 364, 1.0, 16.0, 0.0, 0.2)
    ahead, left = samples[0], samples[273]  # 0 and 270.27 degrees clockwise
    assert (ahead.distance_q2, ahead.quality) == (0, 0)  # the wall x = 20, 19 m
    assert left.distance_m == pytest.approx(16.0 / math.cos(math.radians(0.27)), abs=1e-3)


@pytest.mark.parametrize(
    "keys, message",
    [
        (
            {"sample_rate": 8000},
            (
                "robot.sensors[0]: 8000 samples/s of 50 bits (5 bytes 8N1) need baud at least "
                "400000, or sample_rate at most 2304 (baud is 115200)"
            ),
        ),
        # 1200 baud carries 24 samples/s, fewer than any sample_rate allowed.
        (
            {"baud": 1200},
            (
                "robot.sensors[0]: 2000 samples/s of 50 bits (5 bytes 8N1) need baud at least "
                "100000 (baud is 1200)"
            ),
        ),
    ],
)
def test_a_serial_link_slower_than_the_samples_is_refused(keys, message):
    with pytest.raises(ConnectorError, match=re.escape(message)):
        parse_connectors({"sensors": [{"kind": "lidar_uart", **keys}]})


def test_a_serial_link_at_its_limit_keeps_up():
    """2304 samples/s fill 115200 baud (50 bits a packet): after a second on the wire, every
    sample taken has arrived but the last two (still behind the descriptor's 70 bits)."""
    io = _run(_connector(LidarUartConnector, sample_rate=2304), 1.0)
    data = bytes(_line_bytes(io.events["rx"][1:], CLOCK_HZ / 115200, io.cycle))
    assert data[:7] == bytes.fromhex("A55A0500004081")
    assert len(data[7:]) // 5 >= 2304 - 2


def test_a_stream_at_two_edges_a_sample_keeps_up():
    # 2000 samples/s on a 4 kHz clock: sample i is due at edge 2 i. Sample 0 waits for the
    # first edge after the start (1), which puts every later one an edge late, no more.
    io = _run(_connector(LidarConnector), 1.0, clock_hz=4000)
    rises = [e for e, v in io.events["valid"][1:] if v]
    assert rises == [2 * i + 1 for i in range(2000)]


@pytest.mark.parametrize(
    "scenario, sets, message",
    [
        (
            "corridor",
            ["sim.clock_hz=3000"],
            (
                "robot.sensors[0]: 2000 samples/s need two clock edges a sample: sim.clock_hz at "
                "least 4000, or sample_rate at most 1500 (sim.clock_hz is 3000)"
            ),
        ),
        # (Another design than corridor_follow_uart, whose UART's own check would speak first.)
        (
            "corridor_uart",
            ["sim.clock_hz=100000", 'design.top="corridor_follow"'],
            (
                "robot.sensors[0]: 115200 baud needs a clock edge a bit: sim.clock_hz at least "
                "115200, or baud at most 100000 (sim.clock_hz is 100000)"
            ),
        ),
        # The walls end at the ceiling: a scan plane above it would pass over them.
        (
            "corridor",
            ["room.height=2.0", "robot.sensors.0.height=2.9"],
            "robot.sensors[0].height must be below the ceiling (room.height = 2 m), got 2.9",
        ),
    ],
)
def test_a_lidar_that_does_not_fit_the_run_is_refused_at_load(scenario, sets, message):
    with pytest.raises(ScenarioError, match=re.escape(message)):
        load_scenario(scenario, sets)


def test_the_serial_binding_takes_its_baud():
    [spec] = parse_connectors({"sensors": [{"kind": "lidar_uart", "baud": 230400}]})
    assert spec.params.baud == 230400
