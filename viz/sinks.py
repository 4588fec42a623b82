"""Attach a ``rerun.RecordingStream`` to the sink a ``Mode`` asks for, or say why it cannot.

Every sink that cannot work here (no display, a viewer that fails to start, nobody listening
at a URL, a busy port) raises ``SinkUnavailable`` with the reason; the recorder then saves to
its default file instead and tells the user, so data is never lost silently.
"""

import os
import shutil
import socket
import subprocess
import tempfile
import time
import uuid
from urllib.parse import quote, urlsplit

import rerun as rr

from .errors import ViewerError
from .modes import DEFAULT_VIEWER_PORT, DEFAULT_WEB_PORT, display_available, port_is_listening

__all__ = ["SinkUnavailable", "attach_connect", "attach_save", "attach_serve", "attach_spawn"]

#: How long a spawned viewer may take to listen, and how long it must then stay alive.
SPAWN_TIMEOUT_S = 20.0
SPAWN_SETTLE_S = 1.0
_LOCALHOST = "127.0.0.1"


class SinkUnavailable(RuntimeError):
    """The requested sink cannot work here; the message says why."""


def temp_path_for(path):
    """A hidden temporary file next to ``path`` (same file system, so the final rename is atomic)."""
    folder, name = os.path.split(os.path.abspath(path))
    # Hidden, and still ending in .rrd: ignored by git like any recording, openable if salvaged.
    return os.path.join(folder, f".{name}.{uuid.uuid4().hex[:8]}.partial.rrd")


def attach_save(stream, path):
    """Stream to a temporary file beside ``path``; returns the temporary path (rename on close)."""
    folder = os.path.dirname(os.path.abspath(path))
    tmp = temp_path_for(path)
    try:
        os.makedirs(folder, exist_ok=True)
        with open(tmp, "wb"):  # fail here, with a clear message, if the folder is not writable
            pass
        stream.save(tmp)
    except OSError as exc:
        raise ViewerError(f"cannot write the recording {path}: {exc.strerror or exc}") from None
    return tmp


def _viewer_binary():
    # The binary itself rather than the `rerun` console script, which would run it as a child:
    # then the pid we know is the viewer's own.
    try:
        import rerun_cli

        exe = os.path.join(os.path.dirname(rerun_cli.__file__), "rerun")
        if os.path.isfile(exe) and os.access(exe, os.X_OK):
            return exe
    except ImportError:
        pass
    exe = shutil.which("rerun")
    if exe is None:
        raise SinkUnavailable("the rerun viewer is not installed (pip install rerun-sdk)")
    return exe


def viewer_command(port):
    """The command that starts a native rerun viewer listening on ``port``."""
    base = [_viewer_binary()]
    return base + ["--port", str(port), "--memory-limit", "75%", "--expect-data-soon"]


def _last_line(fileobj):
    fileobj.seek(0)
    lines = [
        ln.strip() for ln in fileobj.read().decode(errors="replace").splitlines() if ln.strip()
    ]
    errors = [ln for ln in lines if "error" in ln.lower()]
    return (errors or lines or ["(no output)"])[-1][:300]


def _start_viewer(port):
    cmd = viewer_command(port)
    env = dict(os.environ, RERUN_APP_ONLY="true")
    with tempfile.TemporaryFile() as errlog:
        try:
            proc = subprocess.Popen(
                cmd,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=errlog,
                env=env,
                start_new_session=True,  # the viewer outlives the run
            )
        except OSError as exc:
            raise SinkUnavailable(f"cannot start the rerun viewer ({cmd[0]}): {exc}") from None
        deadline = time.monotonic() + SPAWN_TIMEOUT_S
        listening_since = None
        while True:
            code = proc.poll()
            if code is not None:
                raise SinkUnavailable(
                    f"the rerun viewer exited with code {code}: {_last_line(errlog)}"
                )
            now = time.monotonic()
            if listening_since is None and port_is_listening(_LOCALHOST, port):
                listening_since = now
            # A viewer can bind its port and only then fail to open a window: wait a moment.
            if listening_since is not None and now - listening_since >= SPAWN_SETTLE_S:
                return proc
            if now > deadline:
                proc.terminate()
                raise SinkUnavailable(
                    f"the rerun viewer did not listen on port {port} within {SPAWN_TIMEOUT_S:.0f} s"
                )
            time.sleep(0.05)


#: The port a spawned viewer listens on (rerun's default).
VIEWER_PORT = DEFAULT_VIEWER_PORT


def attach_spawn(stream, port=None):
    """Open a native viewer (or reuse one already listening on ``port``) and stream to it.

    Returns a description of what happened and the pid of the viewer started (or ``None``).
    """
    port = VIEWER_PORT if port is None else port
    url = f"rerun+http://{_LOCALHOST}:{port}/proxy"
    if port_is_listening(_LOCALHOST, port):
        stream.connect_grpc(url)
        return f"streamed to the rerun viewer already running on port {port}", None
    if not display_available():
        raise SinkUnavailable(
            "no display to open a viewer window (DISPLAY and WAYLAND_DISPLAY unset)"
        )
    proc = _start_viewer(port)
    stream.connect_grpc(url)
    return f"streamed to a new rerun viewer (pid {proc.pid}, port {port})", proc.pid


def attach_connect(stream, url):
    """Stream to the viewer at ``url`` after checking that something listens there."""
    parts = urlsplit(url)
    default_port = 443 if parts.scheme == "rerun+https" else DEFAULT_VIEWER_PORT
    port = parts.port or default_port
    if not port_is_listening(parts.hostname, port, timeout=1.0):
        raise SinkUnavailable(f"no rerun viewer is listening at {url} (start one with `rerun`)")
    stream.connect_grpc(url)
    return f"streamed to the rerun viewer at {url}"


def _free_port():
    with socket.socket() as s:
        s.bind((_LOCALHOST, 0))
        return s.getsockname()[1]


def attach_serve(stream, grpc_port=DEFAULT_VIEWER_PORT, web_port=DEFAULT_WEB_PORT):
    """Host a gRPC server and the web viewer on localhost.

    Returns ``(grpc_url, web_url or None, how_to_open)``.
    """
    # rerun's default ports may be taken by another run or viewer: then any free port.
    if port_is_listening(_LOCALHOST, grpc_port):
        grpc_port = _free_port()
    if port_is_listening(_LOCALHOST, web_port):
        web_port = _free_port()
    try:
        url = stream.serve_grpc(grpc_port=grpc_port)
    except Exception as exc:  # noqa: BLE001 - reported, and the recorder saves instead
        raise SinkUnavailable(f"cannot serve gRPC on port {grpc_port}: {exc}") from None
    try:
        rr.serve_web_viewer(web_port=web_port, open_browser=False, connect_to=url)
        web = f"http://localhost:{web_port}/?url={quote(url, safe='')}"
        how = f"open {web} in a browser, or run `rerun {url}`"
    except Exception as exc:  # noqa: BLE001 - the gRPC server still works without it
        web = None
        how = f"run `rerun {url}` (the web viewer could not start: {exc})"
    return url, web, how
