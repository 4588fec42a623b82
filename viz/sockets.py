"""Cut the TCP connections rerun opened for a sink, so that closing it cannot hang.

rerun's gRPC client waits without limit, on disconnect and at interpreter exit, for a peer that
stopped reading (a stalled viewer, a port that accepts and never answers). The SDK has no way
to abort it; shutting its socket down does: the client sees the connection fail, gives up and
returns at once. The sockets are found among this process's file descriptors (``/proc/self/fd``
on Linux, ``/dev/fd`` elsewhere): the TCP ones opened after ``Connections`` was created that
lead to the given port (and host). Where descriptors cannot be listed, nothing is cut.

They also tell whether the connection lasted: rerun's client opens one connection and never
reconnects, and a rerun sink that tees to a file only *logs* a failed gRPC flush, so a
connection still open at the end is the sign that the viewer got everything.
"""

import os
import socket
import stat

__all__ = ["Connections"]


def _fd_folder():
    for folder in ("/proc/self/fd", "/dev/fd"):
        if os.path.isdir(folder):
            return folder
    return None


def _duplicate(fd):
    """A socket object on a duplicate of ``fd`` (closing it leaves ``fd`` open), or None."""
    try:
        dup_fd = os.dup(fd)
    except OSError:
        return None
    try:
        return socket.socket(fileno=dup_fd)
    except OSError:
        os.close(dup_fd)
        return None


def _tcp_sockets():
    """``{(fd, inode): (local, peer)}`` of this process's TCP sockets (peer None if unconnected)."""
    folder = _fd_folder()
    found = {}
    if folder is None:
        return found
    try:
        names = os.listdir(folder)
    except OSError:
        return found
    for name in names:
        try:
            fd = int(name)
            st = os.fstat(fd)
        except (ValueError, OSError):
            continue
        if not stat.S_ISSOCK(st.st_mode):
            continue
        dup = _duplicate(fd)
        if dup is None:
            continue
        with dup:
            if dup.family not in (socket.AF_INET, socket.AF_INET6):
                continue
            if dup.type != socket.SOCK_STREAM:
                continue
            try:
                local = dup.getsockname()[:2]
            except OSError:
                continue
            try:
                peer = dup.getpeername()[:2]
            except OSError:
                peer = None
        found[(fd, st.st_ino)] = (local, peer)
    return found


def _addresses(host):
    try:
        return {info[4][0] for info in socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)}
    except OSError:
        return None  # unknown: match on the port alone


class Connections:
    """The TCP sockets this process opens from now on to ``host:port`` (a client), or on local
    ``port`` (a server: ``host=None``)."""

    def __init__(self, port, host=None):
        self.port = port
        self._peers = _addresses(host) if host is not None else None
        self._client = host is not None
        self._before = set(_tcp_sockets())

    def _ours(self, local, peer):
        if not self._client:
            return local[1] == self.port
        if peer is None or peer[1] != self.port:
            return False
        return self._peers is None or peer[0] in self._peers

    def alive(self):
        """How many such sockets are still connected, with no end of stream from the peer."""
        count = 0
        for (fd, ino), (local, peer) in _tcp_sockets().items():
            if (fd, ino) in self._before or peer is None or not self._ours(local, peer):
                continue
            dup = _duplicate(fd)
            if dup is None:
                continue
            with dup:
                try:  # a peek at the stream: b"" is the peer's end; nothing to read is fine
                    ended = dup.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
                except BlockingIOError:
                    ended = False
                except OSError:
                    ended = True
            count += not ended
        return count

    def sever(self):
        """Shut down every such socket opened since; returns how many were cut."""
        cut = 0
        for (fd, ino), (local, peer) in _tcp_sockets().items():
            if (fd, ino) in self._before or not self._ours(local, peer):
                continue
            dup = _duplicate(fd)
            if dup is None:
                continue
            with dup:
                try:
                    dup.shutdown(socket.SHUT_RDWR)  # acts on the socket, whichever descriptor
                    cut += 1
                except OSError:
                    pass
        return cut
