"""Where a recording goes: parse the ``--rerun`` mode string.

Modes (the string a user types):

- ``save:PATH.rrd`` write a file, replacing an earlier one at PATH (and saying so); ``save``
  alone: the caller's default path, under a new name (``NAME-2.rrd``, ...) if that file exists;
- ``spawn`` open a native viewer (or use the one already listening on the default port);
- ``connect`` / ``connect:URL`` stream to a running viewer (default ``rerun+http://127.0.0.1:9876/proxy``);
- ``serve`` / ``serve:ADDRESS`` host a gRPC server and the web viewer, listening on 127.0.0.1
  unless an IP address is given (``serve:0.0.0.0``: every network interface);
- ``off`` record nothing;
- ``auto`` (or ``None``) ``spawn`` where a display exists, else ``save`` to the default path.

Parsing looks at the string, and for ``serve:IP`` whether that address is this machine's; the
file system and the rest of the network are checked when the recorder opens.
"""

import ipaddress
import os
import sys
from dataclasses import dataclass
from urllib.parse import urlsplit

from .errors import ViewerError
from .net import port_is_free
from .outfile import check_rrd_name

__all__ = [
    "DEFAULT_CONNECT_URL",
    "DEFAULT_SERVE_BIND",
    "DEFAULT_VIEWER_PORT",
    "DEFAULT_WEB_PORT",
    "MODE_KINDS",
    "Mode",
    "display_available",
    "parse_mode",
]

MODE_KINDS = ("save", "spawn", "connect", "serve", "off", "auto")
#: rerun's default gRPC port (viewer and ``serve``) and web viewer port.
DEFAULT_VIEWER_PORT = 9876
DEFAULT_WEB_PORT = 9090
DEFAULT_CONNECT_URL = f"rerun+http://127.0.0.1:{DEFAULT_VIEWER_PORT}/proxy"
#: ``serve`` is reachable from this machine only unless told otherwise.
DEFAULT_SERVE_BIND = "127.0.0.1"
_URL_SCHEMES = ("rerun", "rerun+http", "rerun+https")
_VALID = "save:PATH.rrd, spawn, connect[:URL], serve[:ADDRESS], off, auto"


@dataclass(frozen=True)
class Mode:
    """A parsed recorder mode.

    Attributes
    ----------
    kind : str
        One of ``save``, ``spawn``, ``connect``, ``serve``, ``off`` (``auto`` is resolved).
    path : str or None
        The ``.rrd`` file for ``save``; for the live kinds the caller's default path, where
        the recording is kept when a viewer cannot be used or delivery is not confirmed.
    url : str or None
        The viewer URL for ``connect``.
    fresh : bool
        ``path`` is the caller's default, so a new name is taken when it exists; an explicit
        ``save:PATH`` replaces the file.
    bind : str or None
        The IP address ``serve`` listens on.
    """

    kind: str
    path: str | None = None
    url: str | None = None
    fresh: bool = True
    bind: str | None = None


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


def _check_url(url):
    parts = urlsplit(url)
    if parts.scheme not in _URL_SCHEMES or not parts.hostname:
        raise ViewerError(
            f"connect:{url}: not a rerun viewer URL; use e.g. connect:{DEFAULT_CONNECT_URL} "
            f"(scheme rerun+http, rerun+https or rerun)"
        )
    try:
        port = parts.port
    except ValueError:
        raise ViewerError(f"connect:{url}: the port is not a number 0..65535") from None
    if port is None:  # rerun's own default here is not the viewer's port: ask
        raise ViewerError(
            f"connect:{url}: give the port, e.g. "
            f"connect:{parts.scheme}://{parts.hostname}:{DEFAULT_VIEWER_PORT}/proxy"
        )
    if parts.path != "/proxy":
        raise ViewerError(
            f"connect:{url}: a rerun viewer URL ends in /proxy, e.g. {DEFAULT_CONNECT_URL}"
        )
    return url


def _check_bind(address):
    hint = "use serve (this machine only) or serve:0.0.0.0 (every network interface)"
    try:
        bind = str(ipaddress.ip_address(address))
    except ValueError:
        raise ViewerError(f"serve:{address}: not an IP address to listen on; {hint}") from None
    if not port_is_free(bind, 0):  # port 0: any port, so only the address is tried
        raise ViewerError(f"serve:{address}: not an address of this machine; {hint}")
    return bind


def parse_mode(mode, default_path, *, environ=None, platform=None):
    """Parse a mode string into a ``Mode``; ``auto``/``None`` picks ``spawn`` or ``save``.

    Raises ``ViewerError`` saying what to type instead when ``mode`` is malformed.
    """
    if mode is None:
        mode = "auto"
    if not isinstance(mode, str):
        raise ViewerError(f"the viewer mode must be a string, not {type(mode).__name__}")
    default = check_rrd_name(default_path, "the default recording path") if default_path else None
    kind, sep, arg = mode.strip().partition(":")
    kind = kind.lower()
    if kind not in MODE_KINDS:
        raise ViewerError(f"unknown viewer mode {mode!r}; choose one of: {_VALID}")
    if kind in ("spawn", "off", "auto") and sep:
        raise ViewerError(
            f"viewer mode {kind!r} takes no argument (got {mode!r}); choose one of: {_VALID}"
        )
    if kind == "auto":
        kind = "spawn" if display_available(environ, platform) else "save"
    if kind == "save":
        if not sep and default is None:
            raise ViewerError("viewer mode 'save' needs a file: use save:PATH.rrd")
        path = check_rrd_name(arg, f"save:{arg}") if sep else default
        return Mode("save", path=path, fresh=not sep)
    if kind == "connect":
        url = _check_url(arg) if sep else DEFAULT_CONNECT_URL
        return Mode("connect", path=default, url=url)
    if kind == "serve":
        bind = _check_bind(arg) if sep else DEFAULT_SERVE_BIND
        return Mode("serve", path=default, bind=bind)
    return Mode(kind, path=default)
