"""A frame's direct rerun calls, held until the frame is complete and then made at once.

``Recorder.log_frame`` buffers most rows (``viz.columns``) and drops the rows of a frame cut
short by Ctrl-C; the 3D world, the LIDAR scans and the events are logged with ``stream.log``.
Made as they are computed, a Ctrl-C in the middle of a frame left that frame in the file in
part (the camera pose and the robot, without the rest). ``FrameCalls`` stands in for the
stream while the frame is computed and ``replay`` makes its calls once nothing is left to
compute, with Ctrl-C and SIGTERM held (``signals_held``) until the last one is made and the
frame counted, so an interrupted frame leaves nothing of itself.
"""

import contextlib
import signal
import threading

__all__ = ["FrameCalls", "signals_held"]


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
        """Make the calls on ``stream`` (inside ``signals_held`` for them to be whole)."""
        calls, self._calls = self._calls, []
        for name, args, kwargs in calls:
            getattr(stream, name)(*args, **kwargs)


#: The signals a run ends on (Ctrl-C, and SIGTERM, which the commands turn into an exception).
_HELD = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_held():
    """Ctrl-C or SIGTERM arriving inside the block takes effect at its end. ``rr.log`` runs
    a good deal of Python (the archetype to Arrow), so a signal lands inside the calls often;
    the calls are non-blocking, so holding it costs no wait. Only the main thread has signal
    handlers: elsewhere the block runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived = []
    previous = {}
    try:
        for signum in _HELD:
            if signal.getsignal(signum) is None:  # set outside Python: cannot be put back
                continue
            previous[signum] = signal.signal(signum, lambda n, f: arrived.append((n, f)))
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    for signum, frame in arrived[:1]:  # as the handler in force would have at the time
        handler = previous[signum]
        if callable(handler):
            handler(signum, frame)
        elif handler == signal.SIG_DFL:
            signal.raise_signal(signum)
