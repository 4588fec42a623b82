"""The robot's camera: the raster renderer (``raster.py``, its compiled stages ``kernel.py``),
the 3D renderer (``render3d/``), the OV7670 sensor model (``sensor/``), the scene it draws
(``scene.py``), conversions to the design's pixels (``frames.py``) and seeded synthetic frames
(``synthetic.py``)."""

from .raster import CameraRenderer, focal_length, render

__all__ = ["CameraRenderer", "focal_length", "render"]
