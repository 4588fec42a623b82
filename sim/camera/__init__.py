"""The robot's camera: the raster renderer (``raster.py``, its compiled stages ``kernel.py``),
the 3D renderer (``render3d/``), the OV7670 sensor model (``sensor/``), the scene it draws
(``scene.py``), conversions to the design's pixels (``frames.py``) and seeded synthetic frames
(``synthetic.py``)."""

#: The names the docs use (docs/camera.md, docs/scenarios.md), by the module that defines them.
_HOMES = {
    "CameraRenderer": "raster",
    "VERTICAL_MARGIN": "raster",
    "focal_length": "raster",
    "max_hfov": "raster",
    "max_tilt": "raster",
    "render": "raster",
    "vertical_fov": "raster",
    "CameraPose": "scene",
}

__all__ = [
    "VERTICAL_MARGIN",
    "CameraPose",
    "CameraRenderer",
    "focal_length",
    "max_hfov",
    "max_tilt",
    "render",
    "vertical_fov",
]

#: The names are handed out on first use (PEP 562): a module of this package (``frames.py``,
#: which the backends import) comes without the renderer, whose compiled stage is built with
#: the backends' toolchain.


def __getattr__(name):
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib  # lazy: a name of the package, on use

    return getattr(importlib.import_module(f".{home}", __name__), name)
