"""Pin-level simulation: every port of a design by name, clock by clock (base.py)."""

from .base import PinBackend, PinError, PixelTiming, Port, Stop

__all__ = ["PinBackend", "PinError", "PixelTiming", "Port", "Stop"]
