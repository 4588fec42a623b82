"""Gamma: the OV7670's piecewise-linear tone curve, as a lookup table on 10-bit codes.

The curve is 15 output values ``GAM1..GAM15`` (registers 0x7B..0x89) at the fixed 8-bit inputs
``GAMMA_X`` = 4, 8, 16, 32, 40, 48, 56, 64, 72, 80, 96, 112, 144, 176, 208, starting at (0, 0).
Above 208 the curve continues with the slope ``SLOP / 64`` (register 0x7A); the datasheet sets
``SLOP = (256 - GAM15) * 40 / 30``, which makes the last segment the line from (208, GAM15) to
(256, 256), as here. Between the points the output is interpolated linearly.
"""

import numpy as np

__all__ = ["GAMMA_CURVES", "GAMMA_X", "gamma_curve", "gamma_lut"]

#: The curve's input end points (8-bit scale), fixed in the chip.
GAMMA_X = (4, 8, 16, 32, 40, 48, 56, 64, 72, 80, 96, 112, 144, 176, 208)

#: Register sets GAM1..GAM15. "default": the power-on values (the project's board leaves them,
#: hw/board/sccb.py); "driver": the values OmniVision's implementation guide and the Linux
#: ov7670 driver write; "off": a straight line (gamma disabled).
GAMMA_CURVES = {
    "default": (
        0x04,
        0x07,
        0x10,
        0x28,
        0x36,
        0x44,
        0x52,
        0x60,
        0x6C,
        0x78,
        0x8C,
        0x9E,
        0xBB,
        0xD2,
        0xE5,
    ),
    "driver": (
        0x10,
        0x1E,
        0x35,
        0x5A,
        0x69,
        0x76,
        0x80,
        0x88,
        0x8F,
        0x96,
        0xA3,
        0xAF,
        0xC4,
        0xD7,
        0xE8,
    ),
    "off": GAMMA_X,
}


def gamma_curve(x, name="default"):
    """The curve ``name`` at 8-bit input(s) ``x`` (0..255, float), as float outputs 0..256."""
    ys = GAMMA_CURVES[name]
    # The last segment: from (208, GAM15) with slope (256 - GAM15) / 48, i.e. towards (256, 256).
    return np.interp(x, (0,) + GAMMA_X + (256,), (0,) + ys + (256,))


def gamma_lut(bits=10, name="default"):
    """``2**bits`` float32 entries: the curve at each ADC code, on the 8-bit output scale
    (0..255.x); code ``c`` stands for the input ``c * 256 / 2**bits``."""
    codes = np.arange(2**bits, dtype=np.float64) * (256.0 / 2**bits)
    return gamma_curve(codes, name).astype(np.float32)
