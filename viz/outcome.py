"""The end of a recording: keep or drop its file, and the line that says where it went.

The line names the file's size; when the folder it is in holds more than
``LARGE_FOLDER_BYTES`` of recordings, it says so and how to record nothing, so that a folder
of default-named runs (``runs/``) does not fill the disk unnoticed.
"""

import os
from pathlib import Path

__all__ = ["LARGE_FOLDER_BYTES", "recordings_bytes", "settle"]

#: A recording's folder holding more ``.rrd`` bytes than this is named in the closing line.
LARGE_FOLDER_BYTES = 500 * 10**6


def recordings_bytes(folder):
    """The bytes of the ``.rrd`` files in ``folder`` (not below it), hidden partial files of
    runs that were killed included."""
    total = 0
    for path in Path(folder).glob("*.rrd"):
        try:
            if path.is_file():
                total += path.stat().st_size
        except OSError:  # removed meanwhile, or unreadable: not ours to count
            continue
    return total


def _folder_hint(path):
    folder = Path(path).parent
    held = recordings_bytes(folder)
    if held <= LARGE_FOLDER_BYTES:
        return ""
    where = folder.as_posix().rstrip("/")
    return f" ({where}/ holds {held / 1e6:.0f} MB; --rerun off skips the recording)"


def _saved(file, frames):
    size = os.path.getsize(file.path)
    per = size / frames if frames else 0
    text = f"{file.path} ({size / 1e6:.1f} MB, {per / 1e3:.1f} kB/frame)"
    if file.replaced:
        text += ", replacing an earlier recording there"
    return f"{text}; open it with: rerun {file.path}{_folder_hint(file.path)}"


def _keep(file):
    failed = file.keep()
    return f"the recording could not be saved: {failed}" if failed else None


def settle(output, confirmed, problem, frames, images):
    """Keep the file (or drop a copy whose stream was delivered); returns ``(line, path)``,
    ``path`` the file kept or ``None``.

    ``confirmed`` and ``problem`` come from ``Output.finish``; ``frames`` and ``images`` count
    the frames logged and those with images.
    """
    counted = f"{frames} frames ({images} with images)"
    file = output.file
    if frames == 0 and file is not None:
        # The run stopped before its first frame (an error, Ctrl-C): an empty recording
        # would only replace an earlier one or sit there looking like a run.
        file.discard()
        text = "no frame was recorded, so no file was written"
        if output.kind != "save":
            return f"{output.description}: {text}", None
        return (f"{output.reason}; {text}" if output.reason else text), None
    if output.kind == "save":
        failed = _keep(file)
        text = failed or f"saved {counted} to {_saved(file, frames)}"
        if problem:
            text = f"{text} ({problem})"
        return (
            f"{output.reason}; {text}" if output.reason else text
        ), None if failed else file.path
    if file is None:  # a live stream with no default path
        text = f"{output.description}: {counted}"
        return (text if confirmed else f"{text}; {problem}, and no file was kept"), None
    if confirmed and not output.keep_copy:
        file.discard()
        return f"streamed {counted} to {output.description}", None
    failed = _keep(file)
    if output.kind == "serve":
        head = f"{output.description} (stopped with the run): {counted}"
    else:
        head = f"{problem}, so not every frame may have reached it"
    if failed:
        return f"{head}; {failed}", None
    return f"{head}; all of it is saved to {_saved(file, frames)}", file.path
