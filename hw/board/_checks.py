"""Argument checks shared by the board components."""

__all__ = ["check_int"]


def check_int(owner, name, value, lo=None, hi=None):
    """Raise ``ValueError`` unless ``value`` is an int in ``lo..hi``.

    ``owner`` is the component being constructed: it is marked as used before raising, so that
    a rejected constructor call does not also warn that an elaboratable was never elaborated.
    """
    if (isinstance(value, bool) or not isinstance(value, int)
            or (lo is not None and value < lo) or (hi is not None and value > hi)):
        owner._MustUse__silence = True
        bounds = f"{'' if lo is None else lo}..{'' if hi is None else hi}"
        raise ValueError(f"{name} must be an int in {bounds}, got {value!r}")
