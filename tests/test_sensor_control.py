"""Auto-exposure (AEC/AGC) and auto white balance (AWB) of the OV7670 sensor model: their
convergence over frames, hand-computed from the chip's documented rules."""

import itertools
import math

import numpy as np
import pytest

from fpga_robotics.sim.camera.sensor import OV7670Params, OV7670Sensor
from fpga_robotics.sim.camera.sensor.exposure import AutoExposure
from fpga_robotics.sim.camera.sensor.white_balance import grey_world_gains

# A linear camera (no noise, mosaic or gamma) so that the frame's mean luminance is
# 255.75 * clip(radiance * sensitivity * exposure * gain, 0, 1), rounded to 10-bit codes.
LINEAR = {
    "noise": False,
    "bayer": "off",
    "gamma": "off",
    "awb": False,
    "settle_frames": 0,
    "sensitivity": 1.2,
}


def flat(value):
    return np.full((120, 160, 3), value, np.uint8)


def luma_of(exposure_total, value):
    """The frame's mean luminance (8-bit scale) the linear camera measures."""
    q = min(value / 255 * 1.2 * min(exposure_total, 1.0), 1.0) * max(exposure_total, 1.0)
    return round(min(q, 1.0) * 1023) / 4


def test_step_rules():
    aec = AutoExposure()  # power-on registers: window 99..117, control zone 64..208
    assert [aec.step_factor(m) for m in (63.9, 64, 98.9, 99, 117, 117.1, 208, 208.1)] == [
        2.0,
        17 / 16,
        17 / 16,
        1.0,
        1.0,
        15 / 16,
        15 / 16,
        0.5,
    ]
    aec.set_total(3.0)  # a whole frame of exposure first, then gain
    assert (aec.exposure, aec.gain) == (1.0, 3.0)
    aec.set_total(1e3)
    assert aec.gain == 32.0  # the gain ceiling
    aec.set_total(1e-6)
    assert aec.exposure == pytest.approx(1 / 510) and aec.gain == 1.0  # one row


def test_a_darker_scene_doubles_the_exposure_a_frame_then_gain_takes_over():
    # Converged on a bright grey (200), the scene drops 4x (50): mean 27 < 64 (fast zone),
    # so the exposure doubles (0.45 -> 0.9: mean 54, still < 64), doubles again (1.8: a
    # whole frame and gain 1.8, mean 108 in the stable region) and stays.
    cam = OV7670Sensor(160, 120, OV7670Params(**LINEAR, exposure=0.45))
    out = cam.process(flat(200))
    assert np.all(out == round(luma_of(0.45, 200)) & 0xF0)  # 108 in RGB444 levels: 96
    assert (cam.aec.exposure, cam.aec.gain) == (0.45, 1.0)  # 108.3: inside 99..117
    expected = [0.9, 1.8, 1.8, 1.8]
    for total in expected:
        cam.process(flat(50))
        assert cam.aec.total == pytest.approx(total)
    assert (cam.aec.exposure, cam.aec.gain) == (1.0, pytest.approx(1.8))
    assert luma_of(1.8, 50) == pytest.approx(108.25, abs=0.3)


def test_in_the_control_zone_the_exposure_moves_a_sixteenth_a_frame():
    # Mean 144 (above the window, inside the zone): the exposure shrinks by 15/16 a frame until
    # the mean is at most 117: ceil(ln(117/144.4) / ln(15/16)) = 4 frames.
    cam = OV7670Sensor(160, 120, OV7670Params(**LINEAR, exposure=0.6))
    means = []
    for _ in range(8):
        means.append(cam.process(flat(200)).mean())
    totals = 0.6 * (15 / 16) ** np.arange(5)
    lumas = [luma_of(t, 200) for t in totals]
    assert lumas[0] == pytest.approx(144.4, abs=0.3)
    assert all(117 < m for m in lumas[:4]) and 99 <= lumas[4] <= 117
    assert cam.aec.total == pytest.approx(totals[4])
    n = math.ceil(math.log(117 / lumas[0]) / math.log(15 / 16))
    assert n == 4
    # The output (RGB444 levels) follows the exposure: each frame darker until frame 4.
    assert all(a >= b for a, b in itertools.pairwise(means[:5]))
    assert means[4] == means[7]


def test_aec_off_keeps_the_exposure():
    cam = OV7670Sensor(160, 120, OV7670Params(**{**LINEAR, "aec": False}, exposure=0.2))
    for _ in range(5):
        cam.process(flat(20))
    assert (cam.aec.exposure, cam.aec.gain) == (0.2, 1.0)


def test_grey_world_gains():
    g = grey_world_gains((0.5, 0.4, 0.3))
    assert g == pytest.approx((1.0, 1.25, 5 / 3))
    # Means measured with those gains are equal: the gains stay.
    assert grey_world_gains((0.5, 0.5, 0.5), gains=(1.0, 1.25, 5 / 3)) == pytest.approx(
        (1.0, 1.25, 5 / 3)
    )
    assert max(grey_world_gains((1.0, 0.1, 0.01))) == pytest.approx(0xFF / 0x40)  # ceiling


def test_white_balance_turns_a_grey_card_under_a_coloured_light_grey():
    # A grey card under a warm light (1.0 : 0.8 : 0.6): the AWB gains move a quarter of the way
    # (in log) to (1, 1.25, 5/3) each frame, so the log-error shrinks by 0.75 a frame.
    params = OV7670Params(
        noise=False, settle_frames=0, aec=False, exposure=0.5, awb_speed=0.25, gamma="off"
    )
    cam = OV7670Sensor(160, 120, params)
    card = np.empty((120, 160, 3), np.uint8)
    card[...] = (200, 160, 120)
    target = np.log([1.0, 1.25, 5 / 3])
    first = cam.process(card)
    assert first[..., 0].mean() > first[..., 2].mean() + 40  # untouched: warm
    for n in range(1, 25):
        err = np.log(cam.awb.gains) - target
        assert np.abs(err).max() == pytest.approx(np.abs(target).max() * 0.75**n, abs=2e-5)
        out = cam.process(card)
    channel_means = out[2:-2, 2:-2].reshape(-1, 3).mean(axis=0)
    assert channel_means.max() - channel_means.min() <= 16  # within one RGB444 level: grey
