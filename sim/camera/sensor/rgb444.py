"""RGB444: the camera's output format keeps 4 bits a channel.

The design takes RGB888 and keeps each channel's top nibble (``c >> 4``, docs/contract.md); the
sensor model hands it RGB888 whose low nibble is zero (``c & 0xF0``, the contract's way back from
RGB444: ``c << 4``), so what the design sees is exactly the RGB444 word the camera sent and the
frames shown in the viewer are the camera's levels.
"""

import numpy as np

__all__ = ["rgb444_levels", "truncate_rgb444"]


def rgb444_levels(value8):
    """8-bit value(s) (float 0..255.x or int) to the RGB888 byte of their RGB444 level:
    the top 4 bits of the rounded, saturated 8-bit value, low nibble zero."""
    v = np.clip(np.floor(np.asarray(value8, dtype=np.float64) + 0.5), 0, 255).astype(np.uint8)
    return v & np.uint8(0xF0)


def truncate_rgb444(rgb888, out=None):
    """An RGB888 uint8 image with each channel's low nibble cleared (``c & 0xF0``)."""
    return np.bitwise_and(rgb888, np.uint8(0xF0), out=out)
