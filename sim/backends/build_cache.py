"""On-disk cache of compiled simulation models.

An entry is a directory named by the flow and a hash of everything that decides the build
(generated source, harness sources, parameters, flags, compiler and tool versions). It holds
the built files and a ``manifest.json`` with their sizes and SHA-256, so a damaged entry
(truncated library, missing file, edited manifest) is detected and rebuilt.

Concurrent builds are safe: a process takes an exclusive lock on ``<entry>.lock``, checks the
entry again, builds in a fresh temporary directory next to it and renames it into place, so a
reader never sees a half-written entry and two processes never build the same entry at once.

The cache lives in ``$FPGA_ROBOTICS_CACHE`` when set, else ``~/.cache/fpga_robotics``.
"""

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

from .base import BackendError

__all__ = ["CACHE_ENV", "CacheEntry", "build_key", "cache_root", "get_or_build", "invalidate"]

CACHE_ENV = "FPGA_ROBOTICS_CACHE"
_MANIFEST = "manifest.json"
_FORMAT = 1


def cache_root():
    """The cache directory (created on demand)."""
    configured = os.environ.get(CACHE_ENV, "").strip()
    root = Path(configured).expanduser() if configured else Path.home() / ".cache" / "fpga_robotics"
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BackendError(
            f"cannot create the build cache {root} ({exc.strerror}); set {CACHE_ENV} to a "
            f"writable directory"
        ) from None
    return root


def build_key(parts):
    """A hex digest of ``parts`` (a JSON-serialisable dict): the identity of a build."""
    blob = json.dumps({"format": _FORMAT, **parts}, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


def _file_digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


class CacheEntry:
    """A complete, verified cache entry: ``path`` is its directory."""

    def __init__(self, path, built):
        self.path = Path(path)
        #: True when this call built it, False when it was found in the cache.
        self.built = built

    def file(self, name):
        return self.path / name


def _valid(entry_dir, key, files):
    manifest = entry_dir / _MANIFEST
    try:
        data = json.loads(manifest.read_text())
        if data.get("key") != key or sorted(data["files"]) != sorted(files):
            return False
        for name, info in data["files"].items():
            path = entry_dir / name
            if path.stat().st_size != info["size"] or _file_digest(path) != info["sha256"]:
                return False
    except (OSError, ValueError, KeyError, TypeError):
        return False
    return True


@contextlib.contextmanager
def _locked(lock_path):
    with open(lock_path, "a+") as lock:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock.fileno(), fcntl.LOCK_UN)


def get_or_build(name, key, files, build, *, root=None, on_build=None):
    """Return the verified ``CacheEntry`` ``name-key``, building it when needed.

    Parameters
    ----------
    name : str
        Flow and variant, e.g. ``"cxxrtl-follow_target"``; part of the directory name.
    key : str
        ``build_key`` of everything that decides the build.
    files : list of str
        Names of the files the entry must hold (checked and hashed in the manifest).
    build : callable
        ``build(directory)`` writes those files into the fresh ``directory`` (raising
        ``BackendError`` on failure). Other files it leaves there (objects) are removed.
    on_build : callable(), optional
        Called once before an actual build (not for a cache hit).
    """
    root = Path(root) if root is not None else cache_root()
    entry_dir = root / f"{name}-{key[:32]}"
    if _valid(entry_dir, key, files):
        return CacheEntry(entry_dir, built=False)
    with _locked(root / f"{name}-{key[:32]}.lock"):
        # Someone else may have built it while we waited for the lock.
        if _valid(entry_dir, key, files):
            return CacheEntry(entry_dir, built=False)
        if on_build is not None:
            on_build()
        work = Path(tempfile.mkdtemp(prefix=f".build-{name}-", dir=root))
        final = None
        try:
            build(work)
            manifest = {"key": key, "files": {}}
            for fname in files:
                path = work / fname
                if not path.is_file():
                    raise BackendError(f"the {name} build did not produce {fname}")
                manifest["files"][fname] = {
                    "size": path.stat().st_size,
                    "sha256": _file_digest(path),
                }
            final = Path(tempfile.mkdtemp(prefix=f".entry-{name}-", dir=root))
            for fname in files:
                os.replace(work / fname, final / fname)
            (final / _MANIFEST).write_text(json.dumps(manifest, indent=1))
            if entry_dir.exists():  # damaged: move it aside, then delete
                trash = Path(tempfile.mkdtemp(prefix=".trash-", dir=root))
                os.replace(entry_dir, trash / "old")
                shutil.rmtree(trash, ignore_errors=True)
            os.replace(final, entry_dir)
            final = None
        finally:
            shutil.rmtree(work, ignore_errors=True)
            if final is not None:
                shutil.rmtree(final, ignore_errors=True)
    return CacheEntry(entry_dir, built=True)


def invalidate(entry):
    """Delete a cache entry found unusable after verification (e.g. it does not load)."""
    shutil.rmtree(entry.path, ignore_errors=True)
