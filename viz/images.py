"""Frames to logged images: lossless PNG for small frames, JPEG above; the design's RGB444 as
RGB888.

PNG keeps every pixel: a frame read back from the recording equals the frame the design saw,
bit for bit. The encoder settings are chosen for the camera's frames: sensor noise defeats
deflate's string matches, so only runs are looked for (``STRATEGY_RLE``), after the filter
libpng picks per row among none, sub and up. The filtered frame (flat areas of few colours)
shrinks well with the same settings; both encode in under a millisecond at 160x120.
"""

import cv2
import numpy as np

from fpga_robotics.sim.camera.frames import rgb444_to_rgb888

from .errors import ViewerError

__all__ = [
    "AUTO_JPEG_QUALITY",
    "PNG_MAX_PIXELS",
    "check_jpeg_quality",
    "decode_image",
    "encode_frame",
    "filtered_rgb",
    "frame_kind",
]

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

# Packed RGB444 -> RGB888 for every 12-bit value: one gather per frame instead of shifts.
_RGB444_LUT = rgb444_to_rgb888(np.arange(4096, dtype=np.uint16)[None, :])[0]


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
