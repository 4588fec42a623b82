"""The OV7670 sensor model: a rendered frame in, the frame the camera would deliver out.

Stages, in the order light meets them (each a small module of this package, docs/camera.md):

1. **Linear light**: the renderer's 8-bit values are scene radiance ``(v / 255) ** input_gamma``
   (``input_gamma`` 1: the shipped renderer shades linearly in light).
2. **Motion blur** (``blur``): the image smeared sideways by ``|turn rate| * exposure time * f``.
3. **Bayer mosaic** (``bayer``): each pixel keeps its colour filter's channel.
4. **Exposure** (``exposure``): the well fills to ``radiance * sensitivity * exposure`` (a fraction
   of full well, saturating at 1).
5. **Shot and read noise** (``noise``).
6. **Analogue gains**: AGC gain times the white-balance gain of the pixel's colour; the 10-bit ADC
   saturates at full scale and rounds to a code.
7. **Demosaic** (``bayer``, bilinear), on the codes.
8. **Gamma** (``gamma``) and **RGB444** (``rgb444``): one table from code to output byte.

After each frame the AEC/AGC (``exposure``) and AWB (``white_balance``) update from that frame's
statistics, so the next frame shows the change, as on the robot. The tables (radiance, gamma
and RGB444) and the larger buffers are built once per sensor; a frame costs a few dozen
whole-array numpy and OpenCV calls.
"""

import cv2
import numpy as np

from .bayer import BAYER_ORDERS, bayer_channels, demosaic
from .blur import MIN_BLUR_PIXELS, blur_length, motion_blur
from .exposure import AutoExposure
from .gamma import gamma_lut
from .noise import PixelNoise
from .params import OV7670Params
from .rgb444 import rgb444_levels
from .white_balance import AutoWhiteBalance

__all__ = ["ADC_BITS", "LUMA", "OV7670Sensor"]

#: The ADC's resolution.
ADC_BITS = 10
_FULL = 2**ADC_BITS - 1
#: Luminance weights (ITU-R BT.601, the chip's YUV) for the AEC's frame average.
LUMA = (0.299, 0.587, 0.114)


class OV7670Sensor:
    """Turns rendered RGB888 frames into OV7670 frames, carrying AEC/AWB state between frames.

    Parameters
    ----------
    width, height : int
        Frame size (any size; the Bayer tile is cut at odd edges).
    params : OV7670Params
    rng : numpy.random.Generator
        The noise's stream (one per run).
    frame_period : float
        Seconds per frame: the longest exposure, and the unit of ``exposure``.
    focal_px : float
        Focal length in pixels (the motion blur's scale).
    """

    def __init__(self, width, height, params=None, *, rng=None, frame_period=1 / 30, focal_px=None):
        p = params if params is not None else OV7670Params()
        self.params = p
        self.width, self.height = width, height
        self.frame_period = frame_period
        self.focal_px = focal_px if focal_px is not None else width / 2
        self.aec = AutoExposure(
            window=tuple(p.aec_window),
            fast_zone=tuple(p.aec_fast_zone),
            max_gain=p.max_gain,
            enabled=p.aec,
        )
        self.aec.set_total(p.exposure * p.gain)
        self.awb = AutoWhiteBalance(speed=p.awb_speed, enabled=p.awb)
        plane = (height, width) if p.bayer != "off" else (height, width, 3)
        self.noise = PixelNoise(plane, p.snr_db, p.dynamic_range_db, rng) if p.noise else None
        self.frames = 0
        self.last_blur_px = 0.0
        # Tables: radiance of an 8-bit input; output byte (gamma, then RGB444) and luminance
        # (gamma only) of a 10-bit code.
        self._radiance = ((np.arange(256) / 255.0) ** p.input_gamma).astype(np.float32)
        curve = gamma_lut(ADC_BITS, p.gamma)
        self._out_lut = rgb444_levels(curve)
        self._luma_lut = curve
        if p.bayer == "off":
            self._channels = None
        else:
            self._channels = bayer_channels(height, width, p.bayer)
            # Flat index of each pixel's filter channel in an (H, W, 3) image.
            self._mosaic_index = (np.arange(height * width) * 3 + self._channels.ravel()).reshape(
                height, width
            )
            tile = BAYER_ORDERS[p.bayer]
            self._tile = [(i, j, tile[2 * i + j]) for i in (0, 1) for j in (0, 1)]
            self._codes = np.empty((height, width), dtype=np.uint16)
        self._lin3 = np.empty((height, width, 3), dtype=np.float32)
        self._codes3 = np.empty((height, width, 3), dtype=np.uint16)

    # State -------------------------------------------------------------------------------

    def state(self):
        """The sensor's state after the last frame: exposure (s and fraction of a frame),
        gain, white-balance gains, frames taken, the last frame's smear."""
        return {
            "exposure_s": self.aec.exposure * self.frame_period,
            "exposure": self.aec.exposure,
            "gain": self.aec.gain,
            "wb_gains": tuple(float(g) for g in self.awb.gains),
            "frames": self.frames,
            "blur_px": self.last_blur_px,
        }

    # Frames ------------------------------------------------------------------------------

    def process(self, rgb, turn_rate=0.0):
        """The camera's frame (H, W, 3) uint8, low nibbles zero, of the rendered ``rgb``;
        ``turn_rate`` (rad/s) is the robot's during this frame's exposure."""
        if rgb.shape != (self.height, self.width, 3) or rgb.dtype != np.uint8:
            raise ValueError(
                f"the sensor takes ({self.height}, {self.width}, 3) uint8 frames, "
                f"got {rgb.shape} {rgb.dtype}"
            )
        if self.frames == 0:
            for _ in range(self.params.settle_frames):
                self._frame(rgb, turn_rate)
        return self._frame(rgb, turn_rate)

    def _frame(self, rgb, turn_rate):
        raw = self.light(rgb, turn_rate)
        q = self.expose(raw)
        if self.noise is not None:
            self.noise.add(q)
        codes, means = self.amplify(q)
        codes3 = self.demosaic(codes)
        out = self.tone(codes3)
        self.adapt(codes3, means)
        self.frames += 1
        return out

    # The stages (each times on its own in the benchmark) ----------------------------------

    def light(self, rgb, turn_rate=0.0):
        """Radiance (float32) at each pixel's filter colour ((H, W, 3) without a mosaic),
        smeared by the turn during the exposure."""
        p = self.params
        blur = 0.0
        if p.motion_blur and turn_rate:
            blur = blur_length(turn_rate, self.aec.exposure * self.frame_period, self.focal_px)
            blur = blur if blur >= MIN_BLUR_PIXELS else 0.0
        self.last_blur_px = blur
        if blur:
            lin = motion_blur(self._radiance.take(rgb, out=self._lin3), blur)
            return lin.take(self._mosaic_index) if self._channels is not None else lin
        if self._channels is not None:
            return self._radiance.take(rgb.take(self._mosaic_index))
        return self._radiance.take(rgb)

    def expose(self, raw):
        """The fraction of a full well each pixel collects (in place), saturating at 1."""
        raw *= np.float32(self.params.sensitivity * self.aec.exposure)
        return np.minimum(raw, np.float32(1.0), out=raw)

    def amplify(self, q):
        """AGC and white-balance gains, then the ADC: integer codes (uint16), and the mean
        signal of each colour for the AWB."""
        gains = self.aec.gain * self.awb.gains
        if self._channels is None:
            q *= gains.astype(np.float32)
            np.clip(q, np.float32(0.0), np.float32(1.0), out=q)  # the ADC's range
            means = q.reshape(-1, 3).mean(axis=0)
        else:
            sums, counts = np.zeros(3), np.zeros(3)
            for i, j, c in self._tile:
                site = q[i::2, j::2]
                site *= np.float32(gains[c])
                np.clip(site, np.float32(0.0), np.float32(1.0), out=site)  # the ADC's range
                sums[c] += site.sum(dtype=np.float64)
                counts[c] += site.size
            means = sums / np.maximum(counts, 1)
        q *= np.float32(_FULL)
        np.rint(q, out=q)
        codes = self._codes if self._channels is not None else self._codes3
        np.copyto(codes, q, casting="unsafe")
        return codes, means

    def demosaic(self, codes):
        """(H, W, 3) uint16 codes: the mosaic interpolated, or ``codes`` without a mosaic."""
        if self._channels is None:
            return codes
        return demosaic(codes, self.params.bayer, out=self._codes3)

    def tone(self, codes3):
        """Gamma and RGB444: the output bytes (one table lookup per value)."""
        return self._out_lut.take(codes3)

    def adapt(self, codes3, awb_means):
        """AEC/AGC from the frame's mean luminance (after gamma; every other row and column),
        AWB from its colour means."""
        r, g, b, _ = cv2.mean(self._luma_lut.take(codes3[::2, ::2]))
        self.aec.update(LUMA[0] * r + LUMA[1] * g + LUMA[2] * b)
        self.awb.update(awb_means)
