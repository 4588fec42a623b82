"""Where a recording goes: parse the ``--rerun`` mode string and check that the sink can work.

Modes (the string a user types):

- ``save:PATH.rrd`` write a file (``save`` alone: the caller's default path);
- ``spawn`` open a native viewer (or use the one already listening on the default port);
- ``connect`` / ``connect:URL`` stream to a running viewer (default ``rerun+http://127.0.0.1:9876/proxy``);
- ``serve`` host a gRPC server and the web viewer on localhost;
- ``off`` record nothing;
- ``auto`` (or ``None``) ``spawn`` where a display exists, else ``save`` to the default path.
"""

import os
import socket
import sys
from dataclasses import dataclass
from urllib.parse import urlsplit

from .errors import ViewerError

__all__ = [
    "DEFAULT_CONNECT_URL",
    "DEFAULT_VIEWER_PORT",
    "DEFAULT_WEB_PORT",
    "MODE_KINDS",
    "Mode",
    "display_available",
    "parse_mode",
    "port_is_listening",
]

MODE_KINDS = ("save", "spawn", "connect", "serve", "off", "auto")
#: rerun's default gRPC port (viewer and ``serve``) and web viewer port.
DEFAULT_VIEWER_PORT = 9876
DEFAULT_WEB_PORT = 9090
DEFAULT_CONNECT_URL = f"rerun+http://127.0.0.1:{DEFAULT_VIEWER_PORT}/proxy"
_URL_SCHEMES = ("rerun", "rerun+http", "rerun+https")


@dataclass(frozen=True)
class Mode:
    """A parsed recorder mode.

    Attributes
    ----------
    kind : str
        One of ``save``, ``spawn``, ``connect``, ``serve``, ``off`` (``auto`` is resolved).
    path : str or None
        The ``.rrd`` file for ``save`` (and the fallback file for the other kinds).
    url : str or None
        The viewer URL for ``connect``.
    """

    kind: str
    path: str | None = None
    url: str | None = None


def display_available(environ=None, platform=None):
    """Whether a native viewer window can open here.

    On Linux and the BSDs that needs an X11 or Wayland display (``DISPLAY`` or
    ``WAYLAND_DISPLAY``); macOS and Windows always have one.
    """
    env = os.environ if environ is None else environ
    plat = sys.platform if platform is None else platform
    if plat.startswith(("darwin", "win32", "cygwin")):
        return True
    return bool(env.get("DISPLAY") or env.get("WAYLAND_DISPLAY"))


def port_is_listening(host, port, timeout=0.3):
    """True when a TCP server accepts connections on ``host:port``."""
    try:
        with socket.create_connection((host, port), timeout=timeout):
            return True
    except OSError:
        return False


def _check_rrd_path(path, where):
    if not path:
        raise ViewerError(f"{where}: the file name is empty; use save:PATH.rrd, e.g. save:run.rrd")
    if not path.endswith(".rrd"):
        raise ViewerError(
            f"{where}: {path!r} does not end in .rrd; rerun opens .rrd files, e.g. save:run.rrd"
        )
    if os.path.isdir(path):
        raise ViewerError(f"{where}: {path!r} is a directory; give a file name ending in .rrd")
    return path


def _check_url(url):
    parts = urlsplit(url)
    if parts.scheme not in _URL_SCHEMES or not parts.hostname:
        raise ViewerError(
            f"connect:{url}: not a rerun viewer URL; use e.g. connect:{DEFAULT_CONNECT_URL} "
            f"(scheme rerun+http, rerun+https or rerun)"
        )
    try:
        parts.port  # noqa: B018 - raises on a malformed port
    except ValueError:
        raise ViewerError(f"connect:{url}: the port is not a number 0..65535") from None
    return url


def parse_mode(mode, default_path, *, environ=None, platform=None):
    """Parse a mode string into a ``Mode``; ``auto``/``None`` picks ``spawn`` or ``save``.

    Raises ``ViewerError`` naming the valid modes when ``mode`` is not one of them.
    """
    if mode is None:
        mode = "auto"
    if not isinstance(mode, str):
        raise ViewerError(f"the viewer mode must be a string, not {type(mode).__name__}")
    default = _check_rrd_path(default_path, "the default recording path") if default_path else None
    kind, sep, arg = mode.strip().partition(":")
    kind = kind.lower()
    valid = "save:PATH.rrd, spawn, connect[:URL], serve, off, auto"
    if kind not in MODE_KINDS:
        raise ViewerError(f"unknown viewer mode {mode!r}; choose one of: {valid}")
    if kind in ("spawn", "serve", "off", "auto") and sep:
        raise ViewerError(
            f"viewer mode {kind!r} takes no argument (got {mode!r}); choose one of: {valid}"
        )
    if kind == "auto":
        kind = "spawn" if display_available(environ, platform) else "save"
    if kind == "save":
        path = arg if sep else default
        if not sep and path is None:
            raise ViewerError("viewer mode 'save' needs a file: use save:PATH.rrd")
        return Mode("save", path=_check_rrd_path(path, f"save:{arg}"))
    if kind == "connect":
        url = _check_url(arg) if sep else DEFAULT_CONNECT_URL
        return Mode("connect", path=default, url=url)
    return Mode(kind, path=default)
