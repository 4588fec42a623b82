"""Fractions as percentages in what a run prints: never rounded onto 0%, 100% or a
check's limit when they are not exactly that."""

__all__ = ["limit_percent", "percent"]


def percent(v, limit=None, least_digits=0):
    """A fraction as a whole percentage, but never 0% or 100% for what is not exactly that
    (0.9967 is 99.7%, not 100%), and with a ``limit`` never shown equal to it, or on its
    other side, when it is not (0.4004 against 40% is 40.04%); ``least_digits`` decimals
    at least."""
    if limit is not None and v == limit:
        return limit_percent(limit)  # as the limit reads: 40.67% against 40.67%, not 41%
    for digits in range(least_digits, 7):
        text = f"{v:.{digits}%}"
        shown = float(text[:-1])
        if (shown == 100 and v < 1) or (shown == 0 and v > 0):
            continue
        if limit is not None and v != limit:
            bound = float(limit_percent(limit)[:-1])
            if (shown > bound) != (v > limit) or shown == bound:
                continue
        return text
    return text


def limit_percent(limit):
    """A check's fraction limit as a percentage, as set (0.1595 is 15.95%, 0.02 is 2%)."""
    return f"{round(limit * 100, 6):g}%"
