"""The camera frames of a closed-loop run written as a video, so that ``run --source`` can be
tried on footage at once (``run --save-video clip.mp4``, then ``run --source clip.mp4``).

A frame of an odd width or height gets its last column or row twice (the codecs take even
sizes). Written under a hidden temporary name and renamed when the run ends; an interrupted
or failed run leaves no file. Video codecs are lossy: the design on the replayed clip sees
nearly, not exactly, the frames of the run.
"""

from contextlib import ExitStack

import cv2
import numpy as np

from fpga_robotics.hw.errors import UserError
from fpga_robotics.sim.files import atomic_path, check_output_path

__all__ = ["VIDEO_CODECS", "CameraVideo", "VideoPathError", "check_video_path"]

#: File suffix -> OpenCV FourCC of a codec that OpenCV's own build writes everywhere.
VIDEO_CODECS = {".mp4": "mp4v", ".avi": "MJPG"}


class VideoPathError(UserError, ValueError):
    """A video path with a suffix no codec is known for."""


def check_video_path(path):
    """Raise ``VideoPathError``/``OutputPathError`` unless ``path`` can take a video."""
    path = check_output_path(path, what="--save-video")
    if path.suffix.lower() not in VIDEO_CODECS:
        raise VideoPathError(
            f"--save-video {str(path)!r}: give a file ending in {' or '.join(VIDEO_CODECS)}"
        )
    return path


class CameraVideo:
    """``with CameraVideo(path, fps) as video: video.write(rgb)`` for each RGB888 frame."""

    def __init__(self, path, fps):
        self.path = check_video_path(path)
        self.fps = float(fps)
        self._stack = ExitStack()
        self._writer = None
        self.frames = 0

    def __enter__(self):
        self._tmp = self._stack.enter_context(atomic_path(self.path, what="--save-video"))
        return self

    def write(self, rgb):
        # The codecs take even sizes only (OpenCV would drop an odd last row or column):
        # repeat the last one instead, so that the video holds every pixel of the frame.
        height, width = rgb.shape[:2]
        if height % 2 or width % 2:
            rgb = np.pad(rgb, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
            height, width = rgb.shape[:2]
        if self._writer is None:  # the size is known with the first frame
            fourcc = cv2.VideoWriter_fourcc(*VIDEO_CODECS[self.path.suffix.lower()])
            self._writer = cv2.VideoWriter(str(self._tmp), fourcc, self.fps, (width, height))
            if not self._writer.isOpened():
                raise OSError(f"OpenCV cannot write {self.path.suffix} video here")
        self._writer.write(rgb[:, :, ::-1].copy())  # OpenCV wants BGR
        self.frames += 1

    def __exit__(self, *exc):
        if self._writer is not None:
            self._writer.release()
        return self._stack.__exit__(*exc)
