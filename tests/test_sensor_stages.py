"""Each stage of the OV7670 sensor model (fpga_robotics.sim.camera.sensor) against its formula."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.camera.frames import rgb444_to_rgb888, to_rgb444
from fpga_robotics.sim.camera.sensor.bayer import bayer_channels, demosaic, mosaic
from fpga_robotics.sim.camera.sensor.blur import blur_length, box_kernel, motion_blur
from fpga_robotics.sim.camera.sensor.gamma import GAMMA_CURVES, GAMMA_X, gamma_curve, gamma_lut
from fpga_robotics.sim.camera.sensor.noise import PixelNoise, noise_sigma, well_and_read_noise
from fpga_robotics.sim.camera.sensor.rgb444 import rgb444_levels, truncate_rgb444

# Gamma -------------------------------------------------------------------------------------


@pytest.mark.parametrize("name,slop", [("default", 0x24), ("driver", 0x20)])
def test_gamma_last_segment_has_the_datasheet_slope(name, slop):
    # The datasheet's SLOP register is (256 - GAM15) * 40 / 30, in 1/64: the curve's slope
    # above 208 must be SLOP / 64 (the power-on and the driver's register sets).
    gam15 = GAMMA_CURVES[name][-1]
    assert (256 - gam15) * 40 // 30 == slop
    slope = (gamma_curve(250.0, name) - gamma_curve(210.0, name)) / 40
    assert slope == pytest.approx(slop / 64, abs=1e-9)


def test_gamma_passes_through_the_registers_and_interpolates_linearly():
    ys = GAMMA_CURVES["default"]
    assert np.array_equal(gamma_curve(np.array(GAMMA_X, float)), ys)
    assert gamma_curve(36.0) == pytest.approx((0x28 + 0x36) / 2)  # halfway from 32 to 40
    assert gamma_curve(2.0) == pytest.approx(0x04 / 2)  # the first segment starts at (0, 0)
    lut = gamma_lut(10)
    assert lut.shape == (1024,)
    assert lut[32 * 4] == pytest.approx(0x28) and lut[1] == pytest.approx(0x04 / 4 / 4)
    assert np.all(np.diff(lut) > 0)  # strictly increasing: no two codes swap
    assert np.allclose(gamma_lut(10, "off"), np.arange(1024) / 4)


# RGB444 ------------------------------------------------------------------------------------


def test_rgb444_keeps_the_top_nibble_of_the_rounded_value():
    assert list(rgb444_levels([0.0, 15.4, 15.6, 16.0, 127.9, 254.6, 300.0, -3.0])) == [
        0,
        0,
        16,
        16,
        128,
        240,
        240,
        0,
    ]
    img = np.arange(256, dtype=np.uint8).reshape(16, 16, 1).repeat(3, axis=2)
    out = truncate_rgb444(img)
    assert np.array_equal(out, img & 0xF0)
    # What the design sees (c >> 4) is unchanged, and RGB444 back to RGB888 (c << 4) is `out`.
    h, w = img.shape[:2]
    assert np.array_equal(to_rgb444(out, w, h), to_rgb444(img, w, h))
    assert np.array_equal(rgb444_to_rgb888(to_rgb444(img, w, h)), out)


# Bayer -------------------------------------------------------------------------------------


def test_bggr_pattern_and_mosaic():
    ch = bayer_channels(4, 6, "BGGR")
    assert ch[0, :4].tolist() == [2, 1, 2, 1]  # B G B G
    assert ch[1, :4].tolist() == [1, 0, 1, 0]  # G R G R
    assert np.array_equal(ch[2:], ch[:2])
    assert bayer_channels(3, 5, "BGGR").shape == (3, 5)  # odd sizes cut the tile
    rgb = np.arange(4 * 6 * 3).reshape(4, 6, 3)
    raw = mosaic(rgb, ch)
    assert raw[0, 0] == rgb[0, 0, 2] and raw[0, 1] == rgb[0, 1, 1] and raw[1, 1] == rgb[1, 1, 0]


@pytest.mark.parametrize("order", ["BGGR", "RGGB", "GBRG", "GRBG"])
def test_demosaic_of_a_flat_colour_is_that_colour_everywhere(order):
    ch = bayer_channels(9, 12, order)
    rgb = np.empty((9, 12, 3), np.uint16)
    rgb[...] = (100, 600, 1000)
    out = demosaic(mosaic(rgb, ch), order)
    assert np.all(out == (100, 600, 1000))


def test_demosaic_of_a_vertical_edge_leaves_the_hand_computed_fringes():
    # Columns 0..3 dark (0), 4.. bright (1000) in every channel; BGGR. Bilinear interpolation
    # takes each missing colour from the nearest pixels of that colour:
    rgb = np.zeros((8, 10, 3), np.uint16)
    rgb[:, 4:] = 1000
    out = demosaic(mosaic(rgb, bayer_channels(8, 10, "BGGR")), "BGGR").astype(int)
    # (2, 3): a G pixel of a B G row; B from its left (0) and right (1000) neighbours.
    assert out[2, 3].tolist() == [0, 0, 500]
    # (3, 3): an R pixel; G from 4 neighbours (one bright), B from 4 diagonals (two bright).
    assert out[3, 3].tolist() == [0, 250, 500]
    # (2, 4): a B pixel; G from 4 neighbours (three bright), R from 4 diagonals (two bright).
    assert out[2, 4].tolist() == [500, 750, 1000]
    # (3, 4): a G pixel of a G R row; R from left (0) and right (1000), B above and below.
    assert out[3, 4].tolist() == [500, 1000, 1000]
    # Away from the edge the grey is exact.
    assert np.all(out[1:-1, 1:2] == 0) and np.all(out[1:-1, 6:9] == 1000)


# Motion blur -------------------------------------------------------------------------------


def test_blur_length_is_turn_rate_times_exposure_times_focal_length():
    assert blur_length(-2.0, 1 / 60, 138.6) == pytest.approx(2.0 / 60 * 138.6)


@pytest.mark.parametrize("length", [0.6, 1.0, 2.5, 4.62, 7.0])
def test_motion_blur_is_the_time_average_of_the_sliding_image(length):
    # A row of random pixels, moving sideways at constant speed over the exposure: each output
    # pixel (sampled at its centre) averages the piecewise-constant row over offsets
    # s in [-L/2, L/2]; numerically, 40001 instants.
    rng = np.random.default_rng(3)
    row = rng.random(40).astype(np.float32)
    out = motion_blur(row[None, :].copy(), length)[0]
    s = np.linspace(-length / 2, length / 2, 40001)
    for x in range(8, 32):
        cells = np.floor(x + 0.5 - s).astype(int)  # the input pixel under the centre at s
        assert out[x] == pytest.approx(row[cells].mean(), abs=2e-4)
    k = box_kernel(length)
    assert k.sum() == pytest.approx(1.0) and np.allclose(k, k[::-1]) and len(k) % 2 == 1


# Noise -------------------------------------------------------------------------------------


def test_full_well_and_read_noise_from_the_datasheet_figures():
    full, read = well_and_read_noise(46.0, 52.0)
    assert full == pytest.approx(39810.7, rel=1e-5)  # SNR at full well = sqrt(N)
    assert 20 * math.log10(full / read) == pytest.approx(52.0)
    assert read == pytest.approx(100.0, rel=1e-2)


@pytest.mark.parametrize("q", [0.0, 0.02, 0.25, 0.8])
def test_noise_mean_and_variance_follow_shot_plus_read(q):
    noise = PixelNoise((120, 160), 46.0, 52.0, np.random.default_rng(7))
    samples = []
    for _ in range(20):
        frame = np.full((120, 160), q, np.float32)
        samples.append(noise.add(frame).astype(np.float64))
    x = np.concatenate([s.ravel() for s in samples])
    sigma = noise_sigma(q, noise.full_well, noise.read_noise)
    n = x.size
    assert abs(x.mean() - q) < 4 * sigma / math.sqrt(n)
    # The sample variance of n normal values has a relative spread of sqrt(2 / n) (0.2 % here).
    assert x.var() == pytest.approx(sigma**2, rel=6 * math.sqrt(2 / n))


def test_noise_is_a_function_of_the_generator_state():
    a = PixelNoise((12, 16), 46.0, 52.0, np.random.default_rng(1))
    b = PixelNoise((12, 16), 46.0, 52.0, np.random.default_rng(1))
    fa, fb = (n.add(np.full((12, 16), 0.5, np.float32)) for n in (a, b))
    assert np.array_equal(fa, fb) and fa.std() > 0
    with pytest.raises(TypeError, match="numpy.random.Generator"):
        PixelNoise((12, 16), 46.0, 52.0, 5)
