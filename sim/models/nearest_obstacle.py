"""Python model of ``NearestObstacle`` (numpy, no Amaranth), from its docstring: each
revolution's nearest counted sample, published when the next revolution starts."""

import itertools

import numpy as np

from fpga_robotics.hw.lidar_params import NearestParams

__all__ = ["nearest_per_revolution"]


def nearest_per_revolution(samples, params=None):
    """``samples``: an (N, 4) array-like of ``(angle_q6, distance_q2, quality, start)`` in
    the order they arrive. Returns one ``(found, nearest_mm, bearing_q6)`` per sample with
    ``start`` set: the revolution that sample ends (``found`` 0: none counted; then the
    other two repeat the last found ones, 0 before any)."""
    p = NearestParams() if params is None else params
    a = np.asarray(samples, dtype=np.int64).reshape(-1, 4)
    counts = (a[:, 1] > 0) & (a[:, 2] >= p.min_quality) & (a[:, 1] >= 4 * p.min_mm)
    starts = np.flatnonzero(a[:, 3] != 0)
    out, mm, q6 = [], 0, 0
    bounds = [0, *starts.tolist()]
    for lo, hi in itertools.pairwise(bounds):
        rev = np.arange(lo, hi)
        rev = rev[counts[rev]]
        if len(rev):
            k = rev[np.argmin(a[rev, 1])]  # argmin takes the first of equal ones
            mm, q6 = int(a[k, 1]) >> 2, int(a[k, 0])
        out.append((int(len(rev) > 0), mm, q6))
    return out
