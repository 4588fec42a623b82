"""Where a camera frame's pixels fall on the design's clock in real-clock time: the lines of
a frame spread over the frame period as an OV7670 spreads them (510 line periods per frame
for its 480 active lines at VGA), and a line's pixels inside the first 640/784 of the line
period (its active part of a VGA line)."""

from .base import PinError, PixelTiming

__all__ = ["ACTIVE_LINE_FRACTION", "LINES_PER_ACTIVE_LINE", "real_clock_timing"]

#: Line periods per frame over active lines (OV7670 VGA: 510 / 480).
LINES_PER_ACTIVE_LINE = (510, 480)
#: The active part of a line period (OV7670 VGA: 640 of 784 pixel clocks).
ACTIVE_LINE_FRACTION = (640, 784)


def real_clock_timing(width, height, fps, clock_hz, start_edge):
    """The ``PixelTiming`` of a ``width`` x ``height`` frame at ``fps`` frames per second on a
    ``clock_hz`` design clock, its first pixel at edge ``start_edge``:
    ``total_lines = round(height * 510 / 480)``, ``line_period = frame_cycles //
    total_lines`` with ``frame_cycles = round(clock_hz / fps)``, and ``pixel_period =
    max(1, (line_period * 640 // 784) // width)``."""
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise PinError(f"{name} must be a positive int, not {value!r}")
    if not fps > 0 or not clock_hz > 0:
        raise PinError(f"fps and clock_hz must be positive (got {fps}, {clock_hz})")
    frame_cycles = round(clock_hz / fps)
    total_lines = round(height * LINES_PER_ACTIVE_LINE[0] / LINES_PER_ACTIVE_LINE[1])
    line_period = frame_cycles // total_lines
    active, whole = ACTIVE_LINE_FRACTION
    pixel_period = max(1, (line_period * active // whole) // width)
    if line_period < (width - 1) * pixel_period + 1:
        raise PinError(
            f"a {clock_hz:g} Hz clock has {line_period} cycles per line at {fps:g} "
            f"fps, too few for {width} pixels; lower the resolution or fps"
        )
    return PixelTiming(start=start_edge, line_period=line_period, pixel_period=pixel_period)
