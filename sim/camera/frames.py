"""Conversions between host images and the design's RGB444 pixels, with clear errors.

Host frames are RGB888 arrays (H x W x 3, uint8, channels in R, G, B order). The design sees
RGB444 packed in a uint16 as ``r << 8 | g << 4 | b``; a channel keeps its top 4 bits (``c >> 4``)
and goes back to 8 bits as ``c << 4``.
"""

import numpy as np

from fpga_robotics.hw.errors import UserError

__all__ = ["FrameError", "rgb444_to_rgb888", "to_rgb444", "unpack_rgb444"]


class FrameError(UserError, ValueError):
    """A frame of the wrong shape, dtype or value range."""


def to_rgb444(frame, width, height):
    """Return ``frame`` as a contiguous (height, width) uint16 array of packed RGB444.

    Accepts an RGB888 image (height, width, 3) of uint8, or an already packed RGB444 array
    (height, width) of uint16 (or a wider unsigned dtype) with values below 4096.
    """
    if not isinstance(frame, np.ndarray):
        raise FrameError(f"a frame must be a numpy array, not {type(frame).__name__}")
    if frame.ndim == 3:
        if frame.shape != (height, width, 3):
            raise FrameError(
                f"an RGB888 frame must have shape ({height}, {width}, 3) for a {width}x{height} "
                f"design, got {frame.shape}; resize it (cv2.resize) or build the design for "
                f"that resolution"
            )
        if frame.dtype != np.uint8:
            raise FrameError(f"an RGB888 frame must be uint8, got {frame.dtype}")
        f = frame.astype(np.uint16) >> 4
        return np.ascontiguousarray((f[..., 0] << 8) | (f[..., 1] << 4) | f[..., 2])
    if frame.ndim == 2:
        if frame.shape != (height, width):
            raise FrameError(
                f"a packed RGB444 frame must have shape ({height}, {width}) for a "
                f"{width}x{height} design, got {frame.shape}"
            )
        if frame.dtype == np.uint8:
            # 8 bits cannot hold a 12-bit pixel: a greyscale image, whose 192 would read as
            # green 12 (0x0C0).
            raise FrameError(
                f"a packed RGB444 frame must be uint16 (12-bit pixels), got uint8 {frame.shape}: "
                f"a greyscale image? give RGB888 ({height}, {width}, 3) uint8 instead "
                f"(cv2.cvtColor(image, cv2.COLOR_GRAY2RGB))"
            )
        if frame.dtype.kind != "u":
            raise FrameError(
                f"a packed RGB444 frame must have an unsigned integer dtype (uint16), "
                f"got {frame.dtype}"
            )
        if frame.size and int(frame.max()) > 0xFFF:
            raise FrameError("a packed RGB444 frame holds 12-bit values; found one above 0xFFF")
        return np.ascontiguousarray(frame, dtype=np.uint16)
    raise FrameError(
        f"a frame must be (H, W, 3) RGB888 or (H, W) packed RGB444, got shape {frame.shape}"
    )


def unpack_rgb444(packed):
    """Split packed RGB444 into three int arrays ``r, g, b`` (0..15 each)."""
    p = np.asarray(packed).astype(np.int32)
    return (p >> 8) & 0xF, (p >> 4) & 0xF, p & 0xF


def rgb444_to_rgb888(packed):
    """Packed RGB444 (H, W) to an RGB888 image (H, W, 3) uint8, each channel ``c << 4``."""
    r, g, b = unpack_rgb444(packed)
    return (np.stack([r, g, b], axis=-1) << 4).astype(np.uint8)
