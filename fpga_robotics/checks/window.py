"""What the design's tracking window lets it see of the target: its tracker counts only the
pixels inside the window's columns, ``margin_x <= x < width - margin_x`` (docs/contract.md),
so with part of the target's silhouette beyond them its centroid and pixel count are those of
the part inside. The checks that compare the design's centroid or count with the target's
place in the image ask here whether a sighting is whole, and where the part inside lies."""

import numpy as np

__all__ = ["visible_middle", "whole_in_window", "window_columns"]


def window_columns(width, margin_x=None):
    """``(lo, hi)``: the tracking window's columns as continuous pixels, ``margin_x`` from each
    side of an image ``width`` wide (default ``width // 10``, the design's default)."""
    margin = width // 10 if margin_x is None else margin_x
    return margin, width - margin


def whole_in_window(left, right, width, margin_x=None):
    """Whether a silhouette from column ``left`` to ``right`` (continuous pixels) lies wholly
    inside the tracking window's columns. Numbers or numpy arrays (a NaN edge: False)."""
    lo, hi = window_columns(width, margin_x)
    return (left >= lo) & (right <= hi)


def visible_middle(left, right, width, margin_x=None):
    """The middle column of the part of a silhouette from ``left`` to ``right`` inside the
    tracking window's columns: where the design's centroid of an upright cylinder cut by the
    window's edge lies (every column of it covers about the same rows). NaN where no part is
    inside. Numpy arrays."""
    lo, hi = window_columns(width, margin_x)
    a = np.maximum(np.asarray(left, dtype=float), lo)
    b = np.minimum(np.asarray(right, dtype=float), hi)
    return np.where(b > a, (a + b) / 2, np.nan)
