"""``--source bag:PATH[:TOPIC]``: the images of a ROS 2 or ROS 1 bag (a real robot's
recording) as frames for the design.

``sensor_msgs/Image`` in rgb8, bgr8, rgba8, bgra8, mono8, yuv422 (UYVY) or yuv422_yuy2
(YUYV), or ``sensor_msgs/CompressedImage`` (JPEG, PNG): decoded to BGR and resized to the
design's resolution like every other source (``sim.camera.opencv_frames.to_design_rgb``). Without ``TOPIC``
the bag's only image topic is used (``/camera/image_raw`` when there are several). The
frames keep the bag's times: ``frame_time(k)`` is seconds since the first frame.
"""

from itertools import islice
from pathlib import Path

import cv2
import numpy as np
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.sim.camera.opencv_frames import to_design_rgb

__all__ = ["ENCODINGS", "IMAGE_TYPES", "BagSource", "parse_bag_spec"]

IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")

#: Raw image encodings read, with the OpenCV conversion to BGR (None: already BGR).
ENCODINGS = {
    "rgb8": "COLOR_RGB2BGR",
    "bgr8": None,
    "rgba8": "COLOR_RGBA2BGR",
    "bgra8": "COLOR_BGRA2BGR",
    "mono8": "COLOR_GRAY2BGR",
    "yuv422": "COLOR_YUV2BGR_UYVY",
    "uyvy": "COLOR_YUV2BGR_UYVY",
    "yuv422_yuy2": "COLOR_YUV2BGR_YUY2",
    "yuyv": "COLOR_YUV2BGR_YUY2",
}
_CHANNELS = {"rgb8": 3, "bgr8": 3, "rgba8": 4, "bgra8": 4, "mono8": 1}

_DEFAULT_TOPIC = "/camera/image_raw"


def parse_bag_spec(spec):
    """``bag:PATH[:TOPIC]`` (a topic starts with ``/``) to ``(path, topic or None)``."""
    rest = str(spec)[len("bag:") :]
    path, sep, topic = rest.rpartition(":/")
    if not sep:
        path, topic = rest, None
    else:
        topic = "/" + topic
    if not path:
        raise UsageError(f"--source bag:PATH[:TOPIC] needs the bag's path, got {spec!r}")
    return Path(path), topic


def check_image(msg, msgtype):
    """``UsageError`` for a raw image whose encoding is not read, that has no pixels, or
    whose size does not fit its data (a CompressedImage shows whether it can be read only when it is decoded)."""
    if msgtype.endswith("CompressedImage"):
        return
    enc = msg.encoding.lower()
    if enc not in ENCODINGS:
        raise UsageError(
            f"image encoding {msg.encoding!r} is not read; use one of " + ", ".join(ENCODINGS)
        )
    h, w, size = msg.height, msg.width, len(msg.data)
    if h == 0 or w == 0:  # a driver's placeholder for a dropped frame; nothing to resize
        raise UsageError(f"a {w}x{h} image holds no pixels")
    if msg.step < w * _CHANNELS.get(enc, 2) or size != h * msg.step:
        raise UsageError(
            f"a {w}x{h} {enc} image with step {msg.step} cannot hold "
            f"{size} bytes: the bag's image is malformed"
        )


def decode_image(msg, msgtype):
    """A bag image message as a BGR uint8 array; ``UsageError`` for an encoding not read."""
    data = np.frombuffer(memoryview(msg.data), np.uint8)
    if msgtype.endswith("CompressedImage"):
        bgr = cv2.imdecode(data, cv2.IMREAD_COLOR)
        if bgr is None:
            raise UsageError(
                f"cannot decode a CompressedImage in format {msg.format!r} "
                f"(OpenCV reads JPEG and PNG)"
            )
        return bgr
    check_image(msg, msgtype)
    enc = msg.encoding.lower()
    h, w = msg.height, msg.width
    if enc in _CHANNELS:
        c = _CHANNELS[enc]
        rows = data.reshape(h, msg.step)[:, : w * c]  # rows may be padded to `step`
        img = rows.reshape(h, w, c) if c > 1 else rows.reshape(h, w)
    else:  # 4:2:2, two bytes a pixel
        img = data.reshape(h, msg.step)[:, : w * 2].reshape(h, w, 2)
    conversion = ENCODINGS[enc]
    return (
        np.ascontiguousarray(img)
        if conversion is None
        else cv2.cvtColor(np.ascontiguousarray(img), getattr(cv2, conversion))
    )


class BagSource:
    """The images of one topic of a bag, as RGB888 frames at ``width`` x ``height``; with
    ``max_frames`` the run takes the first ones only, and only they are checked."""

    def __init__(self, spec, width, height, max_frames=None):
        self.spec = str(spec)
        self.kind = "bag"
        self.width, self.height = width, height
        path, topic = parse_bag_spec(spec)
        if not path.exists():
            raise UsageError(
                f"--source {self.spec!r}: no such bag (give a ROS 2 bag folder, "
                f"its .mcap/.db3 file, or a ROS 1 .bag file)"
            )
        # A ROS 2 bag's .mcap/.db3 file is read alone (it holds its own topics and types), not
        # with its folder: a copied-out file has no metadata.yaml, and the folder may hold
        # another bag.
        try:
            self._reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
            self._reader.open()
        except (AnyReaderError, OSError, ValueError, KeyError) as exc:
            raise UsageError(f"--source {self.spec!r}: cannot read the bag ({exc})") from None
        images = {c.topic: c for c in self._reader.connections if c.msgtype in IMAGE_TYPES}
        if topic is None:
            if not images:
                self.close()
                raise UsageError(
                    f"bag {str(path)!r} has no sensor_msgs/Image or CompressedImage topic"
                )
            if len(images) > 1 and _DEFAULT_TOPIC not in images:
                self.close()
                raise UsageError(
                    f"bag {str(path)!r} has several image topics ("
                    + ", ".join(sorted(images))
                    + f"); pick one with "
                    f"bag:{path}:TOPIC"
                )
            topic = next(iter(images)) if len(images) == 1 else _DEFAULT_TOPIC
        if topic not in images:
            known = {c.topic: c.msgtype for c in self._reader.connections}
            self.close()
            if topic in known:
                raise UsageError(
                    f"topic {topic} of bag {str(path)!r} holds {known[topic]}, not images"
                )
            raise UsageError(
                f"bag {str(path)!r} has no topic {topic}; image topics: "
                + (", ".join(sorted(images)) or "none")
            )
        self.topic, self._path = topic, path
        self._connections = [c for c in self._reader.connections if c.topic == topic]
        if sum(c.msgcount for c in self._connections) == 0:
            self.close()
            raise UsageError(f"topic {topic} of bag {str(path)!r} has no messages")
        self._stamps = []
        # Every image the run will take is checked now and the first one decoded: an image
        # it cannot read is reported before anything is written, not after a part of the run.
        messages = islice(self._reader.messages(connections=self._connections), max_frames)
        for k, (conn, _, raw) in enumerate(messages):
            msg = self._reader.deserialize(raw, conn.msgtype)
            try:
                (decode_image if k == 0 else check_image)(msg, conn.msgtype)
            except UsageError as exc:
                self.close()
                raise self._unreadable(k, exc) from None

    def _unreadable(self, k, exc):
        """The error for frame ``k``, which cannot be read: it says which, and how to run
        the frames before it."""
        cut = f"; --max-frames {k} runs the frames before it" if k else ""
        return UsageError(f"bag {str(self._path)!r} topic {self.topic}, frame {k}: {exc}{cut}")

    def frame_time(self, k):
        """Seconds from the first frame to frame ``k`` (by the bag's times)."""
        return (self._stamps[k] - self._stamps[0]) / 1e9

    def __iter__(self):
        reader = self._reader
        for k, (conn, stamp, raw) in enumerate(reader.messages(connections=self._connections)):
            msg = reader.deserialize(raw, conn.msgtype)
            try:
                bgr = decode_image(msg, conn.msgtype)
            except UsageError as exc:  # a CompressedImage: decoded only now
                raise self._unreadable(k, exc) from None
            self._stamps.append(stamp)
            yield to_design_rgb(bgr, self.width, self.height)

    def close(self):
        if self._reader is not None:
            self._reader.close()
            self._reader = None
