"""A design's extra outputs (every output no connector reads) in a ROS 2 bag: one topic each,
``/design/extra/<name>``, ``std_msgs/msg/Int64``, read back with rosbags."""

import dataclasses
import json
import math
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.cli.run import main as run_main
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.ros.bag_writer import open_bag_writer
from fpga_robotics.ros.messages import extra_topic
from fpga_robotics.scenario.load import load_scenario

DESIGNS = Path(__file__).parent / "data" / "user_designs"


def _read_bag(path):
    """{topic: [(stamp ns, data)]} of the extra-output topics and {topic: msgtype}."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    out, types = {}, {}
    with AnyReader([Path(path)], default_typestore=store) as reader:
        for conn in reader.connections:
            types[conn.topic] = conn.msgtype
        for conn, stamp, raw in reader.messages():
            if conn.topic.startswith("/design/extra/"):
                msg = reader.deserialize(raw, conn.msgtype)
                out.setdefault(conn.topic, []).append((stamp, msg.data))
    return out, types


def test_extra_topic_names_are_ros_names():
    assert extra_topic("distance_mm") == "/design/extra/distance_mm"
    assert extra_topic("a__b") == "/design/extra/a_b"
    assert extra_topic("hit-o.x") == "/design/extra/hit_o_x"
    assert extra_topic("3d") == "/design/extra/o3d"


def test_each_extra_output_is_a_topic_of_its_frames(tmp_path):
    """The values each frame carries, at the frame's simulated time; a frame without a
    value (NaN) publishes nothing on that topic."""
    scenario = load_scenario("follow_person", ['camera.resolution="80x60"', "sim.duration=0.5"])
    bag = tmp_path / "bag"
    writer = open_bag_writer(bag, scenario)
    sent = {"/design/extra/count": [], "/design/extra/signed_x": []}

    def on_frame(record):
        k = len(sent["/design/extra/count"])
        ns = round(record.sim_time * 1e9)
        extra = {"count": k, "signed x": -3 * k if k % 2 else math.nan}
        record = dataclasses.replace(record, design_extra=extra)
        sent["/design/extra/count"].append((ns, k))
        if k % 2:
            sent["/design/extra/signed_x"].append((ns, -3 * k))
        writer.log_frame(record)

    run_scenario(scenario, backend="model", on_frame=on_frame)
    writer.close()
    got, types = _read_bag(bag)
    assert types["/design/extra/count"] == types["/design/extra/signed_x"] == "std_msgs/msg/Int64"
    assert got == sent
    assert len(sent["/design/extra/count"]) == 15


@pytest.mark.slow  # a compiled model of wall_stop, 2 s in real-clock timing
def test_a_users_design_records_its_outputs_in_the_bag(tmp_path, monkeypatch):
    """wall_stop's distance_mm in the bag: the ultrasound's measure of the wall ahead (2.5 m
    room, robot at 0.5 m, sensor 0.1 m forward: 1.9 m at the start) and the same last, min
    and max as the run's summary."""
    monkeypatch.chdir(tmp_path)
    argv = [
        "--scenario",
        str(DESIGNS / "wall_stop.toml"),
        "--duration",
        "2",
        "--rerun",
        "off",
        "--quiet",
        "--bag",
        "bag",
        "--summary",
        "s.json",
    ]
    assert run_main(argv) == 0
    got, _ = _read_bag(tmp_path / "bag")
    assert sorted(got) == ["/design/extra/distance_mm", "/design/extra/stopped"]
    summary = json.loads((tmp_path / "s.json").read_text())
    for name in ("distance_mm", "stopped"):
        values = [v for _, v in got[f"/design/extra/{name}"]]
        assert len(values) == summary["frames"]
        stats = summary["extra_outputs"][name]
        assert (values[-1], min(values), max(values)) == (stats["last"], stats["min"], stats["max"])
    first = got["/design/extra/distance_mm"][0][1]
    assert abs(first - 1900) <= 15
