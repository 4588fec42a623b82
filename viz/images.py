"""Frames to logged images: lossless PNG for small frames, JPEG above; RGB444 shown as RGB888.

PNG keeps every pixel: a frame read back from the recording equals the frame logged, bit for
bit. Two kinds of frame are logged:

- RGB444 (``encode_rgb444``): the camera frame as the design receives it and the design's
  filtered frame, packed ``r << 8 | g << 4 | b`` and shown as RGB888 ``c << 4`` (the
  contract's way back, docs/contract.md). A rendered frame has a few dozen of the 4096 colours,
  so it is written as a palette PNG (one byte a pixel, Pillow); a frame of more than 256
  colours falls back to an RGB PNG. Always 8 bits a sample: the rerun viewer refuses an
  image stream whose PNGs change bit depth from frame to frame.
- RGB888 (``encode_frame``): the full 8-bit render. Its sensor noise defeats deflate's string
  matches, so only runs are looked for (``STRATEGY_RLE``), after the filter libpng picks per
  row among none, sub and up.
"""

import io

import cv2
import numpy as np
from PIL import Image

from fpga_robotics.sim.camera.frames import rgb444_to_rgb888, to_rgb444

from .errors import ViewerError

__all__ = [
    "AUTO_JPEG_QUALITY",
    "CAMERA_FORMATS",
    "PNG_MAX_PIXELS",
    "as_received",
    "check_camera_format",
    "check_jpeg_quality",
    "decode_image",
    "encode_frame",
    "encode_rgb444",
    "filtered_rgb",
    "frame_kind",
]

#: How the camera frame is recorded: ``rgb444`` as the design receives it (the default),
#: ``rgb888`` the full 8-bit render.
CAMERA_FORMATS = ("rgb444", "rgb888")

#: ``jpeg_quality=None`` (auto): frames up to this many pixels (160x120) are logged as PNG.
PNG_MAX_PIXELS = 160 * 120
#: ``jpeg_quality=None`` (auto): the JPEG quality of larger frames.
AUTO_JPEG_QUALITY = 85
#: The media type logged with each encoded kind (``rr.EncodedImage``).
MEDIA_TYPES = {"png": "image/png", "jpeg": "image/jpeg"}

_PNG_OPTIONS = [
    cv2.IMWRITE_PNG_COMPRESSION,
    1,
    cv2.IMWRITE_PNG_STRATEGY,
    cv2.IMWRITE_PNG_STRATEGY_RLE,
    cv2.IMWRITE_PNG_FILTER,
    cv2.IMWRITE_PNG_FAST_FILTERS,
]

# zlib level of the palette PNGs: 4 is the first with lazy matching, about a fifth smaller
# than 1 at the same cost on rendered frames; 6 saves a tenth more at twice the time.
_PALETTE_PNG_LEVEL = 4

# The fewest palette entries Pillow writes at 8 bits a pixel.
_MIN_PALETTE = 17

# Packed RGB444 -> RGB888 for every 12-bit value: one gather per frame instead of shifts.
_RGB444_LUT = rgb444_to_rgb888(np.arange(4096, dtype=np.uint16)[None, :])[0]


def check_camera_format(name):
    """``rgb444`` or ``rgb888`` (``CAMERA_FORMATS``)."""
    if name not in CAMERA_FORMATS:
        raise ViewerError(
            f"camera must be one of {', '.join(CAMERA_FORMATS)} (rgb444: the frame as the "
            f"design receives it; rgb888: the full 8-bit render), got {name!r}"
        )
    return name


def check_jpeg_quality(quality):
    """``None`` (auto), ``0`` (always raw) or 1..100 (always JPEG at that quality)."""
    if quality is None:
        return None
    if isinstance(quality, bool) or not isinstance(quality, int) or not 0 <= quality <= 100:
        raise ViewerError(
            f"jpeg_quality must be empty (auto), 0 (raw images) or 1..100, got {quality!r}"
        )
    return quality


def frame_kind(width, height, quality):
    """How a ``width`` x ``height`` frame is logged under ``quality``: ``"png"``, ``"jpeg"``
    or ``"raw"``."""
    if quality is None:
        return "png" if width * height <= PNG_MAX_PIXELS else "jpeg"
    return "jpeg" if quality > 0 else "raw"


def encode_frame(rgb, quality):
    """``(kind, data)``: ``("png", bytes)``, ``("jpeg", bytes)`` or ``("raw", a private copy
    of rgb)``, as ``frame_kind`` says.

    The copy matters: the row is sent a few frames later, and the caller may reuse its array.
    """
    h, w = rgb.shape[:2]
    kind = frame_kind(w, h, quality)
    if kind != "raw":
        bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)  # OpenCV writes BGR arrays as RGB files
        if kind == "png":
            ok, buf = cv2.imencode(".png", bgr, _PNG_OPTIONS)
        else:
            q = AUTO_JPEG_QUALITY if quality is None else quality
            ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, q])
        if ok:
            return kind, buf.tobytes()
    return "raw", np.array(rgb, dtype=np.uint8, order="C", copy=True)


def as_received(rgb):
    """The camera frame (H, W, 3) RGB888 as the design receives it: packed RGB444 (H, W),
    each channel's top four bits (``c >> 4``)."""
    return to_rgb444(rgb, rgb.shape[1], rgb.shape[0])


def _palette_png(packed):
    """Packed RGB444 (H, W) as a palette PNG of its colours (RGB888 ``c << 4``), or None when
    it has more than 256."""
    present = np.flatnonzero(np.bincount(packed.ravel(), minlength=4096))
    if len(present) > 256:
        return None
    index = np.zeros(4096, np.uint8)
    index[present] = np.arange(len(present), dtype=np.uint8)
    img = Image.fromarray(index[packed])
    # At least 17 entries: Pillow packs a palette of 16 or fewer into fewer bits a pixel,
    # which the viewer refuses mid-stream. An "L" image becomes "P".
    palette = np.zeros((max(len(present), _MIN_PALETTE), 3), np.uint8)
    palette[: len(present)] = _RGB444_LUT[present]
    img.putpalette(palette.tobytes())
    buf = io.BytesIO()
    img.save(buf, "PNG", compress_level=_PALETTE_PNG_LEVEL)
    return buf.getvalue()


def encode_rgb444(packed, quality):
    """``(kind, data)`` of a packed RGB444 frame (H, W), shown as RGB888 ``c << 4``: a palette
    PNG where ``frame_kind`` says PNG (an RGB PNG above 256 colours), else as ``encode_frame``
    of its RGB888."""
    packed = np.asarray(packed, dtype=np.uint16)
    h, w = packed.shape
    if frame_kind(w, h, quality) == "png":
        data = _palette_png(packed)
        if data is not None:
            return "png", data
    return encode_frame(filtered_rgb(packed), quality)


def decode_image(data):
    """The RGB888 image (H, W, 3) of PNG or JPEG bytes (``encode_frame``'s inverse)."""
    bgr = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError("not a PNG or JPEG image")
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def filtered_rgb(packed):
    """The design's filtered frame (packed RGB444, (H, W)) as RGB888, equal to
    ``rgb444_to_rgb888(packed)``."""
    # np.take is several times faster than fancy indexing for a row gather.
    return np.take(_RGB444_LUT, np.asarray(packed, dtype=np.uint16), axis=0)
