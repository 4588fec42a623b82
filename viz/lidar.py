"""A LIDAR's scan in the 3D view: the last revolution's returns as points where they hit, at
the scan plane's height (``world3d/sensors/<name>``). The 2D map draws the same points under
``map/sensors/<name>/points`` (``viz.sensors``)."""

import numpy as np
import rerun as rr

from .world3d import WORLD3D

__all__ = ["LIDAR_KINDS", "SCANS3D", "log_scans_3d"]

SCANS3D = f"{WORLD3D}/sensors"
#: The connector kinds whose points are a scan.
LIDAR_KINDS = ("lidar", "lidar_uart")
_POINT_COLOR = (255, 80, 60)


def log_scans_3d(stream, record, frame, t):
    """Log ``record``'s LIDAR scans at ``frame`` and sim time ``t`` (ns); nothing without."""
    scans = {
        name: reading
        for name, reading in (getattr(record, "sensors", None) or {}).items()
        if reading.kind in LIDAR_KINDS and reading.points
    }
    if not scans:
        return
    stream.set_time("frame", sequence=frame)
    stream.set_time("sim_time", duration=t)
    for name, reading in scans.items():
        xy = np.asarray(reading.points, dtype=np.float32).reshape(-1, 2)
        z = np.full((len(xy), 1), reading.height, dtype=np.float32)
        stream.log(
            f"{SCANS3D}/{name}",
            rr.Points3D(np.hstack([xy, z]), radii=0.015, colors=_POINT_COLOR),
        )
