"""A corridor run's LIDAR written to a ROS 2 bag as sensor_msgs/LaserScan, read back with
rosbags: one message per revolution, its angles counter-clockwise (ROS) from the RPLIDAR's
clockwise ones, its ranges the connector's, no return as +inf."""

import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.ros.bag_writer import open_bag_writer
from fpga_robotics.scenario.load import load_scenario


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
    assert m.header.frame_id == "base_link"
