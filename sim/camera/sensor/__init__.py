"""The OV7670 camera sensor model: what the robot's camera makes of the light that reaches it.

``OV7670Sensor(width, height, params, rng=..., frame_period=..., focal_px=...).process(rgb,
turn_rate)`` turns a rendered RGB888 frame (any renderer's) into the RGB888 frame the camera
delivers (RGB444 levels), carrying auto-exposure and white balance from frame to frame.
docs/camera.md, "Sensor model", describes each stage and its defaults.
"""

from .params import PARAMS, OV7670Params
from .pipeline import OV7670Sensor

__all__ = ["PARAMS", "OV7670Params", "OV7670Sensor"]
