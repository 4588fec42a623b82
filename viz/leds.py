"""The board's LEDs as small RGB images: one square cell per LED, left to right.

Each LED is a ``CELL`` x ``CELL`` square; ``GAP`` dark pixels separate the cells and frame the
row, so an image of ``n`` LEDs is ``CELL + 2*GAP`` high and ``n*(CELL + GAP) + GAP`` wide.
The viewer magnifies them with nearest-neighbour filtering, so they stay crisp.
"""

import numpy as np

__all__ = [
    "CELL",
    "CENTROID_LEDS",
    "GAP",
    "PROXIMITY_LEDS",
    "cell_centre",
    "centroid_image",
    "led_row_image",
    "proximity_image",
]

CELL = 6
GAP = 2
#: The proximity bar: 7 segments, segment i lit when proximity > i (level 0 = all dark).
PROXIMITY_LEDS = 7
#: The centroid LEDs: 8, bit 0 = leftmost.
CENTROID_LEDS = 8

_BACKGROUND = (16, 16, 16)
_OFF = (48, 48, 48)
_CENTROID_ON = (255, 40, 40)  # the board's red user LEDs
# A level meter: far (green) to very close (red).
_PROXIMITY_ON = (
    (40, 220, 40),
    (90, 230, 40),
    (150, 230, 30),
    (210, 220, 20),
    (250, 170, 20),
    (250, 110, 20),
    (250, 40, 30),
)


def cell_centre(i):
    """``(row, column)`` of the centre pixel of LED ``i`` in a row image."""
    return GAP + CELL // 2, GAP + i * (CELL + GAP) + CELL // 2


def led_row_image(lit, on_colors):
    """An RGB image of a row of LEDs; ``lit[i]`` turns LED ``i`` on in ``on_colors[i]``."""
    n = len(lit)
    img = np.empty((CELL + 2 * GAP, n * (CELL + GAP) + GAP, 3), np.uint8)
    img[:] = _BACKGROUND
    for i, on in enumerate(lit):
        x0 = GAP + i * (CELL + GAP)
        img[GAP : GAP + CELL, x0 : x0 + CELL] = on_colors[i] if on else _OFF
    return img


def _cached(builder, n):
    # Every possible state is precomputed once: logging then costs one lookup per frame.
    return [builder(state) for state in range(n)]


def _proximity(level):
    return led_row_image([level > i for i in range(PROXIMITY_LEDS)], _PROXIMITY_ON)


def _centroid(bits):
    lit = [(bits >> i) & 1 for i in range(CENTROID_LEDS)]
    return led_row_image(lit, [_CENTROID_ON] * CENTROID_LEDS)


_PROXIMITY_IMAGES = _cached(_proximity, PROXIMITY_LEDS + 1)
_CENTROID_IMAGES = _cached(_centroid, 1 << CENTROID_LEDS)
for _img in _PROXIMITY_IMAGES + _CENTROID_IMAGES:
    _img.flags.writeable = False


def proximity_image(level):
    """The proximity bar for ``level`` 0..7: segments 0..level-1 lit (read-only array)."""
    if not 0 <= int(level) <= PROXIMITY_LEDS:
        raise ValueError(f"proximity must be 0..{PROXIMITY_LEDS}, got {level}")
    return _PROXIMITY_IMAGES[int(level)]


def centroid_image(bits):
    """The 8 centroid LEDs for the 8-bit code ``bits`` (bit 0 = leftmost; read-only array)."""
    if not 0 <= int(bits) < (1 << CENTROID_LEDS):
        raise ValueError(f"centroid_leds must be 0..255, got {bits}")
    return _CENTROID_IMAGES[int(bits)]
