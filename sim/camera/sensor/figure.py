"""The same frame through each stage of the sensor model, as 8-bit images to look at.

``stage_images`` returns ``[(title, (H, W, 3) uint8), ...]``: the rendered frame, the light with
the motion blur, the raw mosaic (each pixel shown in its filter's colour), the mosaic after
exposure, noise and gains (ADC codes / 4), the demosaiced frame (still linear), after gamma, and
the RGB444 frame the design gets. docs/camera.md shows them (``python -m
fpga-robotics bench camera --stage-images docs/images``).
"""

import numpy as np

from .blur import motion_blur
from .pipeline import OV7670Sensor

__all__ = ["stage_images"]


def _as_mosaic_image(plane, channels, scale):
    img = np.zeros(plane.shape + (3,), dtype=np.float32)
    np.put_along_axis(img, channels[..., None].astype(np.intp), plane[..., None], axis=2)
    return np.clip(img * scale + 0.5, 0, 255).astype(np.uint8)


def stage_images(rgb, params, *, rng, turn_rate, frame_period=1 / 30, focal_px=None):
    """The stages of the frame ``rgb`` after the sensor settled on it (``params.settle_frames``
    frames); needs a Bayer mosaic (``params.bayer`` not ``"off"``)."""
    h, w = rgb.shape[:2]
    cam = OV7670Sensor(w, h, params, rng=rng, frame_period=frame_period, focal_px=focal_px)
    cam.process(rgb, turn_rate)  # settle (AEC, AWB) on this view
    raw = cam.light(rgb, turn_rate)
    blurred = cam._radiance.take(rgb)
    if cam.last_blur_px:
        blurred = motion_blur(blurred, cam.last_blur_px)
    mosaic_light = _as_mosaic_image(raw, cam._channels, 255.0)
    q = cam.expose(raw)
    cam.noise.add(q)
    codes, _ = cam.amplify(q)
    mosaic_codes = _as_mosaic_image(codes.astype(np.float32), cam._channels, 0.25)
    codes3 = cam.demosaic(codes)
    linear = np.clip(codes3 / 4.0 + 0.5, 0, 255).astype(np.uint8)
    gamma = np.clip(cam._luma_lut.take(codes3) + 0.5, 0, 255).astype(np.uint8)
    out = cam.tone(codes3)
    s = cam.state()
    return [
        ("rendered", rgb),
        (
            f"motion blur {s['blur_px']:.1f} px",
            np.clip(blurred * 255 + 0.5, 0, 255).astype(np.uint8),
        ),
        ("Bayer mosaic (BGGR)", mosaic_light),
        (f"exposure {s['exposure_s'] * 1e3:.1f} ms, gain {s['gain']:.2f}, noise, WB", mosaic_codes),
        ("demosaic (linear)", linear),
        ("gamma", gamma),
        ("RGB444", out),
    ]
