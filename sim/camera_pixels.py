"""The camera renderer's per-pixel stage compiled (camera_pixels.cpp), when a C++ compiler is
present: it paints the columns' runs of rows into the RGB888 image and adds the sensor noise
in one pass, where the numpy path takes a cumulative sum, two lookups and a colour
conversion. Both give the same bytes (tests/test_camera_pixels.py). Built once into the
build cache like the simulation models; without a compiler ``pixel_kernel()`` is None and the
renderer keeps its numpy path.
"""

import ctypes
import functools
import hashlib
from pathlib import Path

__all__ = ["pixel_kernel"]

_SOURCE = Path(__file__).resolve().parent / "camera_pixels.cpp"
_LIBRARY = "libcamera_pixels.so"
_FLAGS = ("-std=c++17", "-O2", "-fPIC", "-fvisibility=hidden", "-shared")
_VP = ctypes.c_void_p
_I64 = ctypes.c_int64


class PixelKernel:
    """The loaded library: ``paint(starts, runs, palette, width, height, rgb, noise, table)``
    with addresses (``noise`` and ``table`` 0 for no noise)."""

    def __init__(self, path):
        lib = ctypes.CDLL(str(path))
        if lib.fr_camera_pixels_version() != 1:
            raise OSError("unexpected camera_pixels library version")
        paint = lib.fr_camera_paint
        paint.restype = None
        paint.argtypes = [_VP, _I64, _VP, _I64, _I64, _VP, _VP, _VP]
        self.paint = paint
        self.path = path


@functools.cache
def pixel_kernel():
    """The compiled per-pixel stage, or None where it cannot be built or loaded (no
    compiler, an unwritable cache): the renderer then uses numpy, with the same result."""
    from .backends import build_cache
    from .backends.base import BackendError
    from .backends.toolchain import find_compiler, run_tool

    try:
        compiler = find_compiler()
        source = _SOURCE.read_text()
        key = build_cache.build_key({
            "flow": "camera-pixels",
            "source": hashlib.sha256(source.encode()).hexdigest(),
            "flags": list(_FLAGS),
            "compiler": compiler.version,
        })

        def build(directory):
            (directory / _SOURCE.name).write_text(source)
            run_tool([compiler.path, *_FLAGS, directory / _SOURCE.name, "-o",
                      directory / _LIBRARY], cwd=directory,
                     what=f"compiling the camera's pixel stage ({compiler.path})")

        entry = build_cache.get_or_build("camera-pixels", key, [_LIBRARY], build)
        return PixelKernel(entry.file(_LIBRARY))
    except (BackendError, OSError):
        return None
