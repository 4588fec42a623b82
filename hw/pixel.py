"""RGB444 pixels and the framed pixel stream shared by every stage of the design.

The pixel layout is the camera's RGB444 order: ``r`` in bits 11:8, ``g`` in 7:4, ``b`` in 3:0.
A stream transfer carries one pixel plus two framing flags, as AXI4-Stream video does:
``first`` marks the first pixel of a frame, ``last`` the last pixel of every line.
The stream cannot be stalled (``always_ready``): a camera does not wait.
"""

import numbers
from types import MappingProxyType

from amaranth.lib import data, enum, stream

from .errors import ParamError

__all__ = [
    "COLOR_SELECT",
    "RGB444",
    "FramedPixel",
    "TargetColor",
    "color_select_value",
    "pixel_stream_signature",
]


#: One RGB444 pixel, 12 bits. Struct fields are laid out LSB first.
RGB444 = data.StructLayout({"b": 4, "g": 4, "r": 4})

#: A pixel with its framing flags, 14 bits: pixel 11:0, ``first`` bit 12, ``last`` bit 13.
FramedPixel = data.StructLayout({"pixel": RGB444, "first": 1, "last": 1})


def pixel_stream_signature():
    """Signature of a framed, non-stallable pixel stream (source side)."""
    return stream.Signature(FramedPixel, always_ready=True)


class TargetColor(enum.Enum, shape=3):
    """The colour filter's ``color_sel`` codes: bit 2 red, bit 1 green, bit 0 blue."""

    NONE = 0b000  # every pixel matches
    BLUE = 0b001
    GREEN = 0b010
    CYAN = 0b011
    RED = 0b100
    MAGENTA = 0b101
    YELLOW = 0b110
    WHITE = 0b111


#: Lower-case colour names to ``TargetColor`` codes (ints), for host code that reads names
#: from scenarios, command lines and ROS topics.
COLOR_SELECT = MappingProxyType({color.name.lower(): color.value for color in TargetColor})


def color_select_value(color):
    """Return the 3-bit ``color_sel`` code (an int) for a colour name, a ``TargetColor`` or an
    integer 0..7 (numpy's too: a run's recorded ``color_sel`` column)."""
    if isinstance(color, TargetColor):
        return color.value
    if isinstance(color, str):
        try:
            return TargetColor[color.upper()].value
        except KeyError:
            raise ParamError(
                f"unknown colour {color!r}; choose one of: {', '.join(COLOR_SELECT)}"
            ) from None
    if isinstance(color, bool) or not isinstance(color, numbers.Integral) or not 0 <= color <= 7:
        raise ParamError(f"color_sel must be a colour name or an int 0..7, not {color!r}")
    return int(color)
