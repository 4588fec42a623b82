"""Ending a stream that goes to a viewer (or serves one) without ever waiting long.

rerun's ``flush`` and ``disconnect`` run in its native code, where the process neither sees
Ctrl-C nor gives up on a peer that stopped reading. Each is run here in a helper thread while
the caller waits on an event (which Ctrl-C does interrupt), at most ``FLUSH_TIMEOUT_S`` and
``DISCONNECT_TIMEOUT_S``; a client that still hangs has its sockets cut (``viz.sockets``) and
then returns. Links still open when the interpreter exits are cut too, before rerun's own exit
hook would wait on them forever.

During the run, rerun's queues are bounded (a few hundred MB): once a stalled viewer has let
them fill, every logging call blocks in native code. ``LiveLink.watch`` guards those calls: one
that waits longer than ``STALL_TIMEOUT_S`` gets the viewer cut off, rerun drops what was queued
for it, and the run (and the file copy) goes on.
"""

import atexit
import threading
import time
import weakref

__all__ = [
    "DISCONNECT_TIMEOUT_S",
    "FLUSH_TIMEOUT_S",
    "STALL_TIMEOUT_S",
    "BoundedCall",
    "LiveLink",
    "StallWatch",
]

#: How long the data still queued at the end may take to reach the viewer.
FLUSH_TIMEOUT_S = 10.0
#: How long closing the connections (and writing the file's footer) may take.
DISCONNECT_TIMEOUT_S = 5.0
#: How long one logging call may wait for a viewer before the viewer is cut off.
STALL_TIMEOUT_S = 5.0
_WATCH_PERIOD_S = 0.1

_OPEN = weakref.WeakSet()


class BoundedCall:
    """``fn()`` running in a daemon thread; ``wait(timeout)`` says whether it has returned."""

    def __init__(self, fn, name):
        self.error = None
        self._done = threading.Event()
        threading.Thread(target=self._run, args=(fn,), name=name, daemon=True).start()

    def _run(self, fn):
        try:
            fn()
        except Exception as exc:  # noqa: BLE001 - handed to the caller
            self.error = exc
        finally:
            self._done.set()

    def wait(self, timeout):
        return self._done.wait(timeout)


class StallWatch:
    """``with watch:`` around a logging call; a call still waiting after ``STALL_TIMEOUT_S``
    has ``on_stall()`` run from the watch's own thread (the caller is stuck in native code)."""

    def __init__(self, on_stall):
        self.stalled = False
        self._on_stall = on_stall
        self._since = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="viz-stall-watch", daemon=True)
        self._thread.start()

    def __enter__(self):
        self._since = time.monotonic()
        return self

    def __exit__(self, *exc):
        self._since = None
        return False

    def _run(self):
        while not self._stop.wait(_WATCH_PERIOD_S):
            since = self._since
            if since is not None and time.monotonic() - since > STALL_TIMEOUT_S:
                self.stalled = True
                self._on_stall()
                return  # once cut off, the link never blocks again

    def stop(self):
        self._stop.set()


class LiveLink:
    """The network side of a stream: its rerun sockets (``viz.sockets.Connections``)."""

    def __init__(self, connections, what, *, check_delivery=True):
        self.connections = connections
        self.what = what  # e.g. "the rerun viewer at rerun+http://..."
        self.check_delivery = check_delivery  # a client: its connection must last to the end
        self.closed = False
        self.watch = StallWatch(self.connections.sever)
        _OPEN.add(self)

    def finish(self, stream):
        """Flush then disconnect ``stream`` in bounded time.

        Returns ``(confirmed, problem)``: ``confirmed`` when rerun reported every message
        sent and the connection closed; else ``problem`` says what went wrong.
        """
        try:
            problem = None
            if self.watch.stalled:
                problem = (
                    f"{self.what} stopped taking data for {STALL_TIMEOUT_S:g} s during the run "
                    "and was cut off"
                )
            flush = BoundedCall(lambda: stream.flush(timeout_sec=FLUSH_TIMEOUT_S), "viz-flush")
            if not flush.wait(FLUSH_TIMEOUT_S + 1.0) or flush.error is not None:
                if flush.error is not None and "timed out" not in str(flush.error).lower():
                    problem = problem or f"{self.what} failed ({flush.error})"
                problem = (
                    problem or f"{self.what} did not take all the data within {FLUSH_TIMEOUT_S:g} s"
                )
                # Otherwise rerun's disconnect would wait for that peer forever.
                self.connections.sever()
            elif problem is None and self.check_delivery and not self.connections.alive():
                # rerun only logs a lost connection when it also writes a file: look ourselves.
                problem = f"the connection to {self.what} was lost during the run"
            disconnect = BoundedCall(stream.disconnect, "viz-disconnect")
            if not disconnect.wait(DISCONNECT_TIMEOUT_S):
                self.connections.sever()
                if not disconnect.wait(DISCONNECT_TIMEOUT_S):
                    problem = problem or f"the connection to {self.what} did not close"
            if not self.check_delivery:
                # A stopped rerun server keeps the connections it accepted: end them too.
                self.connections.sever()
            return problem is None, problem
        finally:
            self._end()

    def _end(self):
        self.watch.stop()
        self.closed = True
        _OPEN.discard(self)

    def abort(self, stream):
        """After an interrupt: cut the network side, then let rerun write out the rest (the
        file copy) within ``DISCONNECT_TIMEOUT_S``."""
        try:
            self.connections.sever()
            BoundedCall(stream.disconnect, "viz-disconnect").wait(DISCONNECT_TIMEOUT_S)
        finally:
            self._end()


@atexit.register
def _cut_open_links():
    # Registered after rerun's import, so it runs before rerun's exit hook (atexit is LIFO).
    for link in list(_OPEN):
        link.connections.sever()
