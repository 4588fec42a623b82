"""Read a saved recording back (tests, checks) and summarise it.

``fpga-robotics readback FILE.rrd`` prints the summary (the command itself is
``fpga_robotics.cli.readback``, the application layer).

Built on ``rerun.chunk.RrdReader``. Every temporal row of an entity is returned with its
``frame`` and ``sim_time`` (ns), sorted by frame; each component value is the list of its
instances (plain Python values), except byte blobs (image buffers, PNG and JPEG data), which
come back as uint8 numpy arrays. ``images(rec, path)`` turns an image entity's rows back into
pixels, whichever way they were logged (``viz.images``).
"""

import os
import sys
import warnings
from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa
from rerun.chunk import RrdReader

from .errors import ViewerError
from .images import decode_image

__all__ = ["EntityRows", "Recording", "images", "read_rrd", "summary_lines"]

_INDEX_COLUMNS = ("frame", "sim_time", "log_time", "log_tick")
_RRD_MAGIC = b"RRF"


@dataclass
class EntityRows:
    """The temporal rows of one entity: ``frames[i]``, ``sim_time_ns[i]``, ``values[component][i]``."""

    frames: list = field(default_factory=list)
    sim_time_ns: list = field(default_factory=list)
    values: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.frames)


@dataclass
class Recording:
    """A recording read back: temporal rows and static values per entity path (no leading /)."""

    entities: dict
    static: dict
    blueprints: int
    size_bytes: int


def _is_blob(t):
    return pa.types.is_list(t) and pa.types.is_uint8(t.value_type)


def _row_values(column):
    """One Python value per row: the list of the row's instances."""
    out = []
    blob = _is_blob(column.type.value_type)
    for i in range(len(column)):
        if not column[i].is_valid:
            out.append(None)
        elif blob:
            out.append([np.asarray(x.values) for x in column[i].values])
        else:
            out.append(column[i].values.to_pylist())
    return out


def _has_rrd_header(path):
    """Whether the file starts as every rerun recording does (its FourCC, ``RRF`` + version)."""
    with open(path, "rb") as f:
        return f.read(3) == _RRD_MAGIC


def read_rrd(path):
    """Read the first recording in ``path``; returns a ``Recording``."""
    if os.path.isdir(path):
        raise ViewerError(f"{path} is a folder, not a recording (.rrd)")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"no recording at {str(path)!r}")
    if os.path.getsize(path) == 0:
        raise ViewerError(f"{path} is empty, not a rerun recording (.rrd)")
    try:
        with warnings.catch_warnings():
            # Said of a cut-off file too, which then fails below with one line of its own;
            # a whole one is read by the scan that warning announces.
            warnings.filterwarnings("ignore", message="RRD file has no footer")
            reader = RrdReader(path)
        chunks = list(reader.stream())
    except RuntimeError as exc:  # rerun's word for a file it cannot decode
        said = str(exc).splitlines()[0]
        if _has_rrd_header(path):  # a recording's start, not its end: cut off or damaged
            raise ViewerError(
                f"{path} is a cut-off or damaged rerun recording ({said}); a recording is "
                "whole once its run has printed 'saved ...': wait for that, or copy it again"
            ) from None
        raise ViewerError(f"{path} is not a rerun recording (.rrd): {said}") from None
    except ValueError as exc:  # an .rrd with only a blueprint (a saved layout, .rbl)
        raise ViewerError(
            f"{path} holds no recording (a viewer layout at most): {str(exc).splitlines()[0]}"
        ) from None
    entities, static = {}, {}
    for chunk in chunks:
        name = chunk.entity_path.lstrip("/")
        batch = chunk.to_record_batch()
        comps = [
            f.name
            for f in batch.schema
            if f.name not in _INDEX_COLUMNS and (f.metadata or {}).get(b"rerun:kind") == b"data"
        ]
        if chunk.is_static:
            target = static.setdefault(name, {})
            for c in comps:
                target[c] = _row_values(batch.column(c))[-1]
            continue
        rows = entities.setdefault(name, EntityRows())
        n = batch.num_rows
        frames = batch.column("frame").to_pylist() if "frame" in batch.schema.names else [None] * n
        if "sim_time" in batch.schema.names:
            times = batch.column("sim_time").cast(pa.int64()).to_pylist()
        else:
            times = [None] * n
        start = len(rows.frames)
        rows.frames.extend(frames)
        rows.sim_time_ns.extend(times)
        for c in comps:
            rows.values.setdefault(c, [None] * start).extend(_row_values(batch.column(c)))
        for c, vals in rows.values.items():
            vals.extend([None] * (len(rows.frames) - len(vals)))
    for rows in entities.values():
        order = sorted(
            range(len(rows.frames)), key=lambda i: (rows.frames[i] is None, rows.frames[i])
        )
        rows.frames = [rows.frames[i] for i in order]
        rows.sim_time_ns = [rows.sim_time_ns[i] for i in order]
        rows.values = {c: [v[i] for i in order] for c, v in rows.values.items()}
    return Recording(entities, static, len(reader.blueprints()), os.path.getsize(path))


# rerun's ColorModel values -> channels per pixel, and the ChannelDatatype of uint8.
_CHANNELS = {1: 1, 2: 3, 3: 4}  # L, RGB, RGBA
_U8 = 6


def _pixels(buffer, fmt):
    if fmt is None or fmt.get("color_model") not in _CHANNELS or fmt.get("channel_datatype") != _U8:
        raise ValueError(f"an image format this reader does not know: {fmt!r}")
    shape = (fmt["height"], fmt["width"], _CHANNELS[fmt["color_model"]])
    return np.asarray(buffer, dtype=np.uint8).reshape(shape)


def images(rec, path):
    """``{frame: (H, W, C) uint8}``: every image row of entity ``path`` as pixels, from raw
    ``Image`` rows (their format per row, or the static one) and from PNG or JPEG
    ``EncodedImage`` rows alike."""
    rows = rec.entities.get(path)
    if rows is None:
        raise KeyError(f"no entity {path!r} in the recording")
    static_fmt = (rec.static.get(path, {}).get("Image:format") or [None])[0]
    buffers = rows.values.get("Image:buffer", [None] * len(rows))
    formats = rows.values.get("Image:format", [None] * len(rows))
    blobs = rows.values.get("EncodedImage:blob", [None] * len(rows))
    out = {}
    for frame, buf, fmt, blob in zip(rows.frames, buffers, formats, blobs):
        if blob:
            out[frame] = decode_image(blob[0])
        elif buf:
            out[frame] = _pixels(buf[0], fmt[0] if fmt else static_fmt)
    return out


def _image_bytes(rows):
    """``", PNG 26.4 kB each"``: how the rows' images are stored and their mean size, or ``""``."""
    for column, kind in (("EncodedImage:blob", None), ("Image:buffer", "raw")):
        blobs = [row[0] for row in rows.values.get(column, ()) if row]
        if blobs:
            if kind is None:
                types = {
                    t for row in rows.values.get("EncodedImage:media_type", ()) if row for t in row
                }
                kind = "/".join(sorted(t.removeprefix("image/").upper() for t in types)) or "?"
            return f", {kind} {sum(len(b) for b in blobs) / len(blobs) / 1e3:.1f} kB each"
    return ""


def summary_lines(rec, name):
    """Lines describing a ``Recording`` read from ``name``: size, frames, rows per entity.

    The frames are the distinct steps of the ``frame`` timeline over every entity, so any
    design's recording counts them, whatever entities it logs."""
    frames = len({f for rows in rec.entities.values() for f in rows.frames if f is not None})
    head = f"{name}: {rec.size_bytes / 1e6:.2f} MB, {frames} frames"
    if frames:
        head += f", {rec.size_bytes / frames / 1e3:.1f} kB/frame"
    lines = [head, f"blueprints: {rec.blueprints}"]
    lines += [
        f"  {path:22s} {len(rec.entities[path]):6d} rows{_image_bytes(rec.entities[path])}"
        for path in sorted(rec.entities)
    ]
    lines += [
        f"  {path:22s} static: {', '.join(sorted(rec.static[path]))}" for path in sorted(rec.static)
    ]
    return lines


if __name__ == "__main__":
    # A library module: the command that reads a recording is the application layer's, which
    # this layer does not import. Without this, `python -m` ran nothing and exited 0.
    print(
        "python -m fpga_robotics.viz.readback: error: a library module; read a recording "
        "with: fpga-robotics readback FILE.rrd",
        file=sys.stderr,
    )
    sys.exit(2)
