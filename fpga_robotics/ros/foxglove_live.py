"""``--live foxglove[:PORT]``: the run's topics on a Foxglove WebSocket server (foxglove-sdk),
and live control from the client.

The server listens on localhost only and publishes the same ROS 2 messages as the bag
(``messages.TOPICS``, further cameras' ``/cameras/<name>/...`` and a LIDAR's
``/<name>/scan``, CDR with their ``ros2msg`` schemas) as each frame is done. Clients may
publish (client-publish capability) on the control topics ``CONTROL_TOPICS``, in JSON or CDR;
each message becomes a ``LiveControls`` input, applied at the next frame boundary. A message
the run cannot use (a topic that controls nothing, a value out of range, an unreadable
message) is said at once on stderr and listed in the closing notice and the summary.
"""

import json
import socket
import sys
import threading
from pathlib import Path

import foxglove
from foxglove.websocket import Capability

from fpga_robotics.hw.errors import UsageError

from .laser_scan import SCAN_TYPE, LaserScans
from .messages import TOPICS, TYPESTORE, FrameMessages, msgdef, topic_type

__all__ = [
    "CONTROL_TOPICS",
    "DEFAULT_PORT",
    "LivePublisher",
    "check_live_port",
    "control_input",
    "parse_live_spec",
]

DEFAULT_PORT = 8765

#: Topics a client may publish on, with the types they accept: what each one controls.
CONTROL_TOPICS = {
    "/fpga/color_select": ("std_msgs/msg/String", "std_msgs/msg/UInt8"),
    "/target/cmd_vel": ("geometry_msgs/msg/Twist",),
    "/sim/pause": ("std_msgs/msg/Bool", "std_msgs/msg/Empty"),
    "/sim/step": ("std_msgs/msg/Empty", "std_msgs/msg/Bool"),
}


def parse_live_spec(spec):
    """``foxglove`` or ``foxglove:PORT`` (0 = any free port) to the port number."""
    kind, _, port = str(spec).partition(":")
    if kind != "foxglove":
        raise UsageError(f"--live must be foxglove or foxglove:PORT, got {spec!r}")
    if not port:
        return DEFAULT_PORT
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise UsageError(f"--live foxglove:PORT needs a port number 0..65535, got {port!r}")
    return int(port)


def check_live_port(port):
    """``UsageError`` when ``port`` on 127.0.0.1 is taken or not ours to listen on: said
    before the run starts, not when the server opens."""
    if port == 0:  # any free port
        return
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        # As a server binds: a port left in TIME_WAIT is free, one with a listener is not.
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError as exc:
            raise UsageError(
                f"--live: cannot serve on 127.0.0.1:{port} ({exc.strerror}); "
                f"give another port with --live foxglove:PORT"
            ) from None


def _decode(encoding, schema_name, data):
    """A client message as a dict (JSON) or a message object (CDR)."""
    if encoding == "json":
        return json.loads(bytes(data).decode())
    name = schema_name.replace("/", "/msg/", 1) if "/msg/" not in schema_name else schema_name
    msg = TYPESTORE.deserialize_cdr(bytes(data), name)
    return {f: getattr(msg, f) for f in msg.__dataclass_fields__}


def control_input(topic, message):
    """The ``(kind, value)`` input of a message on a control topic (a dict of its fields)."""
    if topic == "/fpga/color_select":
        return "color", message["data"]
    if topic == "/target/cmd_vel":
        lin = message["linear"]
        lin = lin if isinstance(lin, dict) else {"x": lin.x, "y": lin.y}
        return "target_velocity", [float(lin.get("x", 0.0)), float(lin.get("y", 0.0))]
    if topic == "/sim/pause":
        paused = message.get("data", True)
        return ("pause" if paused else "resume"), None
    if topic == "/sim/step":
        return "step", None
    raise ValueError(f"{topic} is not a control topic")


class _Listener(foxglove.websocket.ServerListener):
    def __init__(self, publisher):
        self.publisher = publisher
        self.channels = {}  # (client id, client channel id) -> (topic, encoding, schema name)

    def on_subscribe(self, client, channel):
        with self.publisher.lock:
            self.publisher.subscribed.add(channel.topic)

    def on_client_advertise(self, client, channel):
        self.channels[(client.id, channel.id)] = (
            channel.topic,
            channel.encoding,
            channel.schema_name,
        )

    def on_client_unadvertise(self, client, client_channel_id):
        self.channels.pop((client.id, client_channel_id), None)

    def on_message_data(self, client, client_channel_id, data):
        topic, encoding, schema_name = self.channels.get(
            (client.id, client_channel_id), (None, None, None)
        )
        if topic not in CONTROL_TOPICS:
            self.publisher.refuse(
                topic, "not a control topic; those are " + ", ".join(CONTROL_TOPICS)
            )
            return
        try:
            kind, value = control_input(topic, _decode(encoding, schema_name, data))
            self.publisher.controls.submit(kind, value)
        except Exception as exc:  # noqa: BLE001 - a client's bad message never stops the run
            self.publisher.refuse(topic, _refusal(topic, exc))


def _refusal(topic, exc):
    """Why a message on the control topic ``topic`` could not be used, in words."""
    if isinstance(exc, json.JSONDecodeError):
        return f"not JSON ({exc})"
    if isinstance(exc, (ValueError, TypeError)):  # a value the input does not take
        return str(exc)
    types = " or ".join(t.replace("/msg/", "/") for t in CONTROL_TOPICS[topic])
    return f"not a {types} ({type(exc).__name__}: {exc})"


class LivePublisher:
    """A display connector that publishes each ``FrameRecord`` to a Foxglove server.

    Parameters
    ----------
    port : int
        TCP port on 127.0.0.1 (0: any free port; ``port`` then tells which).
    geometry : messages.CameraGeometry
    controls : controls.LiveControls or None
        Where client-published control messages go (None: no client publishing).
    """

    def __init__(self, port, geometry, controls=None):
        self.controls = controls
        self.lock = threading.Lock()
        self.subscribed = set()
        self.refused = {}  # (topic, why) -> how many client messages were not used for it
        self._messages = FrameMessages(geometry)
        self._scans = LaserScans()  # a LIDAR's revolutions, on channels made when first seen
        self._context = foxglove.Context()
        self._channels = {topic: self._channel(topic, msgtype) for topic, msgtype in TOPICS.items()}
        try:
            self._server = foxglove.start_server(
                name="fpga_robotics",
                host="127.0.0.1",
                port=port,
                context=self._context,
                capabilities=[Capability.ClientPublish] if controls is not None else [],
                supported_encodings=["json", "cdr"],
                server_listener=_Listener(self) if controls is not None else None,
            )
        except RuntimeError as exc:  # FoxgloveError: the port is taken, no permission
            raise UsageError(
                f"--live: cannot serve on 127.0.0.1:{port} ({exc}); "
                f"give another port with --live foxglove:PORT"
            ) from None
        self.port = self._server.port
        self.frames_logged = 0

    def _channel(self, topic, msgtype):
        return foxglove.Channel(
            topic,
            message_encoding="cdr",
            context=self._context,
            schema=foxglove.Schema(
                name=msgtype.replace("/msg/", "/"),
                encoding="ros2msg",
                data=msgdef(msgtype).encode(),
            ),
        )

    def refuse(self, topic, reason):
        """A client message the run cannot use: said at once on stderr (each reason once),
        and counted for the closing notice and the summary."""
        with self.lock:
            count = self.refused[topic, reason] = self.refused.get((topic, reason), 0) + 1
        if count == 1:
            clear = "\r\033[K" if sys.stderr.isatty() else ""  # a progress bar may be drawn
            print(f"{clear}Foxglove live: a message not used: {topic}: {reason}", file=sys.stderr)

    def refused_inputs(self):
        """The refused messages for the summary: ``[{"topic", "reason", "messages"}, ...]``."""
        with self.lock:
            return [
                {"topic": topic, "reason": reason, "messages": count}
                for (topic, reason), count in self.refused.items()
            ]

    @property
    def url(self):
        return f"ws://127.0.0.1:{self.port}"

    def pop_notices(self):
        return [
            (f"Foxglove live: open a WebSocket connection to {self.url} (layout: {layout_path()})")
        ]

    def log_world_map(self, world_map):
        """Nothing: Foxglove draws the people and the robot from their topics."""

    def log_frame(self, record):
        channels = self._channels
        for topic, ns, data in self._messages.encode(record):
            if topic not in channels:  # a further camera's or an extra output's, first seen now
                kind = self._messages.topic_types.get(topic) or topic_type(topic)
                channels[topic] = self._channel(topic, kind)
            channels[topic].log(bytes(data), log_time=ns)
        for topic, ns, data in self._scans.encode(record):
            if topic not in channels:
                channels[topic] = self._channel(topic, SCAN_TYPE)
            channels[topic].log(bytes(data), log_time=ns)
        self.frames_logged += 1

    def close(self):
        """Stop the server; returns the notice of the client messages not used ("" if none)."""
        if self._server is not None:
            self._server.stop()
            self._server = None
        refused = self.refused_inputs()
        if not refused:
            return ""
        return f"Foxglove live: {sum(r['messages'] for r in refused)} message(s) not used: " + (
            "; ".join(
                f"{r['topic']}: {r['reason']}"
                + (f" (x{r['messages']})" if r["messages"] > 1 else "")
                for r in refused
            )
        )


def layout_path():
    """The Foxglove layout shipped with the package."""
    return Path(__file__).with_name("foxglove_layout.json")
