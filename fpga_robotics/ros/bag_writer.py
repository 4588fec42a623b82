"""``--bag PATH``: a run's frames as a ROS 2 bag (MCAP storage), written with ``rosbags``.

A display connector like the rerun recorder (``viz.recorder``): ``log_frame(record)`` for
every ``FrameRecord``, ``close()`` at the end. The bag is written into a hidden folder next to
``PATH`` and renamed to ``PATH`` only when complete (an existing bag there is replaced; anything
else found there then is left alone, and the bag stays in the hidden folder, as ``close()``
says); a run that fails or is interrupted leaves nothing behind (``abandon()``). The topics and
their types are ``messages.TOPICS`` (and a LIDAR's ``/<name>/scan``, ``laser_scan``); ``ros2 bag info PATH`` and Foxglove open the result.
"""

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.sim.files import check_output_dir

from .laser_scan import SCAN_TYPE, LaserScans
from .messages import TOPICS, TYPESTORE, FrameMessages, camera_geometry, topic_type

__all__ = ["BagWriter", "check_bag_path", "open_bag_writer"]


def _is_bag(path):
    return path.is_dir() and (path / "metadata.yaml").is_file()


def check_bag_path(path):
    """``PATH`` must be new, or a bag (a folder with ``metadata.yaml``) to replace, in a
    folder we can write; returns it as a ``Path``."""
    if path is None or str(path).strip() == "":
        raise UsageError("--bag: the path is empty; give a folder name for the bag")
    path = Path(path)
    if path.exists() and not _is_bag(path):
        what = "a folder that is not a ROS 2 bag" if path.is_dir() else "a file"
        raise UsageError(f"--bag {str(path)!r} exists and is {what}; give a new name")
    check_output_dir(path, what="--bag")  # a write is tried for real: os.access trusts root
    return path


class BagWriter:
    """Writes ``FrameRecord`` s to a ROS 2 bag at ``path`` (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The bag folder to create.
    geometry : messages.CameraGeometry
        Camera and robot geometry (``messages.camera_geometry(scenario)``).

    Attributes
    ----------
    frames_logged : int
    path : Path
    """

    def __init__(self, path, geometry):
        self.path = check_bag_path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._staging = Path(
            tempfile.mkdtemp(prefix=f".{self.path.name}.", suffix=".partial", dir=self.path.parent)
        )
        self._tmp = self._staging / self.path.name  # the .mcap inside is named after it
        self._messages = FrameMessages(geometry)
        self._writer = Writer(self._tmp, version=9, storage_plugin=StoragePlugin.MCAP)
        self._writer.open()
        self._connections = {
            topic: self._writer.add_connection(topic, msgtype, typestore=TYPESTORE)
            for topic, msgtype in TOPICS.items()
        }
        self._scans = LaserScans()  # a LIDAR's revolutions, on topics made when first seen
        self.frames_logged = 0
        self._notices = []

    def log_world_map(self, world_map):
        """Nothing: the bag carries the people and the robot, the room stays in the map."""

    def log_frame(self, record):
        write, conns = self._writer.write, self._connections
        for topic, ns, data in self._messages.encode(record):
            if topic not in conns:  # a further camera's or an extra output's, first seen now
                kind = self._messages.topic_types.get(topic) or topic_type(topic)
                conns[topic] = self._writer.add_connection(topic, kind, typestore=TYPESTORE)
            write(conns[topic], ns, data)
        for topic, ns, data in self._scans.encode(record):
            if topic not in conns:
                conns[topic] = self._writer.add_connection(topic, SCAN_TYPE, typestore=TYPESTORE)
            write(conns[topic], ns, data)
        self.frames_logged += 1

    def pop_notices(self):
        notices, self._notices = self._notices, []
        return notices

    def close(self):
        """Finish the bag and move it to ``path``; returns the line that says where it is."""
        if self._writer is None:
            return ""
        writer, self._writer = self._writer, None
        try:
            writer.close()
        except BaseException:
            shutil.rmtree(self._staging, ignore_errors=True)
            raise
        # Checked again now: something other than a bag may have been written there meanwhile.
        if (self.path.exists() or self.path.is_symlink()) and not _is_bag(self.path):
            return (
                f"ROS 2 bag ({self.frames_logged} frames) kept in {self._tmp}: {self.path} is "
                f"no longer a ROS 2 bag (something else was written there during the run), "
                f"so it was not replaced"
            )
        try:
            if self.path.exists():  # a bag from an earlier run: replaced only now
                os.replace(self.path, self._staging / "old")
            os.replace(self._tmp, self.path)
        finally:
            shutil.rmtree(self._staging, ignore_errors=True)
        return f"ROS 2 bag ({self.frames_logged} frames) written to {self.path}"

    def abandon(self):
        """Stop without a bag: the partial one is removed."""
        if self._writer is not None:
            writer, self._writer = self._writer, None
            with contextlib.suppress(OSError, WriterError):  # discarded either way
                writer.close()
        shutil.rmtree(self._staging, ignore_errors=True)


def open_bag_writer(path, scenario):
    """A ``BagWriter`` for the run of ``scenario`` (its camera and robot geometry)."""
    return BagWriter(path, camera_geometry(scenario))
