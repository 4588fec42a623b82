"""The LED images: a proximity bar lit up to the level, and 8 centroid LEDs, bit 0 leftmost."""

import numpy as np
import pytest

from fpga_robotics.viz.leds import CELL, GAP, cell_centre, centroid_image, proximity_image


def lit(img, n):
    # A lit LED is bright; an unlit one is dark grey (every channel below 100).
    return [int(img[cell_centre(i)].max()) > 100 for i in range(n)]


@pytest.mark.parametrize("level", range(8))
def test_proximity_bar_lights_level_segments_from_the_left(level):
    img = proximity_image(level)
    assert img.shape == (CELL + 2 * GAP, 7 * (CELL + GAP) + GAP, 3) and img.dtype == np.uint8
    assert lit(img, 7) == [True] * level + [False] * (7 - level)


@pytest.mark.parametrize("bits", [0, 1, 0x80, 0b00011000, 0xFF, 0b10100101])
def test_centroid_leds_follow_the_bits_with_bit0_leftmost(bits):
    img = centroid_image(bits)
    assert img.shape == (CELL + 2 * GAP, 8 * (CELL + GAP) + GAP, 3)
    expected = [(bits >> i) & 1 == 1 for i in range(8)]
    assert lit(img, 8) == expected
    # Every pixel of a cell has the cell's colour; the gaps between cells are background.
    for i in range(8):
        r, c = cell_centre(i)
        cell = img[GAP : GAP + CELL, c - CELL // 2 : c - CELL // 2 + CELL]
        assert (cell == img[r, c]).all()
        assert (img[:, c + CELL - CELL // 2] == img[0, 0]).all()


def test_images_are_shared_read_only():
    assert proximity_image(3) is proximity_image(3)
    with pytest.raises(ValueError):
        proximity_image(3)[0, 0, 0] = 1


@pytest.mark.parametrize(
    "fn, bad",
    [(proximity_image, 8), (proximity_image, -1), (centroid_image, 256), (centroid_image, -1)],
)
def test_out_of_range_values_are_rejected(fn, bad):
    with pytest.raises(ValueError):
        fn(bad)
