"""Frames from outside the simulation: a camera, a video file, a folder of images or the
images of a ROS bag (``fpga_robotics.ros.bag_source``).

``open_source(spec, width, height)`` yields RGB888 frames at the design's resolution, resized
with ``cv2.resize`` (``INTER_LINEAR``) and converted from OpenCV's BGR order. ``run_source``
runs the design on each frame (no physics) and reports what it found.
"""

import math
import os
import time
from itertools import islice
from pathlib import Path

import cv2

from fpga_robotics.cli.errors import Terminated
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.pixel import color_select_value
from fpga_robotics.sim.camera.opencv_frames import to_design_rgb
from fpga_robotics.sim.records import FrameRecord
from fpga_robotics.sim.world.kinematics import dps_to_twist
from fpga_robotics.sim.world.robots import TURTLEBOT2

__all__ = ["IMAGE_SUFFIXES", "FrameSource", "open_source", "run_source", "to_design_rgb"]

#: Files of a folder source that are read as frames (in sorted name order).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm", ".pgm")
#: FFmpeg's log level that prints nothing (AV_LOG_QUIET).
_AV_LOG_QUIET = -8
#: The per-frame outputs ``run_source`` reports besides ``found``.
_OUTPUTS = ("proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right")


class FrameSource:
    """An opened source of frames; iterate it for RGB888 (height, width, 3) uint8 frames.

    Parameters
    ----------
    spec : str
        ``camera:N`` (OpenCV device N), a video file, a folder of images or one image.
    width, height : int
        The design's resolution; every frame is resized to it.
    fps : float, optional
        The frame rate of a folder of images and of a video that states none; frames are
        stamped ``k / fps`` (``frame_time``), a video's at the rate it states.
    """

    def __init__(self, spec, width, height, fps=None):
        self.spec = str(spec)
        self.width, self.height = width, height
        self.kind = None
        self._cap = None
        self._files = None
        self._fps = fps
        if self.spec.startswith("camera:"):
            index = self.spec[len("camera:") :]
            if not index.isdigit():
                raise UsageError(f"--source camera:N needs a device number, got {self.spec!r}")
            self.kind = "camera"
            self._fps = None  # a camera's frames come when they come: stamped as read
            # OpenCV's own warnings would print before our message; keep only its errors.
            cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)
            self._cap = cv2.VideoCapture(int(index))
            if not self._cap.isOpened():
                self._cap.release()
                raise UsageError(
                    f"cannot open camera {index} ({self.spec}); check that it is connected and "
                    f"not used by another program, or give a video file or image folder"
                )
            return
        path = Path(self.spec)
        if path.is_dir():
            self.kind = "folder"
            self._files = sorted(
                p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file()
            )
            if not self._files:
                raise UsageError(
                    f"folder {self.spec!r} holds no images ({', '.join(IMAGE_SUFFIXES)})"
                )
            return
        if not path.exists():
            raise UsageError(
                f"--source {self.spec!r}: no such file or folder (give camera:N, a video file "
                f"or a folder of images)"
            )
        if path.suffix.lower() in IMAGE_SUFFIXES:  # one image: one frame, read as a folder's
            self.kind = "image"
            self._files = [path]
            if cv2.imread(str(path), cv2.IMREAD_UNCHANGED) is None:
                raise UsageError(f"cannot read image {self.spec!r}: OpenCV cannot decode it")
            return
        self.kind = "video"
        # FFmpeg would print its own complaint ("moov atom not found") on stderr before the
        # one line below says the file cannot be read; OPENCV_FFMPEG_LOGLEVEL set by the user
        # (to debug a codec) stays theirs. Read once, when OpenCV first starts FFmpeg.
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", str(_AV_LOG_QUIET))
        self._cap = cv2.VideoCapture(str(path))
        ok = self._cap.isOpened()
        if ok:
            ok, first = self._cap.read()
        if not ok:
            self._cap.release()
            raise UsageError(f"cannot read video {self.spec!r}: OpenCV cannot decode it")
        self._first = first
        stated = self._cap.get(cv2.CAP_PROP_FPS)
        if stated > 0 and math.isfinite(stated):
            self._fps = stated

    def frame_time(self, k):
        """Seconds from the first frame to frame ``k`` (``k / fps``); None for a camera,
        or without a frame rate."""
        return None if self._fps is None else k / self._fps

    def _convert(self, bgr):
        return to_design_rgb(bgr, self.width, self.height)

    def __iter__(self):
        if self.kind in ("folder", "image"):
            for p in self._files:
                img = cv2.imread(str(p), cv2.IMREAD_UNCHANGED)
                if img is None:
                    raise UsageError(f"cannot read image {p}: OpenCV cannot decode it")
                yield self._convert(img)
            return
        if self.kind == "video" and self._first is not None:
            first, self._first = self._first, None
            yield self._convert(first)
        while True:
            ok, bgr = self._cap.read()
            if not ok:
                return
            yield self._convert(bgr)

    def close(self):
        if self._cap is not None:
            self._cap.release()
            self._cap = None


def open_source(spec, width, height, max_frames=None, fps=None):
    """Open ``spec`` (``camera:N``, a video file, a folder of images, one image,
    ``bag:PATH[:TOPIC]``) at ``width`` x ``height``; ``UsageError`` when it cannot be opened.
    A bag's images are all checked now (the first ``max_frames`` of them, when given); ``fps``
    is the frame rate of a folder of images and of a video that states none."""
    if str(spec).startswith("bag:"):  # a ROS bag (fpga_robotics.ros.bag_source)
        from fpga_robotics.ros.bag_source import BagSource  # lazy: rosbags (~30 ms), for bags only

        return BagSource(spec, width, height, max_frames)
    return FrameSource(spec, width, height, fps)


def run_source(
    source,
    design,
    *,
    color="red",
    recorder=None,
    progress=None,
    max_frames=None,
    duration=None,
    hfov=1.047,
    robot=TURTLEBOT2,
    on_frame=None,
):
    """Run the design on every frame of ``source`` and summarise its outputs.

    Returns a JSON-ready dict: the source, frame count, timing, how often the target was
    found, and the per-frame outputs (``results``). ``on_frame(FrameRecord)`` is called for
    every frame; a source with frame times (``frame_time(k)``: a bag's, a video's or a
    folder's) stamps the frames with them, a camera with the wall time since the start. The frames' commanded twist
    (``cmd_v``, ``cmd_w``) is the design's DPS through ``robot``'s wheels (a ``RobotSpec``:
    the scenario's robot, as ``/cmd_vel`` in a bag); nothing moves, so the measured one is 0.
    """
    sel = color_select_value(color)
    design.reset()
    results = []
    start = time.perf_counter()
    design_time = 0.0
    was_found = False
    try:
        # islice: no frame past the last is read (a bag checked only that far, a camera).
        for k, rgb in enumerate(islice(source, max_frames)):
            if duration is not None and time.perf_counter() - start >= duration:
                break
            t0 = time.perf_counter()
            result = design.process_frame(rgb, sel)
            design_time += time.perf_counter() - t0
            events = []
            if result.found != was_found:
                events.append("target found" if result.found else "target lost")
                was_found = bool(result.found)
            # An output the design lacks (a design of one's own, a port map) is None.
            row = {
                "frame": k,
                "found": bool(result.found),
                **{
                    name: None if getattr(result, name) is None else int(getattr(result, name))
                    for name in _OUTPUTS
                },
            }
            if result.extra:  # a design of one's own: its outputs no connector reads
                row["extra"] = {name: int(value) for name, value in result.extra.items()}
            results.append(row)
            if recorder is not None or on_frame is not None:
                stamp = source.frame_time(k) if hasattr(source, "frame_time") else None
                if stamp is None:  # a camera: the time it was read
                    stamp = time.perf_counter() - start
                cmd_v, cmd_w = dps_to_twist(
                    int(result.motor_left or 0),
                    int(result.motor_right or 0),
                    robot.wheel_radius,
                    robot.wheel_separation,
                )
                record = FrameRecord(
                    frame=k,
                    sim_time=stamp,
                    camera_rgb=rgb,
                    color_sel=sel,
                    result=result,
                    robot_x=0.0,
                    robot_y=0.0,
                    robot_heading=0.0,
                    robot_v=0.0,
                    robot_w=0.0,
                    cmd_v=cmd_v,
                    cmd_w=cmd_w,
                    camera_hfov=hfov,
                    events=events,
                    design_extra=result.extra or {},
                )
                if recorder is not None:
                    recorder.log_frame(record)
                if on_frame is not None:
                    on_frame(record)
            if progress is not None:
                progress(k + 1, None)
    except KeyboardInterrupt as exc:
        # A camera runs until Ctrl-C: report what was seen. A finite source cut off, or any
        # source terminated (SIGTERM), ends as an interrupted closed loop does.
        if source.kind != "camera" or isinstance(exc, Terminated):
            raise
    wall = time.perf_counter() - start
    n = len(results)
    found = sum(r["found"] for r in results)
    proximity = [r["proximity"] for r in results if r["proximity"] is not None]
    # The last, smallest and largest value of each, as a closed-loop run's summary has them.
    seen = {}
    for r in results:
        for name, value in r.get("extra", {}).items():
            seen.setdefault(name, []).append(value)
    extra = {name: {"last": v[-1], "min": min(v), "max": max(v)} for name, v in seen.items()}
    return {
        "source": source.spec,
        "source_kind": source.kind,
        "backend": design.name,
        "resolution": f"{design.params.width}x{design.params.height}",
        "color": color if isinstance(color, str) else int(color),
        "frames": n,
        "wall_time_s": round(wall, 4),
        "ms_per_frame": round(1000.0 * wall / n, 4) if n else None,
        "design_ms_per_frame": round(1000.0 * design_time / n, 4) if n else None,
        "found_frames": found,
        "found_fraction": round(found / n, 4) if n else 0.0,
        "mean_proximity": round(sum(proximity) / len(proximity), 4) if proximity else None,
        **({"extra_outputs": extra} if extra else {}),
        "results": results,
    }
