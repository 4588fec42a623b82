"""``--live foxglove:PORT``: a WebSocket client on loopback subscribes to the run's topics,
decodes Image and Twist with the schemas the server advertises, and steers the run with a
colour change and the target driven by hand, which the summary and the bag show acting at the
frame they were sent for (issue 16). Every wait is bounded."""

import contextlib
import json
import socket
import struct
import threading
import time
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from fpga_robotics.cli.run import main as run_main

STORE = get_typestore(Stores.ROS2_HUMBLE)
DEADLINE_S = 30  # the whole exchange; the run itself takes about 2 s
PAUSED_FRAMES = 5  # frames the client steps through one by one before steering


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Client:
    """A minimal Foxglove WebSocket protocol client (JSON control, binary data)."""

    def __init__(self, port, deadline, stack):
        self.deadline = deadline
        while True:
            try:
                self.ws = stack.enter_context(
                    connect(
                        f"ws://127.0.0.1:{port}",
                        subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                        open_timeout=2,
                    )
                )
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        self.channels = {}  # topic -> advertised channel
        self.subs = {}  # subscription id -> topic
        self.data = []  # (topic, log time ns, payload)

    def recv(self):
        left = self.deadline - time.monotonic()
        assert left > 0, "the live server went quiet"
        msg = self.ws.recv(timeout=left)
        if isinstance(msg, str):
            body = json.loads(msg)
            if body.get("op") == "advertise":
                for ch in body["channels"]:
                    self.channels[ch["topic"]] = ch
            return body
        assert msg[0] == 1  # message data
        sub, ns = struct.unpack_from("<IQ", msg, 1)
        self.data.append((self.subs[sub], ns, msg[13:]))
        return None

    def wait_for(self, predicate):
        while not predicate():
            self.recv()

    def subscribe(self, topics):
        subs = []
        for i, topic in enumerate(topics, start=1):
            self.subs[i] = topic
            subs.append({"id": i, "channelId": self.channels[topic]["id"]})
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def advertise(self, channels):
        self.ws.send(
            json.dumps(
                {
                    "op": "advertise",
                    "channels": [
                        {"id": cid, "topic": topic, "encoding": "json", "schemaName": schema}
                        for cid, (topic, schema) in channels.items()
                    ],
                }
            )
        )

    def publish(self, channel_id, message):
        self.ws.send(b"\x01" + struct.pack("<I", channel_id) + json.dumps(message).encode())

    def count(self, topic):
        return sum(1 for t, _, _ in self.data if t == topic)


def test_live_topics_and_client_controls(tmp_path, capsys):
    port = free_port()
    summary, bag = tmp_path / "s.json", tmp_path / "bag"
    argv = [
        "--backend",
        "model",
        "--resolution",
        "80x60",
        "--duration",
        "1.5",
        "--rerun",
        "off",
        "--quiet",
        "--live",
        f"foxglove:{port}",
        "--paused",
        "--summary",
        str(summary),
        "--bag",
        str(bag),
    ]
    outcome = {}

    def run():
        try:
            outcome["code"] = run_main(argv)
        except Exception as exc:  # noqa: BLE001 - re-raised by the test thread
            outcome["error"] = exc

    runner = threading.Thread(target=run, daemon=True)
    runner.start()
    deadline = time.monotonic() + DEADLINE_S
    with contextlib.ExitStack() as stack:
        client = Client(port, deadline, stack)
        info = client.recv()
        assert info["op"] == "serverInfo" and "clientPublish" in info["capabilities"]
        client.wait_for(
            lambda: "/cmd_vel" in client.channels and "/camera/image_raw" in client.channels
        )
        image_ch, twist_ch = client.channels["/camera/image_raw"], client.channels["/cmd_vel"]
        assert (image_ch["schemaName"], image_ch["encoding"], image_ch["schemaEncoding"]) == (
            "sensor_msgs/Image",
            "cdr",
            "ros2msg",
        )
        assert twist_ch["schemaName"] == "geometry_msgs/Twist"
        assert "float64 x" in twist_ch["schema"]
        client.subscribe(["/camera/image_raw", "/cmd_vel", "/fpga/found"])
        client.advertise(
            {
                1: ("/sim/step", "std_msgs/Empty"),
                2: ("/fpga/color_select", "std_msgs/String"),
                3: ("/target/cmd_vel", "geometry_msgs/Twist"),
                4: ("/sim/pause", "std_msgs/Bool"),
                5: ("/fpga/colour_select", "std_msgs/String"),  # misspelt
            }
        )
        time.sleep(0.3)  # let the server take the subscription and the advertisement
        for k in range(PAUSED_FRAMES):  # one frame a step, each seen before the next
            client.publish(1, {})
            client.wait_for(lambda k=k: client.count("/camera/image_raw") >= k + 1)
        time.sleep(0.3)
        assert client.count("/camera/image_raw") == PAUSED_FRAMES  # still paused
        client.publish(2, {"data": "purple"})  # not a colour select: refused, said why
        client.publish(2, {"data": "purple"})
        client.publish(2, {"colour": "blue"})  # not a std_msgs/String
        client.publish(5, {"data": "blue"})
        client.publish(2, {"data": "blue"})
        client.publish(
            3, {"linear": {"x": 0.5, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}
        )
        client.publish(4, {"data": False})  # resume
        with contextlib.suppress(ConnectionClosed):  # the server stops when the run ends
            while runner.is_alive():
                client.recv()
        runner.join(max(0.0, deadline - time.monotonic()))
    assert not runner.is_alive(), "the live run did not finish"
    if "error" in outcome:
        raise outcome["error"]
    assert outcome["code"] in (0, 1)

    # The client got Image and Twist messages that decode with the advertised types.
    images = [
        STORE.deserialize_cdr(p, "sensor_msgs/msg/Image")
        for t, _, p in client.data
        if t == "/camera/image_raw"
    ]
    twists = [
        STORE.deserialize_cdr(p, "geometry_msgs/msg/Twist")
        for t, _, p in client.data
        if t == "/cmd_vel"
    ]
    assert len(images) > PAUSED_FRAMES and len(twists) > PAUSED_FRAMES
    assert all(
        (m.width, m.height, m.encoding, len(m.data)) == (80, 60, "rgb8", 80 * 60 * 3)
        for m in images
    )

    # The summary says both inputs acted at frame 5, the first frame after the steps.
    inputs = json.loads(summary.read_text())["inputs"]
    assert [i for i in inputs if i["kind"] == "step"] == [
        {"frame": k, "t": pytest.approx(k / 30, abs=1e-6), "kind": "step", "value": None}
        for k in range(PAUSED_FRAMES)
    ]
    acted = {i["kind"]: i for i in inputs if i["kind"] in ("color", "target_velocity")}
    assert acted["color"]["frame"] == acted["target_velocity"]["frame"] == PAUSED_FRAMES
    assert acted["color"]["value"] == "blue"
    assert acted["target_velocity"]["value"] == [0.5, 0.0]

    # The messages the run could not use are said at once, each reason once, and at the end
    # and in the summary with their counts.
    out, err = capsys.readouterr()
    purple = "/fpga/color_select: unknown colour 'purple'"
    shape = "/fpga/color_select: not a std_msgs/String or std_msgs/UInt8 (KeyError: 'data')"
    topic = "/fpga/colour_select: not a control topic; those are /fpga/color_select, "
    for line in (purple, shape, topic):
        assert err.count(f"Foxglove live: a message not used: {line}") == 1, err
    assert "Foxglove live: 4 message(s) not used: " + purple in out
    refused = json.loads(summary.read_text())["refused_inputs"]
    assert [(r["topic"], r["messages"]) for r in refused] == [
        ("/fpga/color_select", 2),
        ("/fpga/color_select", 1),
        ("/fpga/colour_select", 1),
    ]
    assert refused[0]["reason"].startswith("unknown colour 'purple'")

    # The bag shows their effect: nothing blue to find from frame 5 on; the target walks
    # +x at 0.5 m/s from frame 5's instant, its script paused (y stays put).
    with AnyReader([Path(bag)], default_typestore=STORE) as reader:
        msgs = {}
        for conn, stamp, raw in reader.messages():
            msgs.setdefault(conn.topic, []).append((stamp, reader.deserialize(raw, conn.msgtype)))
    found = [m.data for _, m in msgs["/fpga/found"]]
    assert found[:PAUSED_FRAMES] == [True] * PAUSED_FRAMES
    assert not any(found[PAUSED_FRAMES:]) and len(found) == 45
    target = [
        (s / 1e9, next(mk.pose.position for mk in m.markers if mk.color.r > mk.color.g))
        for s, m in msgs["/people"]
    ]
    t5, p5 = target[PAUSED_FRAMES]
    for t, p in target[PAUSED_FRAMES + 1 :]:
        assert p.x - p5.x == pytest.approx(0.5 * (t - t5), abs=1e-6)
        assert p.y == pytest.approx(p5.y, abs=1e-9)


def test_replayed_inputs_give_the_same_run(tmp_path):
    """A run's recorded inputs, replayed, give the same frames: inputs act at the frames
    written in the file, without pacing or pausing."""
    inputs = [
        {"frame": 3, "kind": "target_velocity", "value": [0.0, -0.4]},
        {"frame": 4, "kind": "pause", "value": None},
        {"frame": 4, "kind": "color", "value": "green"},
        {"frame": 9, "kind": "target_velocity", "value": None},
        {"frame": 12, "kind": "color", "value": "red"},
    ]
    (tmp_path / "inputs.json").write_text(json.dumps({"inputs": inputs}))
    base = [
        "--backend",
        "model",
        "--resolution",
        "80x60",
        "--duration",
        "0.6",
        "--rerun",
        "off",
        "--quiet",
    ]
    runs = []
    for name in ("a", "b"):
        assert run_main(
            base
            + [
                "--replay-inputs",
                str(tmp_path / "inputs.json"),
                "--summary",
                str(tmp_path / f"{name}.json"),
                "--bag",
                str(tmp_path / name),
            ]
        ) in (0, 1)
        with AnyReader([tmp_path / name], default_typestore=STORE) as reader:
            runs.append([(c.topic, s, bytes(raw)) for c, s, raw in reader.messages()])
        summary = json.loads((tmp_path / f"{name}.json").read_text())
        assert [(i["frame"], i["kind"], i["value"]) for i in summary["inputs"]] == [
            (i["frame"], i["kind"], i["value"]) for i in inputs
        ]
    assert runs[0] == runs[1]
    found = [
        STORE.deserialize_cdr(raw, "std_msgs/msg/Bool").data
        for topic, _, raw in runs[0]
        if topic == "/fpga/found"
    ]
    assert found[:4] == [True] * 4 and not any(found[4:12]) and found[12:] != []
    assert run_main(base + ["--summary", str(tmp_path / "plain.json")]) in (0, 1)
    plain = json.loads((tmp_path / "plain.json").read_text())
    assert "inputs" not in plain


def test_a_replay_onto_another_run_or_past_its_end_is_said(tmp_path, capsys):
    """Inputs replayed onto another scenario, seed or overrides than the run they steered
    are a warning naming both; inputs at frames the run never reaches are counted."""
    inputs = [
        {"frame": 2, "kind": "color", "value": "green"},
        {"frame": 9, "kind": "color", "value": "red"},
        {"frame": 40, "kind": "color", "value": "blue"},
    ]
    (tmp_path / "inputs.json").write_text(json.dumps(inputs))
    base = ["--backend", "model", "--resolution", "80x60", "--rerun", "off", "--quiet"]
    steered = str(tmp_path / "steered.json")
    replay = ["--replay-inputs", str(tmp_path / "inputs.json")]
    assert run_main(base + ["--duration", "0.3", "--summary", steered] + replay) in (0, 1)
    out, err = capsys.readouterr()
    assert "warning" not in err  # a bare list says nothing of the run it steered
    assert "--replay-inputs: 2 input(s) after the run's last frame 8 were not applied" in out
    assert run_main(base + ["--duration", "0.3", "--replay-inputs", steered]) in (0, 1)
    out, err = capsys.readouterr()
    assert "warning" not in err and "not applied" not in out  # the same run: only frame 2
    assert run_main(base + ["--duration", "0.2", "--seed", "4", "--replay-inputs", steered]) in (
        0,
        1,
    )
    out, err = capsys.readouterr()
    assert (
        f"warning: --replay-inputs {steered!r} was steered on follow_person (seed 0, --set "
        f'camera.resolution="80x60", --set sim.duration=0.3); this run is follow_person '
        f'(seed 4, --set camera.resolution="80x60", --set sim.duration=0.2)'
    ) in err


def test_time_held_paused_is_not_the_runs_speed():
    """A run held paused (``--paused``, a client's ``/sim/pause``) reports its speed without
    the pause, and the pause beside it."""
    from fpga_robotics.checks.summary import format_summary
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.ros.controls import LiveControls
    from fpga_robotics.scenario.load import load_scenario

    hold = 1.5

    class HeldControls(LiveControls):
        """Paused at the first frame; resumed ``hold`` seconds later."""

        def inputs_for(self, frame, t):
            if frame == 0:
                threading.Timer(hold, self.submit, ("resume",)).start()
            return super().inputs_for(frame, t)

    controls = HeldControls(speed=None, paused=True)
    scenario = load_scenario("follow_person", ['camera.resolution="80x60"', "sim.duration=0.1"])
    result = run_scenario(scenario, backend="model", controls=controls)
    assert controls.paused_s >= hold
    summary = result.summary
    assert summary["wall_time_s"] < hold  # three frames of the model, not the pause
    assert summary["realtime_factor"] > 0.1 / hold
    line = format_summary({**summary, "paused_s": round(controls.paused_s, 3)}).splitlines()[1]
    assert f"paused {controls.paused_s:.1f} s besides" in line


@pytest.mark.parametrize(
    "topic, schema, fields, expected",
    [
        ("/fpga/color_select", "std_msgs/String", {"data": "cyan"}, ("color", "cyan")),
        ("/fpga/color_select", "std_msgs/UInt8", {"data": 0b010}, ("color", "green")),
        ("/sim/pause", "std_msgs/Bool", {"data": True}, ("pause", None)),
        ("/sim/pause", "std_msgs/Bool", {"data": False}, ("resume", None)),
        ("/sim/step", "std_msgs/Empty", {}, ("step", None)),
    ],
)
def test_control_messages_in_cdr_and_json(topic, schema, fields, expected):
    """What Foxglove publishes (CDR with a ROS 2 schema, or JSON) becomes the same input."""
    from fpga_robotics.ros.controls import check_input
    from fpga_robotics.ros.foxglove_live import _decode, control_input

    msgtype = schema.replace("/", "/msg/")
    cdr = bytes(STORE.serialize_cdr(STORE.types[msgtype](**fields), msgtype))
    for encoding, data in (("cdr", cdr), ("json", json.dumps(fields).encode())):
        assert check_input(*control_input(topic, _decode(encoding, schema, data))) == expected


def test_teleop_twist_in_cdr():
    from fpga_robotics.ros.foxglove_live import _decode, control_input

    T = STORE.types
    twist = T["geometry_msgs/msg/Twist"](
        linear=T["geometry_msgs/msg/Vector3"](x=0.25, y=-0.5, z=0.0),
        angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=1.0),
    )
    cdr = bytes(STORE.serialize_cdr(twist, "geometry_msgs/msg/Twist"))
    assert control_input("/target/cmd_vel", _decode("cdr", "geometry_msgs/Twist", cdr)) == (
        "target_velocity",
        [0.25, -0.5],
    )


def test_inputs_are_events_of_the_run_and_of_its_frames():
    """Each applied input is an event of the run (the summary's count, the rerun event log
    through the frame records) at its frame; a teleop without a target is an event too."""
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.ros.controls import ReplayControls
    from fpga_robotics.scenario.load import load_scenario

    inputs = [
        {"frame": 2, "kind": "color", "value": "green"},
        {"frame": 4, "kind": "target_velocity", "value": [0.1, 0.0]},
    ]
    for people, teleop_event in (
        (None, "control: target velocity (+0.10, +0.00) m/s"),
        ("people=[]", "control: no target person to drive"),
    ):
        overrides = ['camera.resolution="80x60"', "sim.duration=0.3"]
        scenario = load_scenario("follow_person", overrides + ([people] if people else []))
        records = []
        result = run_scenario(
            scenario, backend="model", controls=ReplayControls(inputs), on_frame=records.append
        )
        controls = [(k, e) for k, _, e in result.events if e.startswith("control:")]
        assert controls == [(2, "control: colour select green"), (4, teleop_event)]
        assert [
            (r.frame, [e for e in r.events if e.startswith("control:")])
            for r in records
            if any(e.startswith("control:") for e in r.events)
        ] == [(2, ["control: colour select green"]), (4, [teleop_event])]
        if people is None:  # the red target is lost on the very frame green is selected
            assert "target lost" in records[2].events
        assert [r.color_sel for r in records] == [4, 4] + [2] * (len(records) - 2)
        assert result.summary["events"] == len(result.events)
