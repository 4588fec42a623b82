"""``--live foxglove``: a further camera's topics and a LIDAR's ``/<name>/scan`` reach a
WebSocket client as they reach the bag. The client subscribes to each topic as soon as it is
advertised (a channel is made at its topic's first message) and decodes what follows: the
images are the frames the pan camera took, stamped at its captures, and the scans are the
LIDAR's revolutions. Every wait is bounded."""

import contextlib
import json
import math
import struct
import time

import numpy as np
import pytest
from test_ros_live import STORE, Client
from test_turret import TWO_CAMERAS, write

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.ros.foxglove_live import LivePublisher
from fpga_robotics.ros.messages import camera_geometry
from fpga_robotics.scenario.load import load_scenario

DEADLINE_S = 60
pytestmark = pytest.mark.slow  # each runs a second or more (the fast tier's rule)


class SensorClient(Client):
    """Reads for a while (not until a message), subscribes to topics one batch at a time."""

    next_id = 1

    def poll(self, seconds):
        end = min(time.monotonic() + seconds, self.deadline)
        while (left := end - time.monotonic()) > 0:
            try:
                msg = self.ws.recv(timeout=left)
            except TimeoutError:
                return
            if isinstance(msg, str):
                body = json.loads(msg)
                if body.get("op") == "advertise":
                    for ch in body["channels"]:
                        self.channels[ch["topic"]] = ch
            elif msg[0] == 1:  # message data
                sub, ns = struct.unpack_from("<IQ", msg, 1)
                self.data.append((self.subs[sub], ns, msg[13:]))

    def subscribe(self, topics):
        subs = []
        for topic in topics:
            self.subs[self.next_id] = topic
            subs.append({"id": self.next_id, "channelId": self.channels[topic]["id"]})
            self.next_id += 1
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))


def live_messages(scenario, backend, topics):
    """Run ``scenario``, publish its frames live and return what a client subscribed to
    ``topics`` got (``{topic: [(log ns, message)]}``), with the run's records."""
    records = []
    run_scenario(scenario, backend=backend, on_frame=records.append)
    publisher = LivePublisher(0, camera_geometry(scenario))
    got = {}
    try:
        with contextlib.ExitStack() as stack:
            client = SensorClient(publisher.port, time.monotonic() + DEADLINE_S, stack)
            waiting = list(topics)
            for record in records:
                publisher.log_frame(record)
                client.poll(0.05)
                new = [t for t in waiting if t in client.channels]
                if new:
                    client.subscribe(new)
                    waiting = [t for t in waiting if t not in new]
                    client.poll(0.3)  # the server takes the subscription
            client.poll(0.5)
            assert not waiting, f"never advertised: {waiting}"
            for topic, ns, payload in client.data:
                kind = client.channels[topic]["schemaName"].replace("/", "/msg/", 1)
                got.setdefault(topic, []).append((ns, STORE.deserialize_cdr(payload, kind)))
    finally:
        publisher.close()
    return got, records


def test_a_further_camera_is_published_live(tmp_path):
    # Both cameras at 10 fps for 0.5 s: the pan camera captures at 0, 0.1, ..., 0.4 s. The
    # first capture makes its channels; the client hears the ones after it subscribed.
    scenario = load_scenario(
        write(tmp_path, TWO_CAMERAS.replace("duration = 0.2", "duration = 0.5"))
    )
    topics = ["/cameras/turret/image_raw", "/cameras/turret/camera_info"]
    got, records = live_messages(scenario, "model", topics)
    views = {round(r.cameras["turret"].sim_time * 1e9): r.cameras["turret"] for r in records}
    assert sorted(views) == [0, 100_000_000, 200_000_000, 300_000_000, 400_000_000]
    images = got[topics[0]]
    assert 1 <= len(images) <= 4 and [ns for ns, _ in images] == sorted(views)[-len(images) :]
    for ns, msg in images:
        view = views[ns]
        assert (msg.width, msg.height, msg.encoding) == (160, 120, "rgb8")
        assert msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec == ns
        assert np.array_equal(np.frombuffer(msg.data, np.uint8).reshape(120, 160, 3), view.rgb)
    infos = got[topics[1]]
    assert [ns for ns, _ in infos] == [ns for ns, _ in images]
    # 60 degrees over 160 px: f = 80 / tan(30 deg), the principal point at the centre.
    f = 80 / math.tan(math.radians(30))
    assert all(m.k[0] == pytest.approx(f) and m.k[2] == pytest.approx(80) for _, m in infos)


def test_a_lidar_scan_is_published_live():
    # 0.6 s at 5.5 rev/s: three whole revolutions (tests/test_lidar_bag.py); the first
    # makes the channel, the client hears those after it subscribed.
    scenario = load_scenario("corridor", ["sim.duration=0.6", "sim.clock_hz=1000000"])
    got, records = live_messages(scenario, "cxxrtl", ["/lidar/scan"])
    scans = {}
    for r in records:
        scan = r.sensors["lidar"].scan
        if scan is not None:
            scans[round(scan.start_time * 1e9)] = scan
    assert len(scans) == 3
    msgs = got["/lidar/scan"]
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _, m in msgs]
    assert 1 <= len(msgs) <= 2 and stamps == sorted(scans)[-len(msgs) :]
    for _, m in msgs:
        scan = scans[m.header.stamp.sec * 10**9 + m.header.stamp.nanosec]
        expected = np.array(scan.ranges, dtype=np.float32)
        expected[expected == 0] = np.inf  # no return
        assert np.array_equal(m.ranges, expected) and m.header.frame_id == "lidar_link"
        assert m.angle_increment == pytest.approx(-math.radians(0.99), abs=1e-7)
    assert [round(s * 1e9) for s in (0.182, 0.364)] == sorted(scans)[1:]
