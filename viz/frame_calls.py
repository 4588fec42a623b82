"""A frame's direct rerun calls, held until the frame is complete and then made at once.

``Recorder.log_frame`` buffers most rows (``viz.columns``) and drops the rows of a frame cut
short by Ctrl-C; the 3D world, the LIDAR scans and the events are logged with ``stream.log``.
Made as they are computed, a Ctrl-C in the middle of a frame left that frame in the file in
part (the camera pose and the robot, without the rest). ``FrameCalls`` stands in for the
stream while the frame is computed and ``replay`` makes its calls once nothing is left to
compute, so an interrupted frame leaves nothing of itself.
"""

__all__ = ["FrameCalls"]


class FrameCalls:
    """Records ``set_time`` and ``log`` calls; ``replay(stream)`` makes them on ``stream``."""

    def __init__(self):
        self._calls = []

    def set_time(self, *args, **kwargs):
        self._calls.append(("set_time", args, kwargs))

    def log(self, *args, **kwargs):
        self._calls.append(("log", args, kwargs))

    def __bool__(self):
        return bool(self._calls)

    def replay(self, stream):
        calls, self._calls = self._calls, []
        for name, args, kwargs in calls:
            getattr(stream, name)(*args, **kwargs)
