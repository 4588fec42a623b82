"""Open the ``rerun.RecordingStream`` a ``Mode`` asks for, and end it in bounded time.

- ``save``: the stream goes to a ``RecordingFile``.
- ``spawn`` / ``connect``: the viewer is first asked to answer (``net.probe_viewer``); the
  stream then goes to it *and* to a copy on the default path. The copy is deleted at the end
  only when rerun confirms that every message was sent; otherwise it is kept and the user is
  told where.
- ``serve``: a gRPC server on ``mode.bind`` (127.0.0.1 unless told), the web viewer on the
  same address (a ``rerun --serve-web`` child), and a copy on the default path, always kept
  (nobody confirms receiving a served stream).

A live sink that cannot work here (no display, no viewer answering, a port that cannot be
served) is not an error when there is a default path: the recording goes to that file
instead, and the first notice says why. Without a default path it is a ``ViewerError``.
"""

import contextlib
import ipaddress
import time
import uuid
from datetime import timedelta
from urllib.parse import quote

import rerun as rr

from fpga_robotics.hw.errors import UserError

from .errors import ViewerError
from .live import DISCONNECT_TIMEOUT_S, FLUSH_TIMEOUT_S, BoundedCall, LiveLink
from .modes import DEFAULT_VIEWER_PORT, DEFAULT_WEB_PORT, display_available
from .net import free_port, port_is_free, port_is_listening, probe_viewer, url_address
from .outfile import RecordingFile
from .sockets import Connections
from .viewers import ViewerUnavailable, start_viewer, start_web_viewer, stop_process

__all__ = ["Output", "open_output"]

_LOCALHOST = "127.0.0.1"
#: The port ``spawn`` uses (rerun's default); tests point it elsewhere.
VIEWER_PORT = DEFAULT_VIEWER_PORT
#: The ports ``serve`` prefers (rerun's defaults); taken ones are replaced by free ports.
SERVE_GRPC_PORT = DEFAULT_VIEWER_PORT
SERVE_WEB_PORT = DEFAULT_WEB_PORT
#: How long a gRPC server we start may take to listen.
SERVE_LISTEN_TIMEOUT_S = 5.0


class Output:
    """Where an open stream goes, and how to end it.

    Attributes
    ----------
    kind : str
        ``save``, ``spawn``, ``connect`` or ``serve``: the sink in use.
    file : RecordingFile or None
        The file written (``save``), or the copy beside a live sink.
    description : str
        The live sink, for messages ("the rerun viewer at URL").
    reason : str or None
        Why the requested live sink was replaced by the file, if it was.
    opening : list of str
        What the user must be told now (where to watch, why a file is used instead).
    keep_copy : bool
        Keep ``file`` even when delivery is confirmed (``serve``).
    """

    def __init__(self, kind, file, *, description="", reason=None, link=None, keep_copy=False):
        self.kind = kind
        self.file = file
        self.description = description
        self.reason = reason
        self.link = link
        self.keep_copy = keep_copy
        self.opening = []
        self.viewer_pid = self.live_url = self.web_url = None
        self.processes = []  # started here, stopped at the end

    def guard(self):
        """The context to enter around every logging call (a stall watch for live sinks)."""
        return self.link.watch if self.link is not None else contextlib.nullcontext()

    def finish(self, stream):
        """End the stream in bounded time; returns ``(confirmed, problem)``."""
        try:
            if self.link is not None:
                return self.link.finish(stream)
            return _finish_file_only(stream)
        finally:
            for proc in self.processes:
                stop_process(proc)

    def close_abandoned(self, stream):
        """For a recorder dropped (or still open at exit) without ``close()``: end the stream
        and give the file its real name all the same; nobody is left to tell."""
        confirmed = False
        try:
            confirmed, _problem = self.finish(stream)
        finally:
            if self.file is not None:
                if confirmed and self.kind != "save" and not self.keep_copy:
                    self.file.discard()
                else:
                    self.file.keep()

    def abort(self, stream):
        """End the stream at once after an interrupt, writing out what it holds (bounded)."""
        try:
            if self.link is not None:
                self.link.abort(stream)
            else:
                _abort_file_only(stream)
        finally:
            for proc in self.processes:
                stop_process(proc)


def _abort_file_only(stream):
    BoundedCall(stream.disconnect, "viz-disconnect").wait(DISCONNECT_TIMEOUT_S)


def _finish_file_only(stream):
    flush = BoundedCall(lambda: stream.flush(timeout_sec=FLUSH_TIMEOUT_S), "viz-flush")
    if not flush.wait(FLUSH_TIMEOUT_S + 1.0) or flush.error is not None:
        return False, f"the file was not fully written ({flush.error or 'timed out'})"
    if not BoundedCall(stream.disconnect, "viz-disconnect").wait(DISCONNECT_TIMEOUT_S):
        return False, "the file was not closed in time"
    return True, None


def _file_batcher():
    # The rows of ``rr.log`` calls (the 3D world: 4 entities a frame) batched by count, about
    # 128 frames a chunk, like the columns (viz.columns.FILE_ONLY); no time limit.
    return rr.ChunkBatcherConfig(
        flush_tick=timedelta(days=1), flush_num_bytes=8 << 20, flush_num_rows=512
    )


class SinkUnavailable(UserError, RuntimeError):
    """The requested live sink cannot work here; the message says why."""


def new_stream(app_id, file_only=False):
    # One stream per recorder, never the global one; no wall-clock timeline, so a recording
    # depends only on the run. A file nobody watches live is batched by rows alone, never
    # by time: longer chunks, a smaller file, and the same chunks on any machine.
    config = _file_batcher() if file_only else None
    stream = rr.RecordingStream(app_id, recording_id=uuid.uuid4(), batcher_config=config)
    stream.set_log_time_enabled(False)
    return stream


def _file_sink(file):
    return [rr.FileSink(str(file.temp))] if file is not None else []


def _attach_live(stream, url, file, description):
    host, port, _tls = url_address(url)
    connections = Connections(port, host)  # before the client exists: its sockets are new
    stream.set_sinks(rr.GrpcSink(url), *_file_sink(file))
    return LiveLink(connections, description)


def _spawn(stream, mode, file):
    port = VIEWER_PORT
    url = f"rerun+http://{_LOCALHOST}:{port}/proxy"
    pid = None
    if port_is_listening(_LOCALHOST, port):
        reason = probe_viewer(url)
        if reason:
            raise SinkUnavailable(f"port {port} is taken by something else: {reason}")
        description = f"the rerun viewer already running on port {port}"
    else:
        if not display_available():
            raise SinkUnavailable(
                "no display to open a viewer window (DISPLAY and WAYLAND_DISPLAY unset)"
            )
        try:
            proc = start_viewer(port)
        except ViewerUnavailable as exc:
            raise SinkUnavailable(str(exc)) from None
        reason = probe_viewer(url)
        if reason:
            stop_process(proc)
            raise SinkUnavailable(f"the rerun viewer started, but {reason}")
        pid = proc.pid
        description = f"a new rerun viewer (pid {pid}, port {port})"
    out = Output("spawn", file, description=description)
    out.link = _attach_live(stream, url, file, description)
    out.viewer_pid, out.live_url = pid, url
    return out


def _connect(stream, mode, file):
    reason = probe_viewer(mode.url)
    if reason:
        raise SinkUnavailable(reason)
    description = f"the rerun viewer at {mode.url}"
    out = Output("connect", file, description=description)
    out.link = _attach_live(stream, mode.url, file, description)
    out.live_url = mode.url
    return out


def _serve_port(bind, preferred):
    # rerun's default ports may be taken by another run or viewer: then any free port.
    return preferred if port_is_free(bind, preferred) else free_port(bind)


def _local_host(bind):
    # Where this machine reaches a server bound to ``bind`` (any-address binds: loopback).
    return {"0.0.0.0": _LOCALHOST, "::": "::1"}.get(bind, bind)


def _serve(stream, mode, file):
    bind, host = mode.bind, _local_host(mode.bind)
    grpc_port = _serve_port(bind, SERVE_GRPC_PORT)
    connections = Connections(grpc_port)  # the server's own sockets
    # rerun's GrpcServerSink reports a port it cannot bind only in its log: check it listens.
    stream.set_sinks(rr.GrpcServerSink(bind_ip=bind, port=grpc_port), *_file_sink(file))
    link = LiveLink(connections, f"the gRPC server on {bind}:{grpc_port}", check_delivery=False)
    if not _wait_listening(host, grpc_port):
        link.finish(stream)
        raise SinkUnavailable(f"could not serve gRPC on {bind}:{grpc_port}")
    url_host = f"[{host}]" if ":" in host else host
    url = f"rerun+http://{url_host}:{grpc_port}/proxy"
    out = Output("serve", file, description=f"served live at {url}", link=link, keep_copy=True)
    out.live_url = url
    web_port = _serve_port(bind, SERVE_WEB_PORT)
    try:
        out.processes.append(start_web_viewer(bind, web_port, url, host))
        out.web_url = f"http://{url_host}:{web_port}/?url={quote(url, safe='')}"
        how = f"open {out.web_url} in a browser, or run `rerun {url}`"
    except ViewerUnavailable as exc:  # the gRPC server still works without it
        how = f"run `rerun {url}` (the web viewer could not start: {exc})"
    if ipaddress.ip_address(bind).is_loopback:
        where = f"{bind}, this machine only (serve:0.0.0.0 lets other machines connect)"
    else:
        where = f"{bind}; from another machine, use this machine's address instead of {host}"
    out.opening.append(f"serving live on {where}: {how}")
    return out


def _wait_listening(host, port):
    deadline = time.monotonic() + SERVE_LISTEN_TIMEOUT_S
    while time.monotonic() < deadline:
        if port_is_listening(host, port):
            return True
        time.sleep(0.05)
    return False


_LIVE = {"spawn": _spawn, "connect": _connect, "serve": _serve}


def open_output(mode, app_id):
    """A stream attached to what ``mode`` asks for; returns ``(stream, Output)``.

    Raises ``ViewerError`` for an unusable path, or a live sink that cannot work with no
    default path to fall back on.
    """
    if mode.kind == "save":
        file = RecordingFile(mode.path, fresh=mode.fresh)
        try:
            stream = new_stream(app_id, file_only=True)
            stream.set_sinks(*_file_sink(file))
        except BaseException:
            file.discard()
            raise
        return stream, Output("save", file)
    # The copy is reserved first: an unusable default path is said before any viewer starts.
    file = RecordingFile(mode.path, fresh=True) if mode.path else None
    try:
        stream = new_stream(app_id)
        try:
            return stream, _LIVE[mode.kind](stream, mode, file)
        except SinkUnavailable as exc:
            if file is None:
                raise ViewerError(
                    f"viewer mode {mode.kind!r} cannot work here ({exc}); use save:PATH.rrd"
                ) from None
            # The first one may have had sinks: start clean.
            stream = new_stream(app_id, file_only=True)
            stream.set_sinks(*_file_sink(file))
            out = Output("save", file, reason=f"{mode.kind}: {exc}")
            out.opening.append(f"{out.reason}; the recording goes to {file.path} instead")
            return stream, out
    except BaseException:
        if file is not None:
            file.discard()
        raise
