"""The end of a recording: keep or drop its file, and the line that says where it went."""

import os

__all__ = ["settle"]


def _saved(file, frames):
    size = os.path.getsize(file.path)
    per = size / frames if frames else 0
    text = f"{file.path} ({size / 1e6:.1f} MB, {per / 1e3:.1f} kB/frame)"
    if file.replaced:
        text += ", replacing an earlier recording there"
    return f"{text}; open it with: rerun {file.path}"


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
    if output.kind == "save":
        failed = _keep(file)
        text = failed or f"saved {counted} to {_saved(file, frames)}"
        if problem:
            text = f"{text} ({problem})"
        return (f"{output.reason}; {text}" if output.reason else text), None if failed else file.path
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
