"""What the frozen parameter dataclasses of the sensor, LIDAR and turret designs share.

Plain Python (no Amaranth import), like the parameter modules that use it.
"""

from dataclasses import fields, replace

from .validate import check_int

__all__ = ["ParamsBase"]


class ParamsBase:
    """Base of a frozen dataclass of elaboration parameters: ``replace`` and ``as_dict``,
    and ``_check`` for the integer fields its ``__post_init__`` validates."""

    def replace(self, **changes):
        """A copy with some parameters changed (validated again)."""
        return replace(self, **changes)

    def as_dict(self):
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def _check(self, name, lo=None, hi=None):
        object.__setattr__(self, name, check_int(name, getattr(self, name), lo, hi))
