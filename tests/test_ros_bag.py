"""``--bag``: a closed-loop run written as a ROS 2 bag (MCAP), read back with rosbags and with
mcap's own reader, and compared with the frames the design saw (issue 16)."""

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.cli.run import main as run_main
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.ros.bag_writer import open_bag_writer
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.world.config import parse_world_config

EXPECTED_TYPES = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "/camera/image_raw": "sensor_msgs/msg/Image",
    "/camera/camera_info": "sensor_msgs/msg/CameraInfo",
    "/fpga/filtered/image": "sensor_msgs/msg/Image",
    "/cmd_vel": "geometry_msgs/msg/Twist",
    "/odom": "nav_msgs/msg/Odometry",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/fpga/found": "std_msgs/msg/Bool",
    "/fpga/proximity": "std_msgs/msg/UInt8",
    "/fpga/centroid_x": "std_msgs/msg/UInt16",
    "/fpga/centroid_leds": "std_msgs/msg/UInt8",
    "/fpga/wheel_dps": "std_msgs/msg/Int16MultiArray",
    "/people": "visualization_msgs/msg/MarkerArray",
}
# Short, small and with the robot moving: 1 s at 80x60.
OVERRIDES = ['camera.resolution="80x60"', "sim.duration=1.0"]


def _read_bag(path):
    """{topic: [(bag stamp ns, message), ...]} and {topic: msgtype}."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    out, types = {}, {}
    with AnyReader([Path(path)], default_typestore=store) as reader:
        for conn in reader.connections:
            types[conn.topic] = conn.msgtype
        for conn, stamp, raw in reader.messages():
            out.setdefault(conn.topic, []).append((stamp, reader.deserialize(raw, conn.msgtype)))
    return out, types


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A run written to a bag through the writer, with the FrameRecords the loop produced."""
    scenario = load_scenario("follow_person", OVERRIDES)
    bag = tmp_path_factory.mktemp("bag") / "run_bag"
    writer = open_bag_writer(bag, scenario)
    records = []

    def on_frame(record):
        records.append(record)
        writer.log_frame(record)

    try:
        run_scenario(scenario, backend="model", on_frame=on_frame)
    except BaseException:
        writer.abandon()
        raise
    writer.close()
    messages, types = _read_bag(bag)
    return scenario, bag, records, messages, types


def test_topics_types_and_counts(recorded):
    _, bag, records, messages, types = recorded
    assert types == EXPECTED_TYPES
    assert len(records) == 30
    for topic in EXPECTED_TYPES:
        assert len(messages[topic]) == len(records), topic
    # Only the bag is left in its folder: no staging folder.
    assert [p.name for p in bag.parent.iterdir()] == [bag.name]
    assert sorted(p.name for p in bag.iterdir()) == ["metadata.yaml", f"{bag.name}.mcap"]


def test_stamps_are_sim_time_and_monotonic(recorded):
    _, _, records, messages, _ = recorded
    expected = [round(r.sim_time * 1e9) for r in records]
    assert all(b > a for a, b in itertools.pairwise(expected))
    for topic, items in messages.items():
        assert [stamp for stamp, _ in items] == expected, topic
    for topic in ("/camera/image_raw", "/camera/camera_info", "/fpga/filtered/image"):
        for _, msg in messages[topic]:
            assert msg.header.frame_id == "camera_optical_link", topic
    clock = [m.clock.sec * 10**9 + m.clock.nanosec for _, m in messages["/clock"]]
    assert clock == expected
    # frame k is captured at k / fps
    fps = 30
    assert np.allclose(np.array(expected) / 1e9, np.arange(len(records)) / fps, atol=1e-3)


def test_images_are_the_frames_the_design_saw(recorded):
    _, _, records, messages, _ = recorded
    for r, (_, img), (_, filt) in zip(
        records, messages["/camera/image_raw"], messages["/fpga/filtered/image"]
    ):
        assert (img.width, img.height, img.encoding, img.step) == (80, 60, "rgb8", 240)
        assert img.data.tobytes() == r.camera_rgb.tobytes()
        packed = r.result.filtered.astype(np.int64)
        # RGB444 to RGB888 by repeating each nibble (0xA -> 0xAA).
        rgb = np.stack([(packed >> s) & 0xF for s in (8, 4, 0)], axis=-1) * 0x11
        assert filt.encoding == "rgb8"
        assert np.array_equal(filt.data.reshape(60, 80, 3), rgb.astype(np.uint8))
    # the run really saw the target: the filtered frames are not all black
    assert any(r.result.filtered.any() for r in records)


def test_design_outputs_and_twist_from_the_dps(recorded):
    """The outputs and the twist they command, on the bag's topics and in the frame records
    the viewer logs."""
    scenario, _, records, messages, _ = recorded
    spec = parse_world_config(scenario.world).robot.spec
    r_wheel, sep = spec.wheel_radius, spec.wheel_separation
    moving = 0
    for k, r in enumerate(records):
        res = r.result
        assert messages["/fpga/found"][k][1].data == bool(res.found)
        assert messages["/fpga/proximity"][k][1].data == res.proximity
        assert messages["/fpga/centroid_x"][k][1].data == res.centroid_x
        assert messages["/fpga/centroid_leds"][k][1].data == res.centroid_leds
        assert list(messages["/fpga/wheel_dps"][k][1].data) == [res.motor_left, res.motor_right]
        twist = messages["/cmd_vel"][k][1]
        wl, wr = math.radians(res.motor_left), math.radians(res.motor_right)
        assert twist.linear.x == pytest.approx(r_wheel * (wl + wr) / 2, abs=1e-12)
        assert twist.angular.z == pytest.approx(r_wheel * (wr - wl) / sep, abs=1e-12)
        # The viewer's commanded twist is the same frame's (not the command in force).
        assert (r.cmd_v, r.cmd_w) == (twist.linear.x, twist.angular.z)
        moving += twist.linear.x != 0
    assert moving > 0
    assert records[0].cmd_v != 0  # the first frame's command, before it acts


def test_odometry_tf_and_people(recorded):
    scenario, _, records, messages, _ = recorded
    spec = parse_world_config(scenario.world).robot.spec
    for k, r in enumerate(records):
        odom = messages["/odom"][k][1]
        assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
        p, q = odom.pose.pose.position, odom.pose.pose.orientation
        assert (p.x, p.y) == pytest.approx((r.robot_x, r.robot_y))
        assert 2 * math.atan2(q.z, q.w) == pytest.approx(r.robot_heading, abs=1e-9)
        assert odom.twist.twist.linear.x == pytest.approx(r.robot_v)
        tf = messages["/tf"][k][1].transforms
        assert [(t.header.frame_id, t.child_frame_id) for t in tf] == [
            ("odom", "base_link"),
            ("base_link", "camera_link"),
            ("camera_link", "camera_optical_link"),
        ]
        assert tf[1].transform.translation.x == pytest.approx(spec.camera_forward)
        assert tf[1].transform.translation.z == pytest.approx(spec.camera_height)
        markers = messages["/people"][k][1].markers
        assert [
            c for m in markers for c in (m.pose.position.x, m.pose.position.y)
        ] == pytest.approx([c for p in r.people for c in (p.x, p.y)])
        assert [m.color.r > m.color.g for m in markers] == [p.is_target for p in r.people]
    info = messages["/camera/camera_info"][0][1]
    f = 40 / math.tan(scenario.camera.hfov / 2)  # (W/2) / tan(hfov/2)
    assert list(info.k) == pytest.approx([f, 0, 40, 0, f, 30, 0, 0, 1])


def test_mcap_reader_sees_embedded_schemas(recorded):
    _, bag, records, _, _ = recorded
    with open(bag / f"{bag.name}.mcap", "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        channels = {c.topic: c for c in summary.channels.values()}
        assert set(channels) == set(EXPECTED_TYPES)
        for topic, channel in channels.items():
            schema = summary.schemas[channel.schema_id]
            assert channel.message_encoding == "cdr"
            assert schema.encoding == "ros2msg"
            assert schema.name == EXPECTED_TYPES[topic]
            assert schema.data
        image_schema = summary.schemas[channels["/camera/image_raw"].schema_id].data.decode()
        assert "uint32 height" in image_schema and "string encoding" in image_schema
        counts = {}
        for _, channel, _message in reader.iter_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    assert counts == dict.fromkeys(EXPECTED_TYPES, len(records))


def test_cli_writes_the_bag_and_replaces_an_old_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = [
        "--backend",
        "model",
        "--resolution",
        "80x60",
        "--duration",
        "0.5",
        "--rerun",
        "off",
        "--quiet",
        "--bag",
        "out",
        "--summary",
        "s.json",
    ]
    assert run_main(argv) == 0
    first, _ = _read_bag(tmp_path / "out")
    frames = json.loads((tmp_path / "s.json").read_text())["frames"]
    assert len(first["/camera/image_raw"]) == frames == 15
    assert run_main(argv[:5] + ["0.2"] + argv[6:]) == 0  # a shorter run over the old bag
    second, _ = _read_bag(tmp_path / "out")
    assert len(second["/camera/image_raw"]) == 6
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "s.json"]


@pytest.mark.parametrize("intruder", ["file", "folder"])
def test_what_appears_at_the_bag_path_during_the_run_is_never_replaced(intruder, tmp_path):
    # Only a bag is replaced: a file or a folder written there meanwhile stays, and the new
    # bag is kept where the closing line says.
    scenario = load_scenario("follow_person", [*OVERRIDES, "sim.duration=0.1"])
    path = tmp_path / "out"
    writer = open_bag_writer(path, scenario)
    run_scenario(scenario, backend="model", on_frame=writer.log_frame)
    if intruder == "file":
        path.write_text("keep me\n")
    else:
        path.mkdir()
        (path / "v.mp4").write_text("keep me\n")
    line = writer.close()
    kept = path if intruder == "file" else path / "v.mp4"
    assert kept.read_text() == "keep me\n"
    assert line.startswith("ROS 2 bag (3 frames) kept in ") and "not replaced" in line
    staged = Path(line.split(" kept in ")[1].split(": ")[0])
    messages, _ = _read_bag(staged)
    assert len(messages["/camera/image_raw"]) == 3


def test_camera_link_is_tilted_as_the_camera():
    """The sim's tilt is positive looking up; in ROS (x forward, y left, z up) the camera's
    x axis then points up: rotated by the tf's quaternion it gains +z."""
    from fpga_robotics.ros.messages import TYPESTORE, CameraGeometry, FrameMessages

    tilt = 0.2
    geometry = CameraGeometry(
        width=80,
        height=60,
        hfov=1.0,
        mount_forward=0.1,
        mount_height=0.3,
        tilt=tilt,
        wheel_radius=0.03,
        wheel_separation=0.2,
    )
    scenario = load_scenario("follow_person", OVERRIDES)
    records = []
    run_scenario(scenario, backend="model", on_frame=records.append)
    encoded = {t: d for t, _, d in FrameMessages(geometry).encode(records[0])}
    tf = TYPESTORE.deserialize_cdr(encoded["/tf"], "tf2_msgs/msg/TFMessage").transforms[1]
    q = tf.transform.rotation
    # x axis rotated by q = (x, y, z, w): first column of the rotation matrix.
    forward = (1 - 2 * (q.y**2 + q.z**2), 2 * (q.x * q.y + q.w * q.z), 2 * (q.x * q.z - q.w * q.y))
    assert forward == pytest.approx((math.cos(tilt), 0.0, math.sin(tilt)))


def test_images_are_in_the_cameras_optical_frame(recorded):
    """REP 103's optical frame under camera_link: x right (-y of the link), y down (-z),
    z into the image (+x, the camera's forward), so that CameraInfo projects ahead."""
    messages = recorded[3]
    for _, msg in messages["/tf"]:
        (optical,) = [t for t in msg.transforms if t.child_frame_id == "camera_optical_link"]
        assert optical.header.frame_id == "camera_link"
        q = optical.transform.rotation
        x, y, z, w = q.x, q.y, q.z, q.w
        columns = [  # the optical axes in camera_link: the rotation matrix's columns
            (1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)),
            (2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)),
            (2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)),
        ]
        assert columns == [
            pytest.approx((0.0, -1.0, 0.0)),
            pytest.approx((0.0, 0.0, -1.0)),
            pytest.approx((1.0, 0.0, 0.0)),
        ]
