"""A corridor run's LIDAR written to a ROS 2 bag as sensor_msgs/LaserScan, read back with
rosbags: one message per revolution, its angles counter-clockwise (ROS) from the RPLIDAR's
clockwise ones, its ranges the connector's, no return as +inf; and a LIDAR mounted off the
centre and turned, whose scan placed by its /tf lands on the walls."""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.loop.connectors import LidarConnector
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.ros.bag_writer import open_bag_writer
from fpga_robotics.ros.laser_scan import LaserScans
from fpga_robotics.ros.messages import TYPESTORE
from fpga_robotics.scenario.connectors import parse_connectors
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.world import World


@pytest.fixture(scope="module")
def scans(tmp_path_factory):
    scenario = load_scenario("corridor", ["sim.duration=0.6", "sim.clock_hz=1000000"])
    bag = tmp_path_factory.mktemp("bag") / "corridor_bag"
    writer = open_bag_writer(bag, scenario)
    readings = []

    def on_frame(record):
        writer.log_frame(record)
        if record.sensors["lidar"].scan is not None:
            readings.append(record.sensors["lidar"].scan)

    run_scenario(scenario, backend="cxxrtl", on_frame=on_frame)
    writer.close()
    store = get_typestore(Stores.ROS2_HUMBLE)
    out = []
    with AnyReader([Path(bag)], default_typestore=store) as reader:
        conns = [c for c in reader.connections if c.topic == "/lidar/scan"]
        assert [c.msgtype for c in conns] == ["sensor_msgs/msg/LaserScan"]
        for conn, _stamp, raw in reader.messages(connections=conns):
            out.append(reader.deserialize(raw, conn.msgtype))
    return out, readings


def test_one_laser_scan_a_revolution(scans):
    msgs, _ = scans
    # 0.6 s at 5.5 rev/s: revolutions end at 0.182, 0.364, 0.546 s: three whole ones.
    assert len(msgs) == 3
    starts = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in msgs]
    # Revolution k begins with sample 0, 364, 728 (at 2000 samples/s).
    assert starts == pytest.approx([0.0, 0.182, 0.364])
    assert [len(m.ranges) for m in msgs] == [364, 364, 363]


def test_angles_and_ranges(scans):
    msgs, readings = scans
    last = readings[-1]
    m = msgs[-1]
    # Sample 728: 728 x 0.99 = 720.72 degrees, 0.72 clockwise: -0.72 degrees in ROS.
    assert m.angle_min == pytest.approx(-math.radians(0.72), abs=1e-6)
    assert m.angle_increment == pytest.approx(-math.radians(0.99), abs=1e-7)
    assert m.angle_max == pytest.approx(m.angle_min + 362 * m.angle_increment, abs=1e-5)
    assert m.time_increment == pytest.approx(0.0005) and m.scan_time == pytest.approx(1 / 5.5)
    assert (m.range_min, m.range_max) == pytest.approx((0.15, 12.0))
    expected = np.array(last.ranges, dtype=np.float32)
    expected[expected == 0] = np.inf
    assert np.array_equal(m.ranges, expected)
    assert np.array_equal(m.intensities, np.array(last.qualities, dtype=np.float32))
    assert m.header.frame_id == "lidar_link"


def test_a_turned_lidar_off_the_centre_lands_on_the_walls():
    """A LIDAR 0.1 m ahead and 0.05 m left of the centre, turned 90 degrees left, on a robot
    at (1, 1) heading 30 degrees in a 4 x 3 m room: each return, placed by the scan's /tf in
    base_link and by the robot's pose in the room, lies on a wall."""
    world = World.from_config(
        {
            "room": {"width": 4.0, "depth": 3.0},
            "robot": {"model": "gopigo3", "start": [1.0, 1.0], "heading_deg": 30.0},
            "people": [],
        }
    )
    table = {"kind": "lidar", "name": "side", "forward": 0.1, "left": 0.05, "height": 0.2}
    (spec,) = parse_connectors(
        {"sensors": [{**table, "yaw_deg": 90, "noise_frac": 0, "dark_return": 0}]}
    )
    conn = LidarConnector(
        spec.name, spec.mount, spec.params, world=world, rng=np.random.default_rng(0)
    )
    conn.take(0.2)  # a revolution (0.18 s) and the start of the next
    record = SimpleNamespace(
        sim_time=0.2, sensors={"side": SimpleNamespace(scan=conn.revolution())}
    )
    (tf_topic, _, tf_cdr), (topic, _, cdr) = LaserScans().encode(record)
    assert (tf_topic, topic) == ("/tf", "/side/scan")
    (place,) = TYPESTORE.deserialize_cdr(tf_cdr, "tf2_msgs/msg/TFMessage").transforms
    scan = TYPESTORE.deserialize_cdr(cdr, "sensor_msgs/msg/LaserScan")
    assert (place.header.frame_id, place.child_frame_id) == ("base_link", scan.header.frame_id)
    offset = place.transform.translation
    assert (offset.x, offset.y, offset.z) == pytest.approx((0.1, 0.05, 0.2))
    r = scan.ranges
    ok = np.isfinite(r)
    assert ok.mean() > 0.8
    a = scan.angle_min + scan.angle_increment * np.arange(len(r))
    bx, by = offset.x + r[ok] * np.cos(a[ok]), offset.y + r[ok] * np.sin(a[ok])
    h = math.radians(30)
    x = 1.0 + bx * math.cos(h) - by * math.sin(h)
    y = 1.0 + bx * math.sin(h) + by * math.cos(h)
    off_wall = np.minimum.reduce([abs(x), abs(x - 4.0), abs(y), abs(y - 3.0)])
    assert off_wall.max() < 1e-3
    # The sensor's forward (its first sample) points 90 degrees left of the robot's.
    assert scan.angle_min == pytest.approx(math.radians(90), abs=math.radians(1))
