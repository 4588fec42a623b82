"""Files the project writes: checked before the work starts, written whole or not at all.

Every output (summaries, Verilog, waveforms, recordings, benchmark tables) goes through here:

- ``check_output_path`` is called before a long job, so a bad path fails in a second, not
  after the run.
- ``atomic_output`` writes through a hidden temporary file in the same folder and renames it
  over the target at the end; on any error (or Ctrl-C) the temporary file is removed and the
  target is untouched. A rename goes only over a regular file or a new path: a device node, a
  folder or a link to one is never replaced.
"""

import json
import os
import stat
import tempfile
import weakref
from contextlib import contextmanager
from pathlib import Path

from fpga_robotics.hw.errors import UserError

__all__ = [
    "NotTextError",
    "OutputPathError",
    "PendingOutput",
    "atomic_output",
    "atomic_path",
    "check_output_dir",
    "check_output_path",
    "check_paths_apart",
    "default_dir_mode",
    "default_file_mode",
    "read_user_text",
    "write_atomic",
    "write_json_atomic",
]


class OutputPathError(UserError, ValueError):
    """An output path that cannot be written; the message names the path and the fix."""


class NotTextError(UserError, ValueError):
    """A user's file that is not UTF-8 text; the message names the file, the byte and the fix."""


def read_user_text(path, *, any_bytes=False):
    """The text of a file the user wrote (scenario, campaign, port map, Verilog, ...): UTF-8,
    a leading byte-order mark dropped (Windows editors add one). A file that is not UTF-8 is a
    ``NotTextError``, or with ``any_bytes`` (Verilog: Yosys and Verilator take any byte, e.g. a
    Latin-1 comment) read as Latin-1, one character per byte. ``OSError`` is the caller's."""
    data = Path(path).read_bytes()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if any_bytes:
            return data.decode("latin-1")
        raise NotTextError(
            f"not UTF-8 text (byte {data[exc.start]:#04x} at position {exc.start}): "
            "save it as UTF-8"
        ) from None


def _umask():
    umask = os.umask(0)  # read only by setting it: put it back at once
    os.umask(umask)
    return umask


def default_file_mode():
    """The mode ``open()`` would give a new file under the current umask (``mkstemp`` files
    are private, 0600; outputs should not be)."""
    return 0o666 & ~_umask()


def default_dir_mode():
    """The mode ``mkdir`` would give a new folder under the current umask (``mkdtemp``
    folders are private, 0700; outputs should not be)."""
    return 0o777 & ~_umask()


def _existing_ancestor(path):
    for parent in path.parents:
        if parent.exists() or parent.is_symlink():
            return parent
    return Path(".")


def _check_folder(folder, path, what):
    """``folder`` (the nearest existing ancestor of ``path``) must be a writable folder."""
    if not folder.is_dir():
        raise OutputPathError(
            f"{what} {str(path)!r}: cannot write there, {str(folder)!r} is not a folder"
        )
    try:  # os.access says yes to root even on a read-only file system: try for real
        fd, probe = tempfile.mkstemp(prefix=".write-test-", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputPathError(
            f"{what} {str(path)!r}: cannot write in {str(folder)!r} ({exc.strerror}); "
            "choose another place"
        ) from None


def check_output_path(path, *, what="output file"):
    """Check that ``path`` can be written as a regular file; return it as a ``Path``.

    Missing parent folders are fine (``atomic_output`` creates them). Raises
    ``OutputPathError`` for an empty path, an existing folder or non-regular file (a device,
    a FIFO), a parent that is a file, or a folder that cannot be written.
    """
    if path is None or str(path).strip() == "":
        raise OutputPathError(f"{what}: the path is empty; give a file name")
    path = Path(path)
    if path.exists():
        mode = path.stat().st_mode
        if stat.S_ISDIR(mode):
            raise OutputPathError(f"{what} {str(path)!r} is a folder; give a file name in it")
        if not stat.S_ISREG(mode):
            raise OutputPathError(
                f"{what} {str(path)!r} exists and is not a regular file (a device or pipe); "
                "give a file name"
            )
    folder = path.parent if path.parent.exists() else _existing_ancestor(path)
    _check_folder(folder, path, what)
    return path


def check_output_dir(path, *, what="output folder"):
    """Check that ``path`` is a writable folder or can be created as one; return a ``Path``."""
    if path is None or str(path).strip() == "":
        raise OutputPathError(f"{what}: the path is empty; give a folder")
    path = Path(path)
    if path.exists():
        if not path.is_dir():
            raise OutputPathError(f"{what} {str(path)!r} exists and is not a folder")
        _check_folder(path, path, what)
    else:
        _check_folder(_existing_ancestor(path), path, what)
    return path


def _relation(path, other):
    """How ``path`` lies to ``other`` (both resolved): the same, inside it, holding it, or
    apart (None)."""
    if path == other:
        return "is the same path as"
    if other in path.parents:
        return "is inside"
    if path in other.parents:
        return "holds"
    return None


def check_paths_apart(outputs, inputs=()):
    """Refuse outputs that would overwrite one another or an input of the same job.

    ``outputs`` and ``inputs`` are ``(name, path)`` pairs, ``name`` saying where the path comes
    from (``"--summary"``); a folder (a bag, a folder of images) holds all below it. Raises
    ``OutputPathError`` naming both paths when two outputs are the same path or one is inside
    the other, or an output is an input, is inside one or holds one.
    """
    resolved = [(name, str(path), Path(path).resolve()) for name, path in outputs]
    for index, (name, path, real) in enumerate(resolved):
        for other_name, other_path, other_real in resolved[:index]:
            relation = _relation(real, other_real)
            if relation:
                raise OutputPathError(
                    f"{name} {path!r} {relation} {other_name} {other_path!r}; "
                    "give each output its own path"
                )
        for input_name, input_path in inputs:
            relation = _relation(real, Path(input_path).resolve())
            if relation:
                raise OutputPathError(
                    f"{name} {path!r} {relation} the input {input_name} {str(input_path)!r}; "
                    "give the output a path outside the inputs"
                )


class PendingOutput:
    """A hidden temporary file next to ``path`` (``.tmp``), for output written over a while
    by a writer that opens files itself (a simulator tracing frames): ``commit()`` makes it
    ``path``, ``discard()`` removes it, as does dropping it uncommitted (its owner dropped
    without finishing, or the interpreter's exit). The path is checked on construction."""

    def __init__(self, path, *, what="output file", suffix=None):
        self.path = check_output_path(path, what=what)
        self.what = what
        self.path.parent.mkdir(parents=True, exist_ok=True)
        suffix = self.path.suffix if suffix is None else suffix
        fd, tmp = tempfile.mkstemp(
            prefix=f".{self.path.stem}.", suffix=f".partial{suffix}", dir=self.path.parent
        )
        os.close(fd)
        self.tmp = Path(tmp)
        self._cleanup = weakref.finalize(self, self.tmp.unlink, missing_ok=True)

    def commit(self):
        _replace(self.tmp, self.path, self.what)
        self._cleanup.detach()

    def discard(self):
        self._cleanup()


@contextmanager
def atomic_path(path, *, what="output file", suffix=None):
    """Yield a hidden temporary path next to ``path`` for a writer that opens files itself
    (a simulator writing a waveform); on success it becomes ``path``, on error it is removed."""
    pending = PendingOutput(path, what=what, suffix=suffix)
    try:
        yield pending.tmp
        pending.commit()
    finally:
        pending.discard()


def _replace(tmp, path, what):
    # Checked again at the end: the target may have changed while the work ran.
    if path.exists() and not path.is_file():
        raise OutputPathError(f"{what} {str(path)!r} is no longer a regular file; not replaced")
    os.chmod(tmp, default_file_mode())
    os.replace(tmp, path)


@contextmanager
def atomic_output(path, mode="w", *, what="output file"):
    """``with atomic_output(path) as f: f.write(...)``: ``path`` gets all of it or nothing."""
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    with atomic_path(path, what=what) as tmp, open(tmp, mode) as f:
        yield f


def write_atomic(path, data, *, what="output file"):
    """Write ``data`` (str or bytes) to ``path`` atomically."""
    with atomic_output(path, "wb" if isinstance(data, bytes) else "w", what=what) as f:
        f.write(data)


def write_json_atomic(path, obj, *, what="JSON file"):
    """Write ``obj`` as indented JSON (with a final newline) to ``path`` atomically."""
    with atomic_output(path, what=what) as f:
        json.dump(obj, f, indent=2)
        f.write("\n")
