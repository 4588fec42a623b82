"""The rerun viewer processes a recorder starts: a native window (``spawn``, outlives the run)
and the web viewer's HTTP server (``serve``, stopped with the run). Every wait is bounded."""

import os
import shutil
import subprocess
import tempfile
import time

from fpga_robotics.hw.errors import UserError

from .net import port_is_listening

__all__ = [
    "SPAWN_SETTLE_S",
    "SPAWN_TIMEOUT_S",
    "STOP_TIMEOUT_S",
    "ViewerUnavailable",
    "start_viewer",
    "start_web_viewer",
    "stop_process",
    "viewer_command",
    "web_viewer_command",
]

#: How long a started viewer may take to listen, and how long it must then stay alive.
SPAWN_TIMEOUT_S = 20.0
SPAWN_SETTLE_S = 1.0
#: How long a process we stop may take to exit after SIGTERM (then SIGKILL).
STOP_TIMEOUT_S = 3.0
_LOCALHOST = "127.0.0.1"


class ViewerUnavailable(UserError, RuntimeError):
    """A viewer process cannot run here; the message says why."""


def _viewer_binary():
    # The binary itself rather than the `rerun` console script, which would run it as a child:
    # then the pid we know is the viewer's own.
    try:
        import rerun_cli  # lazy: optional, the rerun on PATH serves as well

        exe = os.path.join(os.path.dirname(rerun_cli.__file__), "rerun")
        if os.path.isfile(exe) and os.access(exe, os.X_OK):
            return exe
    except ImportError:
        pass
    exe = shutil.which("rerun")
    if exe is None:
        raise ViewerUnavailable("the rerun viewer is not installed (pip install rerun-sdk)")
    return exe


def viewer_command(port):
    """The command that starts a native rerun viewer listening on ``port`` (this machine)."""
    return [
        _viewer_binary(),
        "--bind", _LOCALHOST, "--port", str(port),
        "--memory-limit", "75%", "--expect-data-soon",
    ]  # fmt: skip


def web_viewer_command(bind, web_port, grpc_url):
    """The command that serves only the web viewer, on ``bind:web_port``, pointed at
    ``grpc_url`` (given a URL, ``--serve-web`` hosts no gRPC server of its own)."""
    return [
        _viewer_binary(),
        "--serve-web", "--bind", bind, "--web-viewer-port", str(web_port), grpc_url,
    ]  # fmt: skip


def _last_line(fileobj):
    fileobj.seek(0)
    lines = [
        ln.strip() for ln in fileobj.read().decode(errors="replace").splitlines() if ln.strip()
    ]
    errors = [ln for ln in lines if "error" in ln.lower()]
    return (errors or lines or ["(no output)"])[-1][:300]


def stop_process(proc):
    """SIGTERM, then SIGKILL if it has not exited within ``STOP_TIMEOUT_S``."""
    if proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(STOP_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(STOP_TIMEOUT_S)


def _start(cmd, host, port, what, *, detach):
    env = dict(os.environ, RERUN_APP_ONLY="true")
    with tempfile.TemporaryFile() as errlog:
        try:
            proc = subprocess.Popen(
                cmd,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=errlog,
                env=env,
                start_new_session=detach,  # a viewer window outlives the run
            )
        except OSError as exc:
            raise ViewerUnavailable(f"cannot start {what} ({cmd[0]}): {exc}") from None
        try:
            deadline = time.monotonic() + SPAWN_TIMEOUT_S
            listening_since = None
            while True:
                code = proc.poll()
                if code is not None:
                    raise ViewerUnavailable(f"{what} exited with code {code}: {_last_line(errlog)}")
                now = time.monotonic()
                if listening_since is None and port_is_listening(host, port):
                    listening_since = now
                # A viewer can bind its port and only then fail to open a window: wait a moment.
                if listening_since is not None and now - listening_since >= SPAWN_SETTLE_S:
                    return proc
                if now > deadline:
                    raise ViewerUnavailable(
                        f"{what} did not listen on port {port} within {SPAWN_TIMEOUT_S:.0f} s"
                    )
                time.sleep(0.05)
        except BaseException:  # a failure or Ctrl-C: leave no half-started process behind
            stop_process(proc)
            raise


def start_viewer(port):
    """Start a native viewer listening on 127.0.0.1:``port``; returns its ``Popen``."""
    return _start(viewer_command(port), _LOCALHOST, port, "the rerun viewer", detach=True)


def start_web_viewer(bind, web_port, grpc_url, check_host):
    """Serve the web viewer on ``bind:web_port``; returns its ``Popen`` (stop it at the end)."""
    return _start(
        web_viewer_command(bind, web_port, grpc_url), check_host, web_port,
        "the web viewer", detach=False,
    )  # fmt: skip
