"""The ``.rrd`` file a recording is saved to: checked before the run, never half-written under
its real name, and never replacing an earlier recording without saying so.

- The path is checked when the recorder opens (``sim.files.check_output_path``): a folder, a
  device, a path below a regular file or an unwritable folder is a ``ViewerError`` before
  any frame is simulated.
- The data is written under a hidden temporary name beside it (``sim.files.atomic_path``)
  and renamed at the end, by ``keep()``; ``discard()`` removes it.
- A *fresh* name (the caller's default path) never replaces anything: when ``run.rrd``
  exists, ``run-2.rrd``, ``run-3.rrd``, ... is taken, reserved at once by creating it empty,
  so that runs started together cannot pick the same one. An explicit path replaces what is
  there, and ``replaced`` says that it did.
"""

import os
from pathlib import Path

from ..sim.files import OutputPathError, atomic_path, check_output_path, default_file_mode
from .errors import ViewerError

__all__ = ["MAX_NUMBERED", "RecordingFile", "check_rrd_name"]

#: How many numbered names (``run-2.rrd`` ...) a fresh name tries before giving up.
MAX_NUMBERED = 9999
_WHAT = "recording"


class _Discard(Exception):
    """Thrown into ``atomic_path`` to make it remove its temporary file."""


def check_rrd_name(path, where):
    """``path`` is a non-empty name ending in ``.rrd`` (what rerun opens); returns it."""
    if not path:
        raise ViewerError(f"{where}: the file name is empty; use save:PATH.rrd, e.g. save:run.rrd")
    if not str(path).endswith(".rrd"):
        raise ViewerError(
            f"{where}: {str(path)!r} does not end in .rrd; rerun opens .rrd files, e.g. save:run.rrd"
        )
    return path


def _checked(path):
    try:
        return check_output_path(path, what=_WHAT)
    except OutputPathError as exc:
        raise ViewerError(str(exc)) from None


def _numbered(path, n):
    return path if n == 1 else path.with_name(f"{path.stem}-{n}{path.suffix}")


def _reserve_fresh(path):
    """Create the first free name of ``path``, ``path-2``, ... empty; returns it."""
    for n in range(1, MAX_NUMBERED + 1):
        candidate = _numbered(path, n)
        if candidate.exists() or candidate.is_symlink():
            continue
        _checked(candidate)
        candidate.parent.mkdir(parents=True, exist_ok=True)
        try:
            fd = os.open(candidate, os.O_WRONLY | os.O_CREAT | os.O_EXCL, default_file_mode())
        except FileExistsError:  # taken by another run just now
            continue
        except OSError as exc:
            raise ViewerError(f"{_WHAT} {str(candidate)!r}: {exc.strerror}") from None
        os.close(fd)
        return candidate
    raise ViewerError(
        f"{_WHAT} {str(path)!r}: {MAX_NUMBERED} numbered recordings exist already; "
        "move some away or give save:PATH.rrd"
    )


class RecordingFile:
    """Where one recording is written; see the module docstring.

    Attributes
    ----------
    path : pathlib.Path
        The final name.
    temp : pathlib.Path
        The hidden file rerun writes to until ``keep()`` or ``discard()``.
    replaced : bool
        An explicit path named an existing file, which ``keep()`` replaces.
    """

    def __init__(self, path, *, fresh):
        path = Path(check_rrd_name(str(path), _WHAT))
        self.replaced = False
        self._reserved = None
        if fresh:
            path = self._reserved = _reserve_fresh(path)
        else:
            self.replaced = _checked(path).is_file()
        self.path = path
        self._writer = atomic_path(path, what=_WHAT)
        try:
            self.temp = self._writer.__enter__()
        except OutputPathError as exc:
            self._drop_reservation()
            raise ViewerError(str(exc)) from None
        except BaseException:
            self._drop_reservation()
            raise
        self.done = False

    def _drop_reservation(self):
        if self._reserved is not None:
            self._reserved.unlink(missing_ok=True)

    def keep(self):
        """Give the data its real name; returns ``None`` or why that failed (data lost)."""
        if self.done:
            return None
        self.done = True
        try:
            self._writer.__exit__(None, None, None)
        except OutputPathError as exc:  # the target became a folder or device meanwhile
            self._drop_reservation()
            return str(exc)
        return None

    def discard(self):
        """Remove the temporary file (and the reserved name): nothing is kept."""
        if self.done:
            return
        self.done = True
        try:
            self._writer.__exit__(_Discard, _Discard(), None)
        finally:
            self._drop_reservation()
