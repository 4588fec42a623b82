"""Ending a stream that goes to a viewer (or serves one) without ever waiting long.

rerun's ``flush`` and ``disconnect`` run in its native code, where the process neither sees
Ctrl-C nor gives up on a peer that stopped reading. Each is run here in a helper thread while
the caller waits on an event (which Ctrl-C does interrupt), at most ``FLUSH_TIMEOUT_S`` and
``DISCONNECT_TIMEOUT_S``; a client that still hangs has its sockets cut (``viz.sockets``) and
then returns. Links still open when the interpreter exits are cut too, before rerun's own exit
hook would wait on them forever.
"""

import atexit
import threading
import weakref

__all__ = ["DISCONNECT_TIMEOUT_S", "FLUSH_TIMEOUT_S", "BoundedCall", "LiveLink"]

#: How long the data still queued at the end may take to reach the viewer.
FLUSH_TIMEOUT_S = 10.0
#: How long closing the connections (and writing the file's footer) may take.
DISCONNECT_TIMEOUT_S = 5.0

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


class LiveLink:
    """The network side of a stream: its rerun sockets (``viz.sockets.Connections``)."""

    def __init__(self, connections, what, *, check_delivery=True):
        self.connections = connections
        self.what = what  # e.g. "the rerun viewer at rerun+http://..."
        self.check_delivery = check_delivery  # a client: its connection must last to the end
        self.closed = False
        _OPEN.add(self)

    def finish(self, stream):
        """Flush then disconnect ``stream`` in bounded time.

        Returns ``(confirmed, problem)``: ``confirmed`` when rerun reported every message
        sent and the connection closed; else ``problem`` says what went wrong.
        """
        try:
            problem = None
            flush = BoundedCall(lambda: stream.flush(timeout_sec=FLUSH_TIMEOUT_S), "viz-flush")
            if not flush.wait(FLUSH_TIMEOUT_S + 1.0) or flush.error is not None:
                problem = f"{self.what} did not take all the data within {FLUSH_TIMEOUT_S:g} s"
                if flush.error is not None and "timed out" not in str(flush.error).lower():
                    problem = f"{self.what} failed ({flush.error})"
                # Otherwise rerun's disconnect would wait for that peer forever.
                self.connections.sever()
            elif self.check_delivery and not self.connections.alive():
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
            self.closed = True
            _OPEN.discard(self)

    def abort(self, stream):
        """After an interrupt: cut the network side, then let rerun write out the rest (the
        file copy) within ``DISCONNECT_TIMEOUT_S``."""
        try:
            self.connections.sever()
            BoundedCall(stream.disconnect, "viz-disconnect").wait(DISCONNECT_TIMEOUT_S)
        finally:
            self.closed = True
            _OPEN.discard(self)


@atexit.register
def _cut_open_links():
    # Registered after rerun's import, so it runs before rerun's exit hook (atexit is LIFO).
    for link in list(_OPEN):
        link.connections.sever()
