"""The connectors in the viewer: a real-clock run's recording read back."""

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import read_rrd
from fpga_robotics.viz.sensors import DESIGN_EXTRA, MAP_LINES, MAP_SENSORS, SENSORS


@pytest.fixture(scope="module")
def obstacle_run(tmp_path_factory):
    """obstacle_between for 1 s, the box taken away at 0.5 s, recorded."""
    path = tmp_path_factory.mktemp("rec") / "ob.rrd"
    s = load_scenario(
        "obstacle_between", ["sim.duration=1.0", "room.furniture.0.present_until=0.5"]
    )
    rec = open_recorder(f"save:{path}", default_path=str(path))
    result = run_scenario(s, backend="cxxrtl", recorder=rec)
    rec.close()
    return result, read_rrd(str(path))


def test_each_measurement_is_a_series_on_the_frames_timeline(obstacle_run):
    result, data = obstacle_run
    n = result.summary["frames"]
    echo = data.entities[f"{SENSORS}/front/echo_edges"]
    assert echo.frames == list(range(1, n))  # from the first echo on (frame 0: none yet)
    values = [v[0] for v in echo.values["Scalars:scalars"]]
    assert values == list(result.trajectory["front.echo_edges"][1:])
    mm = data.entities[f"{DESIGN_EXTRA}/distance_mm"]
    assert mm.frames == list(range(n))
    assert [v[0] for v in mm.values["Scalars:scalars"]] == list(
        result.trajectory["design.distance_mm"]
    )


def test_the_sensor_and_its_range_are_on_the_map(obstacle_run):
    result, data = obstacle_run
    ray = data.entities[f"{MAP_SENSORS}/front/ray"]
    assert len(ray.frames) >= 1
    (x0, y0), (x1, y1) = ray.values["LineStrips2D:strips"][-1][0]
    # From the sensor, as long as the last echo says (the map's y axis is flipped).
    assert np.hypot(x1 - x0, y1 - y0) == pytest.approx(
        result.trajectory["front.echo_m"][-1], abs=1e-4
    )


def test_the_box_leaves_the_map_when_it_leaves_the_room(obstacle_run):
    result, data = obstacle_run
    furniture = data.entities[P.MAP_FURNITURE]
    removed = [k for k, _, e in result.events if e == "furniture 'box' removed"]
    assert removed and furniture.frames == [0, removed[0]]


def test_floor_lines_are_drawn_once(tmp_path):
    path = tmp_path / "lt.rrd"
    s = load_scenario("line_track", ["sim.duration=0.2"])
    rec = open_recorder(f"save:{path}", default_path=str(path))
    run_scenario(s, backend="cxxrtl", recorder=rec)
    rec.close()
    data = read_rrd(str(path))
    (strip,) = data.static[MAP_LINES]["LineStrips2D:strips"]
    assert len(strip) == len(s.world["room"]["lines"][0]["points"]) + 1  # closed
    points = data.entities[f"{MAP_SENSORS}/line/points"]
    assert len(points.values["Points2D:positions"][-1]) == 3
    bits = data.entities[f"{SENSORS}/line/line1"]
    assert bits.values["Scalars:scalars"][0][0] == 1.0  # the middle one on the tape
