"""Frames to logged images: raw for small frames, JPEG above; the design's RGB444 as RGB888."""

import cv2
import numpy as np

from fpga_robotics.sim.camera.frames import rgb444_to_rgb888
from .errors import ViewerError

__all__ = [
    "AUTO_JPEG_QUALITY",
    "RAW_MAX_PIXELS",
    "check_jpeg_quality",
    "filtered_rgb",
    "uses_jpeg",
]

#: ``jpeg_quality=None`` (auto): frames up to this many pixels (160x120) are logged raw.
RAW_MAX_PIXELS = 160 * 120
#: ``jpeg_quality=None`` (auto): the JPEG quality of larger frames.
AUTO_JPEG_QUALITY = 85

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


def uses_jpeg(width, height, quality):
    """Whether a ``width`` x ``height`` frame is logged as JPEG under ``quality``."""
    if quality is None:
        return width * height > RAW_MAX_PIXELS
    return quality > 0


def encode_frame(rgb, quality):
    """``("raw", a private copy of rgb)`` or ``("jpeg", bytes)`` when ``uses_jpeg``.

    The copy matters: the row is sent a few frames later, and the caller may reuse its array.
    """
    h, w = rgb.shape[:2]
    if uses_jpeg(w, h, quality):
        q = AUTO_JPEG_QUALITY if quality is None else quality
        bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
        ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, q])
        if ok:
            return "jpeg", buf.tobytes()
    return "raw", np.array(rgb, dtype=np.uint8, order="C", copy=True)


def filtered_rgb(packed):
    """The design's filtered frame (packed RGB444, (H, W)) as RGB888, equal to
    ``rgb444_to_rgb888(packed)``."""
    # np.take is several times faster than fancy indexing for a row gather.
    return np.take(_RGB444_LUT, np.asarray(packed, dtype=np.uint16), axis=0)
