"""The robot's camera: the raster renderer (``raster.py``, its compiled stages ``kernel.py``),
the 3D renderer (``render3d/``), the OV7670 sensor model (``sensor/``), the scene it draws
(``scene.py``), conversions to the design's pixels (``frames.py``) and seeded synthetic frames
(``synthetic.py``)."""

__all__ = ["CameraRenderer", "focal_length", "render"]

#: The renderer's names are handed out on first use (PEP 562): a module of this package
#: (``frames.py``, which the backends import) comes without the renderer, whose compiled
#: stage is built with the backends' toolchain.


def __getattr__(name):
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from . import raster  # lazy: a name of the package, on use

    return getattr(raster, name)
