"""The one integer check used by every constructor that takes counts, widths or limits, and
the construction of elaboratables that check their arguments before they exist.

Plain Python (no Amaranth import), so that host code can use ``check_int`` too without
importing gateware.
"""

import numbers

from .errors import ParamError

__all__ = ["CheckedArguments", "check_int"]


def check_int(name, value, lo=None, hi=None):
    """Return ``value`` as an ``int`` if it is an integer in ``lo..hi`` (either bound may be
    ``None``); otherwise raise ``TypeError`` (not an integer: bool and float are refused) or
    ``ParamError`` (a ``ValueError``: out of range), naming ``name`` and the allowed range."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, not {type(value).__name__} {value!r}")
    value = int(value)
    if lo is not None and value < lo:
        raise ParamError(f"{name} must be >= {lo}, got {value}")
    if hi is not None and value > hi:
        raise ParamError(f"{name} must be <= {hi}, got {value}")
    return value


class CheckedArguments:
    """Base for an Amaranth elaboratable (put it before ``Elaboratable``/``Component``) whose
    constructor can reject its arguments.

    The class's ``check_arguments``, a static method with the constructor's signature, runs
    before the object is created. A rejected call then leaves no object behind that Amaranth
    would report as created but never elaborated (``UnusedElaboratable``), and a parent can
    check the arguments of the parts it builds before it builds any of them.
    """

    @staticmethod
    def check_arguments(*args, **kwargs):
        """Raise ``TypeError`` or ``ValueError`` unless the constructor accepts the arguments."""

    def __new__(cls, *args, **kwargs):
        cls.check_arguments(*args, **kwargs)
        # Elaboratable's own constructor records where the object was made (for the warning
        # about an unused one, and its linter pragma): one frame up, the caller's.
        return super().__new__(cls, src_loc_at=1)
