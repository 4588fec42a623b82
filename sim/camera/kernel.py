"""Two stages of the camera renderer compiled (camera_kernel.cpp), when a C++ compiler is
present: the column rays against the walls and cylinders (depth and shade of every hit), and
the per-pixel stage, which paints the columns' runs of rows into the RGB888 image and adds the
sensor noise in one pass where the numpy path takes a cumulative sum, two lookups and a
colour conversion. Both give the numpy path's values to the bit (tests/test_camera_kernel.py). Built once into the
build cache like the simulation models; without a compiler ``camera_kernel()`` is None and the
renderer keeps its numpy path.
"""

import ctypes
import functools
import hashlib
from pathlib import Path

import numpy as np

from ..backends import build_cache
from ..backends.base import BackendError
from ..backends.toolchain import find_compiler, run_tool

__all__ = ["camera_kernel"]

_SOURCE = Path(__file__).resolve().parent / "kernel.cpp"
_LIBRARY = "libcamera_kernel.so"
#: No fused multiply-adds and no fast-math: the hits must be numpy's to the last bit.
_FLAGS = (
    "-std=c++17",
    "-O2",
    "-ffp-contract=off",
    "-fno-fast-math",
    "-fPIC",
    "-fvisibility=hidden",
    "-shared",
)
_VP = ctypes.c_void_p
_I64 = ctypes.c_int64


class CameraKernel:
    """The loaded library: ``paint(starts, runs, palette, width, height, rgb, noise,
    *NoiseTable.arguments, draw, state)`` (addresses; noise None and the rest None or 0 for no
    noise; ``draw, state``: a PCG64's ``next_uint64`` and state to draw the indices with
    instead of ``noise``, else None), ``hits(...)`` and ``layers(...)``
    (camera.py's ``_hits_compiled`` and ``_layers_compiled`` give their arguments)."""

    def __init__(self, path):
        lib = ctypes.CDLL(str(path))
        if lib.fr_camera_kernel_version() != 9:
            raise OSError("unexpected camera_kernel library version")
        paint = lib.fr_camera_paint
        paint.restype = None
        paint.argtypes = [_VP, _I64, _VP, _I64, _I64, _VP, _VP, _VP, _VP, _I64, _VP, _I64, _VP, _VP]
        self.paint = paint
        hits = lib.fr_camera_hits
        hits.restype = None
        _D = ctypes.c_double
        hits.argtypes = [
            _I64,
            _VP,
            _VP,
            _D,
            _D,
            _D,
            _D,
            _I64,
            _VP,
            _I64,
            _VP,
            _I64,
            _VP,
            _D,
            _D,
            _D,
            _D,
            _D,
            _VP,
            _VP,
            _VP,
        ]
        self.hits = hits
        layers = lib.fr_camera_layers
        layers.restype = _I64
        layers.argtypes = [
            _I64,
            _I64,
            _I64,
            _VP,
            _VP,
            _VP,
            _VP,
            _VP,
            _D,
            _D,
            _D,
            _I64,
            _I64,
            _D,
            _D,
            _D,
            _D,
            _D,
            _D,
            _VP,
            _VP,
        ]
        self.layers = layers
        self.path = path


#: Most steps of the noise table the compiled stage counts (beyond, it looks indices up;
#: MAX_STEPS in camera_kernel.cpp).
MAX_STEPS = 64


class NoiseTable:
    """The 65536-entry int8 noise table in the compiled stage's two forms.

    ``block, sub``: ``table[i] == sub[block[i >> 8] + (i & 255)]``, equal 256-entry blocks
    stored once so that lookups stay in the L1 cache. ``at, base``: the steps of a monotone
    table, ``table[i] == base + count(at[j] <= i)``, a step of two levels listed twice
    (``steps`` 0 when the table is not monotone or has more than ``MAX_STEPS`` steps)."""

    def __init__(self, table):
        blocks, inverse = np.unique(table.reshape(256, 256), axis=0, return_inverse=True)
        self.block = (inverse.reshape(256) * 256).astype(np.int32)
        self.sub = np.ascontiguousarray(blocks.ravel())
        diff = np.diff(table.astype(np.int16))
        monotone = bool(np.all(diff >= 0))
        self.at = np.repeat(np.arange(1, 65536), np.maximum(diff, 0)).astype(np.uint16)
        self.base = int(table[0])
        self.steps = len(self.at) if monotone and len(self.at) <= MAX_STEPS else 0
        #: The paint call's last five arguments, after the noise indices.
        self.arguments = (
            self.block.ctypes.data,
            self.sub.ctypes.data,
            self.steps,
            self.at.ctypes.data if len(self.at) else None,
            self.base,
        )


@functools.cache
def camera_kernel():
    """The compiled per-pixel stage, or None where it cannot be built or loaded (no
    compiler, an unwritable cache): the renderer then uses numpy, with the same result."""
    try:
        compiler = find_compiler()
        source = _SOURCE.read_text()
        key = build_cache.build_key(
            {
                "flow": "camera-kernel",
                "source": hashlib.sha256(source.encode()).hexdigest(),
                "flags": list(_FLAGS),
                "compiler": compiler.version,
            }
        )

        def build(directory):
            (directory / _SOURCE.name).write_text(source)
            run_tool(
                [compiler.path, *_FLAGS, directory / _SOURCE.name, "-o", directory / _LIBRARY],
                cwd=directory,
                what=f"compiling the camera's pixel stage ({compiler.path})",
            )

        entry = build_cache.get_or_build("camera-kernel", key, [_LIBRARY], build)
        return CameraKernel(entry.file(_LIBRARY))
    except (BackendError, OSError):
        return None
