"""The one integer check used by every constructor that takes counts, widths or limits.

Plain Python (no Amaranth), so that host code can use it too without importing gateware.
"""

import numbers

__all__ = ["check_int"]


def check_int(name, value, lo=None, hi=None):
    """Return ``value`` as an ``int`` if it is an integer in ``lo..hi`` (either bound may be
    ``None``); otherwise raise ``TypeError`` (not an integer: bool and float are refused) or
    ``ValueError`` (out of range), naming ``name`` and the allowed range."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, not {type(value).__name__} {value!r}")
    value = int(value)
    if lo is not None and value < lo:
        raise ValueError(f"{name} must be >= {lo}, got {value}")
    if hi is not None and value > hi:
        raise ValueError(f"{name} must be <= {hi}, got {value}")
    return value
