"""Host frame conversions: RGB888 <-> packed RGB444, and clear errors for bad frames."""

import numpy as np
import pytest

from fpga_robotics.sim.camera.frames import FrameError, rgb444_to_rgb888, to_rgb444, unpack_rgb444


def test_rgb888_keeps_the_top_four_bits_of_each_channel():
    img = np.zeros((2, 16, 3), np.uint8)
    img[0, 0] = (0xAB, 0xCD, 0xEF)
    img[1, 15] = (0x0F, 0x10, 0xFF)
    packed = to_rgb444(img, 16, 2)
    assert packed.dtype == np.uint16
    assert packed[0, 0] == 0xACE
    assert packed[1, 15] == 0x01F


def test_round_trip_is_c_shifted_left_by_four():
    rng = np.random.default_rng(1)
    packed = rng.integers(0, 4096, (3, 16), dtype=np.uint16)
    rgb = rgb444_to_rgb888(packed)
    assert rgb.shape == (3, 16, 3) and rgb.dtype == np.uint8
    r, g, b = unpack_rgb444(packed)
    assert np.array_equal(rgb[..., 0], r << 4) and np.array_equal(rgb[..., 1], g << 4)
    assert np.array_equal(rgb[..., 2], b << 4)
    assert np.array_equal(to_rgb444(rgb, 16, 3), packed)


@pytest.mark.parametrize(
    "frame,message",
    [
        (np.zeros((120, 160, 3), np.float32), "must be uint8"),
        (np.zeros((240, 320, 3), np.uint8), "shape (120, 160, 3)"),
        (np.zeros((120, 160), np.int16), "unsigned integer"),
        # A greyscale image: its 192 would be read as the green pixel 0x0C0.
        (np.full((120, 160), 192, np.uint8), "must be uint16 (12-bit pixels), got uint8"),
        (np.full((120, 160), 0x1000, np.uint16), "above 0xFFF"),
        (np.zeros((120, 160, 4), np.uint8), "shape (120, 160, 3)"),
        (np.zeros(5, np.uint8), "got shape (5,)"),
        ([[1, 2]], "numpy array"),
    ],
)
def test_bad_frames_say_what_is_wrong(frame, message):
    with pytest.raises(FrameError) as info:
        to_rgb444(frame, 160, 120)
    assert message in str(info.value)
