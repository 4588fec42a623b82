"""The ultrasound and line-sensor connectors through a PinIO on a fake backend that records
what they poke and schedule: the ECHO edges a TRIG pulse gets, ignored triggers, the line
bits' order, the measurements, and clear errors for bad scenario tables."""

import math
import pathlib
import re
import tomllib

import numpy as np
import pytest

from fpga_robotics.loop.connectors.base import (
    CONNECTORS,
    ConnectorError,
    Mount,
    PinIO,
    connector_class,
    parse_mount,
)
from fpga_robotics.loop.connectors.line_sensors import LineSensorsConnector
from fpga_robotics.loop.connectors.ultrasound import UltrasoundConnector
from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.world import World

F = 50e6


class _Backend:
    """Records pokes and schedules; ``cycle`` is set by the test as the loop would."""

    def __init__(self):
        self.cycle = 0
        self.pokes, self.scheduled = [], []

    def poke(self, name, value):
        self.pokes.append((self.cycle, name, value))

    def schedule(self, edge, name, value):
        assert edge > self.cycle
        self.scheduled.append((edge, name, value))


def _io(binding):
    backend = _Backend()
    return backend, PinIO(backend, binding, F)


def _world(**room):
    return World.from_config(
        {"room": {"width": 4.0, "depth": 6.0, **room}, "robot": {"start": [1.0, 3.0]}, "people": []}
    )


def _pulse(conn, backend, io, rise, fall):
    backend.cycle = rise
    conn.on_change(io, "trig", 1, io.time_of(rise))
    backend.cycle = fall
    conn.on_change(io, "trig", 0, io.time_of(fall))


def test_both_kinds_are_registered():
    assert connector_class("ultrasound") is UltrasoundConnector is CONNECTORS["ultrasound"]
    assert connector_class("line_sensors") is LineSensorsConnector
    assert UltrasoundConnector.watch == ("trig",)
    assert UltrasoundConnector.pins["trig"].direction == "out"
    assert UltrasoundConnector.pins["echo"].direction == "in"


def test_a_trigger_schedules_the_echo_on_its_exact_edges():
    params = UltrasoundConnector.parse({"noise_std": 0.0, "temperature_c": 25.0}, "us")
    # Mounted 0.1 m forward, 0.12 m high: 4.0 - 1.1 = 2.9 m to the wall ahead.
    conn = UltrasoundConnector(
        "us", Mount(forward=0.1, height=0.12), params, world=_world(), rng=None
    )
    backend, io = _io({"trig": "us_trig", "echo": "us_echo"})
    _pulse(conn, backend, io, 1000, 1500)
    c = 331.3 + 0.606 * 25.0
    rise = 1500 + round(0.0005 * F)
    fall = rise + round(2 * 2.9 / c * F)
    assert backend.scheduled == [(rise, "us_echo", 1), (fall, "us_echo", 0)]
    # A row shows the echo once ECHO has fallen, not while the design still waits for it.
    backend.cycle = fall - 1
    conn.after_step(io, io.time_of(fall - 1))
    assert conn.measurement() == {}
    backend.cycle = fall
    conn.after_step(io, io.time_of(fall))
    m = conn.measurement()
    assert m["echo_edges"] == fall - rise and m["timeout"] == 0.0
    assert m["range_m"] == pytest.approx(2.9)
    assert m["echo_m"] == pytest.approx(2.9, abs=c / F)  # to one edge's worth of distance
    # During the echo, and too short: nothing more is scheduled.
    _pulse(conn, backend, io, rise + 100, rise + 700)
    _pulse(conn, backend, io, fall + 10, fall + 400)
    assert len(backend.scheduled) == 2 and conn.ignored == 2
    _pulse(conn, backend, io, fall + 1000, fall + 1500)
    assert len(backend.scheduled) == 4


@pytest.mark.parametrize("delay, clock_hz", [(0.0, F), (0.0005, 1000.0)])
def test_an_echo_delay_under_half_an_edge_rises_on_the_next_edge(delay, clock_hz):
    # No delay, or 0.5 ms on a 1 kHz clock (half an edge): ECHO cannot rise on the edge TRIG
    # fell at, which the design has already simulated; it rises on the next one.
    params = UltrasoundConnector.parse({"noise_std": 0.0, "echo_delay_s": delay}, "us")
    conn = UltrasoundConnector("us", Mount(height=0.1), params, world=_world(), rng=None)
    backend = _Backend()
    io = PinIO(backend, {"trig": "t", "echo": "e"}, clock_hz)
    fall = max(1, round(12e-6 * clock_hz))  # a 12 us TRIG pulse
    _pulse(conn, backend, io, 0, fall)
    width = round(2 * 3.0 / (331.3 + 0.606 * 20.0) * clock_hz)  # 3 m to the wall
    assert backend.scheduled == [(fall + 1, "e", 1), (fall + 1 + width, "e", 0)]


def test_nothing_in_range_is_the_time_out_pulse():
    params = UltrasoundConnector.parse({"noise_std": 0.0, "max_range": 2.0}, "us")
    conn = UltrasoundConnector("us", Mount(height=0.1), params, world=_world(), rng=None)
    backend, io = _io({"trig": "t", "echo": "e"})
    _pulse(conn, backend, io, 0, 500)
    (r, _, _), (f, _, _) = backend.scheduled
    assert f - r == round(0.038 * F)
    backend.cycle = f
    conn.after_step(io, io.time_of(f))
    m = conn.measurement()
    assert m["timeout"] == 1.0 and math.isnan(m["range_m"])


def test_noise_comes_from_the_connector_rng():
    params = UltrasoundConnector.parse({"noise_std": 0.01}, "us")

    def widths(seed):
        conn = UltrasoundConnector(
            "us", Mount(height=0.1), params, world=_world(), rng=np.random.default_rng(seed)
        )
        backend, io = _io({"trig": "t", "echo": "e"})
        for k in range(5):
            _pulse(conn, backend, io, k * 3_000_000, k * 3_000_000 + 500)
        return [b[0] - a[0] for a, b in zip(backend.scheduled[::2], backend.scheduled[1::2])]

    assert widths(7) == widths(7) != widths(8)


def test_line_bits_are_ordered_from_the_left():
    # The robot at (1, 3) facing +x; a line along x at y = 3.05: under the left sensor only.
    world = _world(lines=[{"points": [[0.5, 3.05], [3.5, 3.05]], "width": 0.019}])
    params = LineSensorsConnector.parse(
        {
            "sensors": [
                {"forward": 0.1, "left": 0.05},
                {"forward": 0.1},
                {"forward": 0.1, "left": -0.05},
            ],
            "noise_std": 0.0,
        },
        "robot.sensors[1]",
    )
    conn = LineSensorsConnector("line", Mount(height=0.01), params, world=world, rng=None)
    assert conn.pins["line"].width == 3
    backend, io = _io({"line": "line"})
    conn.before_step(io, 0.0, 0.01)
    assert backend.pokes == [(0, "line", 0b001)]
    m = conn.measurement()
    assert (m["line"], m["line0"], m["line1"], m["line2"]) == (1.0, 1.0, 0.0, 0.0)
    overlay = conn.map_overlay()
    assert overlay["points"][0] == pytest.approx((1.1, 3.05))
    assert overlay["points"][2] == pytest.approx((1.1, 2.95))
    assert overlay["states"] == (1, 0, 0)


@pytest.mark.parametrize(
    "kind, table, match",
    [
        ("ultrasound", {"cone": 15}, r"us: unknown key 'cone' for an 'ultrasound' connector"),
        ("ultrasound", {"cone_deg": 0}, r"us\.cone_deg must be a number in degrees > 0"),
        ("ultrasound", {"temperature_c": "warm"}, r"us\.temperature_c must be a number"),
        ("ultrasound", {"min_range": 0.5, "max_range": 0.4}, r"us\.max_range must be greater"),
        ("line_sensors", {}, r"us\.sensors must be an array of 1 to 3 tables"),
        ("line_sensors", {"sensors": [{}] * 4}, r"us\.sensors must be an array of 1 to 3"),
        (
            "line_sensors",
            {"sensors": [{"left": -0.01}, {"left": 0.01}]},
            r"us\.sensors\[1\]\.left must be less than sensors\[0\]\.left",
        ),
        ("line_sensors", {"sensors": [{"up": 1}]}, r"us\.sensors\[0\]: unknown key 'up'"),
        ("line_sensors", {"sensors": [{}], "threshold": 2}, r"us\.threshold must be a number"),
        ("line_sensors", {"sensors": [{}], "gain": 2}, r"us: unknown key 'gain'"),
    ],
)
def test_bad_tables_name_the_key(kind, table, match):
    with pytest.raises(ConnectorError, match=match):
        connector_class(kind).parse(table, "us")


def test_parse_mount_splits_the_mount_keys():
    mount, rest = parse_mount(
        {"forward": 0.1, "left": -0.02, "height": 0.15, "yaw_deg": 90, "cone_deg": 20},
        "robot.sensors[0]",
    )
    assert mount == Mount(0.1, -0.02, 0.15, math.pi / 2) and rest == {"cone_deg": 20}
    with pytest.raises(ConnectorError, match=r"robot\.sensors\[0\]\.height must be a number"):
        parse_mount({"height": -1}, "robot.sensors[0]")


def test_the_documented_sensor_tables_parse():
    doc = pathlib.Path(__file__).parents[1] / "docs" / "scenarios.md"
    (block,) = re.findall(r"```toml sensors\n(.*?)```", doc.read_text(), re.DOTALL)
    tables = tomllib.loads(block)["robot"]["sensors"]
    assert [t["kind"] for t in tables] == ["ultrasound", "line_sensors"]
    for i, table in enumerate(tables):
        rest = {k: v for k, v in table.items() if k not in ("kind", "name")}
        mount, rest = parse_mount(rest, f"robot.sensors[{i}]")
        params = connector_class(table["kind"]).parse(rest, f"robot.sensors[{i}]")
        conn = connector_class(table["kind"])(
            table["name"], mount, params, world=_world(), rng=np.random.default_rng(0)
        )
        assert conn.mount.height == table["height"]


def test_an_ultrasound_above_the_ceiling_is_refused_at_load():
    # Its beam would pass over the walls, which end at the ceiling (as a LIDAR's scan plane).
    with pytest.raises(
        ScenarioError,
        match=re.escape(
            "robot.sensors[0].height must be below the ceiling (room.height = 2 m), got 2.1"
        ),
    ):
        load_scenario("obstacle_between", ["room.height=2.0", "robot.sensors.0.height=2.1"])
