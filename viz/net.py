"""Bounded network checks: is a port taken, and does a rerun viewer really answer at a URL.

rerun's gRPC client, once connected, waits forever for a peer that never reads (its flush on
disconnect has no timeout). So before streaming anywhere we ask the peer to speak first: a
rerun viewer or server is a gRPC (HTTP/2) server, and an HTTP/2 server answers the client's
connection preface with its SETTINGS frame at once. Anything else (a port that accepts and
stays silent, a web server, another protocol) is found out here, within ``PROBE_TIMEOUT_S``.
"""

import socket
import ssl
import time
from urllib.parse import urlsplit

__all__ = [
    "PROBE_TIMEOUT_S",
    "free_port",
    "port_is_free",
    "port_is_listening",
    "probe_viewer",
    "url_address",
]

#: How long a peer may take to accept a connection and to answer the HTTP/2 preface.
PROBE_TIMEOUT_S = 3.0

# Client connection preface (RFC 9113, 3.4): the magic string, then an empty SETTINGS frame.
_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 0x4, 0, 0, 0, 0, 0])
_SETTINGS = 0x4
_TLS_SCHEMES = ("rerun", "rerun+https")


def port_is_listening(host, port, timeout=0.3):
    """True when a TCP server accepts connections on ``host:port``."""
    try:
        with socket.create_connection((host, port), timeout=timeout):
            return True
    except OSError:
        return False


def port_is_free(host, port):
    """True when this process could listen on ``host:port`` now."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        try:
            s.bind((host, port))
        except OSError:
            return False
    return True


def free_port(host="127.0.0.1"):
    """A port nobody listens on at ``host`` (the system's choice)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def url_address(url):
    """``(host, port, tls)`` of a rerun URL whose port was checked by ``viz.modes``."""
    parts = urlsplit(url)
    return parts.hostname, parts.port, parts.scheme in _TLS_SCHEMES


def _read_frame_header(sock, deadline):
    data = b""
    while len(data) < 9:
        sock.settimeout(max(0.01, deadline - time.monotonic()))
        chunk = sock.recv(9 - len(data))
        if not chunk:
            break
        data += chunk
    return data


def probe_viewer(url, timeout=PROBE_TIMEOUT_S):
    """``None`` when a gRPC server answers at ``url`` within ``timeout`` s, else why not."""
    host, port, tls = url_address(url)
    where = f"{host}:{port}"
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except TimeoutError:
        return f"nothing accepted a connection at {where} within {timeout:g} s"
    except OSError as exc:
        return f"no rerun viewer is listening at {where} ({exc.strerror or exc})"
    try:
        if tls:
            context = ssl.create_default_context()
            context.set_alpn_protocols(["h2"])
            sock = context.wrap_socket(sock, server_hostname=host)
        sock.sendall(_PREFACE)
        header = _read_frame_header(sock, deadline)
    except TimeoutError:
        return (
            f"{where} accepted the connection but did not answer within {timeout:g} s "
            "(not a rerun viewer, or a stalled one)"
        )
    except OSError as exc:  # ssl.SSLError included
        return f"the connection to {where} failed ({exc.strerror or exc})"
    finally:
        sock.close()
    if len(header) < 9:
        return f"{where} closed the connection without answering like a rerun viewer"
    if header[3] != _SETTINGS:
        return f"{where} answered, but not like a rerun viewer (no gRPC there)"
    return None
