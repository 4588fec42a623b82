"""Per-frame rows buffered and sent to rerun as columns, one ``send_columns`` per entity.

A ``rr.log`` call costs tens of microseconds of Python, whatever its size; a frame has about
fifteen small entities. Buffering their rows and sending each entity's rows as one column
every few frames (or every 0.1 s, so a live viewer lags by at most that) keeps logging far
below a millisecond per frame. Each row keeps its own ``frame`` and ``sim_time``, so the
recording is the same as with one ``rr.log`` per row.

A file nobody watches live (``FILE_ONLY``) is sent every 128 frames, whatever the time: every
column sent is a chunk with its own schema, so fewer, longer chunks make a smaller file, and
its chunks no longer depend on the machine's speed. The images buffered are bounded all the
same (``MAX_IMAGE_BYTES``).
"""

import contextlib
import time

import numpy as np
import rerun as rr

__all__ = [
    "ColumnBuffer",
    "arrows",
    "images",
    "jpegs",
    "pngs",
    "points",
    "rgb_images",
    "scalars",
    "strips",
    "time_ns",
]

#: Send when this many frames are buffered or this much wall time passed since the last send.
MAX_FRAMES = 32
MAX_SECONDS = 0.1
#: ``(frames, seconds)`` for a file nobody watches live: no time limit.
FILE_ONLY = (128, None)
#: Send, whatever the frames and time, when the images buffered hold this many bytes.
MAX_IMAGE_BYTES = 32 << 20


def time_ns(seconds):
    """Simulated seconds as a ``timedelta64[ns]`` (the same value for rows and images)."""
    return np.timedelta64(round(float(seconds) * 1e9), "ns")


def scalars(rows):
    """Rows of equal-length float tuples -> ``Scalars`` column (one series per position)."""
    return rr.Scalars.columns(scalars=np.asarray(rows, dtype=np.float64))


def images(rows):
    """Rows of equal-shape uint8 images -> ``Image`` buffer column (format logged static)."""
    return rr.Image.columns(buffer=np.stack(rows).reshape(len(rows), -1))


def rgb_images(rows):
    """Rows of RGB888 images (any sizes) -> ``Image`` buffer and format columns."""
    formats = [
        rr.components.ImageFormat(
            width=r.shape[1], height=r.shape[0], color_model="RGB", channel_datatype="U8"
        )
        for r in rows
    ]
    return rr.Image.columns(buffer=[r.reshape(-1) for r in rows], format=formats)


def jpegs(rows):
    """Rows of JPEG bytes -> ``EncodedImage`` columns."""
    return rr.EncodedImage.columns(blob=rows, media_type=["image/jpeg"] * len(rows))


def pngs(rows):
    """Rows of PNG bytes -> ``EncodedImage`` columns."""
    return rr.EncodedImage.columns(blob=rows, media_type=["image/png"] * len(rows))


def arrows(rows):
    """Rows ``(ox, oy, vx, vy)`` -> one arrow per row."""
    a = np.asarray(rows, dtype=np.float32)
    return rr.Arrows2D.columns(origins=a[:, :2], vectors=a[:, 2:])


def strips(rows):
    """Rows of one line strip each (equal point counts) -> one strip per row."""
    return rr.LineStrips2D.columns(strips=np.asarray(rows, dtype=np.float32))


def points(rows):
    """Rows of ``(positions, radii, colors, labels)`` lists -> a point batch per row."""
    lengths = [len(r[0]) for r in rows]
    cols = rr.Points2D.columns(
        positions=np.asarray([p for r in rows for p in r[0]], dtype=np.float32).reshape(-1, 2),
        radii=np.asarray([x for r in rows for x in r[1]], dtype=np.float32),
        colors=np.asarray([c for r in rows for c in r[2]], dtype=np.uint8).reshape(-1, 3),
        labels=[s for r in rows for s in r[3]],
    )
    return cols.partition(lengths)


class _Rows:
    __slots__ = ("data", "frames", "times")

    def __init__(self):
        self.frames, self.times, self.data = [], [], []


class ColumnBuffer:
    """Buffer rows per key; ``builders[key](rows)`` turns them into columns.

    A key is an entity path, or ``(path, variant)`` when one entity takes rows of different
    kinds (raw, PNG or JPEG images): each variant is sent as its own columns. ``guard`` is entered
    around each send (``viz.live.StallWatch``: a viewer that blocks it for long is cut off).
    """

    def __init__(self, stream, builders, guard=None, *, max_frames=None, max_seconds=MAX_SECONDS):
        self._stream = stream
        self._max_frames = MAX_FRAMES if max_frames is None else max_frames
        self._max_seconds = max_seconds  # None: no time limit
        self._image_bytes = 0
        self._builders = builders
        self._guard = guard if guard is not None else contextlib.nullcontext()
        self._rows = {path: _Rows() for path in builders}
        self._frames = 0
        self._last_send = time.monotonic()

    def register(self, key, builder):
        """Take rows for ``key`` from now on (an entity that appears during a run); returns
        whether it is new."""
        if key in self._builders:
            return False
        self._builders = {**self._builders, key: builder}
        self._rows[key] = _Rows()
        return True

    def add(self, path, frame, t_ns, row):
        r = self._rows[path]
        r.frames.append(frame)
        r.times.append(t_ns)
        r.data.append(row)
        if isinstance(row, bytes | np.ndarray):  # an image (PNG, JPEG or raw)
            self._image_bytes += len(row) if isinstance(row, bytes) else row.nbytes

    def drop_frame(self, frame):
        """Drop the rows of ``frame`` not sent yet: a frame whose logging was cut short (Ctrl-C)
        is not kept in part."""
        for r in self._rows.values():
            while r.frames and r.frames[-1] == frame:
                r.frames.pop()
                r.times.pop()
                row = r.data.pop()
                if isinstance(row, bytes | np.ndarray):
                    self._image_bytes -= len(row) if isinstance(row, bytes) else row.nbytes

    def end_frame(self):
        """Count a frame; send when enough frames or time have gone by."""
        self._frames += 1
        if (
            self._frames >= self._max_frames
            or self._image_bytes >= MAX_IMAGE_BYTES
            or (
                self._max_seconds is not None
                and time.monotonic() - self._last_send >= self._max_seconds
            )
        ):
            self.flush()

    def flush(self):
        for key, r in self._rows.items():
            if not r.frames:
                continue
            columns = self._builders[key](r.data)
            with self._guard:
                self._stream.send_columns(
                    key if isinstance(key, str) else key[0],
                    indexes=[
                        rr.TimeColumn("frame", sequence=r.frames),
                        rr.TimeColumn(
                            "sim_time", duration=np.array(r.times, dtype="timedelta64[ns]")
                        ),
                    ],
                    columns=columns,
                )
            self._rows[key] = _Rows()
        self._frames = 0
        self._image_bytes = 0
        self._last_send = time.monotonic()
