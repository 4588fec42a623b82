"""The life of a compiled model, shared by the frame backends (compiled.py, foreign.py) and
the pin backends (sim/pins/compiled.py): the texts that decide a build and their digests
(part of the build key), the build through the cache (build_cache.py; a missing tool is a
one-line ``BackendError`` from toolchain.py), loading the library through ctypes with its
entry points checked, and the retry policy: an entry that passes the cache's manifest check
but does not load is rebuilt once.
"""

import ctypes
import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

from . import build_cache
from .base import BackendError

__all__ = ["BuildPlan", "bind_library", "digest", "load_built", "read_sources"]


class BuildPlan(NamedTuple):
    """Arguments of ``build_cache.get_or_build``: entry name, key, files and build function."""

    name: str
    key: str
    files: list
    build: Callable


def digest(text):
    """SHA-256 hex digest of a text (a source's identity in a build key)."""
    return hashlib.sha256(text.encode()).hexdigest()


def read_sources(names, *folders):
    """``{name: text}`` of harness files, each read from the first of ``folders`` that has it."""
    texts = {}
    for name in names:
        folder = next((Path(f) for f in folders if (Path(f) / name).exists()), Path(folders[0]))
        texts[name] = (folder / name).read_text()
    return texts


def bind_library(path, entries, *, what, abi_entry, abi, error=BackendError):
    """Load the shared library ``path`` and type its C ``entries`` ((name, restype,
    argtypes)...); its ``abi_entry()`` must return ``abi``. Failures raise ``error`` naming
    ``what`` (e.g. "compiled model")."""
    try:
        lib = ctypes.CDLL(str(path))
    except OSError as exc:
        raise error(f"cannot load the {what} {path}: {exc}") from None
    for name, restype, argtypes in entries:
        fn = getattr(lib, name, None)
        if fn is None:
            raise error(f"the {what} {path} lacks {name}()")
        fn.restype, fn.argtypes = restype, argtypes
    if getattr(lib, abi_entry)() != abi:
        raise error(f"the {what} {path} has an unexpected harness ABI")
    return lib


def load_built(plan, library, load, *, on_build=None, error=BackendError):
    """``(entry, loaded)``: the cache entry of ``plan`` (built when missing) and
    ``load(path of its file library)``. ``load`` raises ``error`` for a library that does not
    load; a cached entry that fails so is deleted and rebuilt once, a fresh build's failure
    is raised."""
    for attempt in range(2):
        entry = build_cache.get_or_build(*plan, on_build=on_build)
        try:
            return entry, load(entry.file(library))
        except error:
            if attempt or entry.built:
                raise
            build_cache.invalidate(entry)
    raise AssertionError("unreachable")
