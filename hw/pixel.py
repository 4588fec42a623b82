"""RGB444 pixels and the framed pixel stream shared by every stage of the design.

The pixel layout is the camera's RGB444 order: ``r`` in bits 11:8, ``g`` in 7:4, ``b`` in 3:0.
A stream transfer carries one pixel plus two framing flags, as AXI4-Stream video does:
``first`` marks the first pixel of a frame, ``last`` the last pixel of every line.
The stream cannot be stalled (``always_ready``): a camera does not wait.
"""

from amaranth.lib import data, stream

from .errors import ParamError

__all__ = [
    "COLOR_SELECT", "RGB444", "FramedPixel", "color_select_value", "pixel_stream_signature",
]


#: One RGB444 pixel, 12 bits. Struct fields are laid out LSB first.
RGB444 = data.StructLayout({"b": 4, "g": 4, "r": 4})

#: A pixel with its framing flags, 14 bits: pixel 11:0, ``first`` bit 12, ``last`` bit 13.
FramedPixel = data.StructLayout({"pixel": RGB444, "first": 1, "last": 1})


def pixel_stream_signature():
    """Signature of a framed, non-stallable pixel stream (source side)."""
    return stream.Signature(FramedPixel, always_ready=True)


#: ``color_sel`` codes of the colour filter: bit 2 red, bit 1 green, bit 0 blue.
COLOR_SELECT = {
    "none": 0b000,
    "blue": 0b001,
    "green": 0b010,
    "cyan": 0b011,
    "red": 0b100,
    "magenta": 0b101,
    "yellow": 0b110,
    "white": 0b111,
}


def color_select_value(color):
    """Return the 3-bit ``color_sel`` code for a colour name or an int 0..7."""
    if isinstance(color, str):
        try:
            return COLOR_SELECT[color.lower()]
        except KeyError:
            raise ParamError(
                f"unknown colour {color!r}; choose one of: {', '.join(COLOR_SELECT)}"
            ) from None
    if isinstance(color, bool) or not isinstance(color, int) or not 0 <= color <= 7:
        raise ParamError(f"color_sel must be a colour name or an int 0..7, not {color!r}")
    return color
