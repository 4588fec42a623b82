"""A LIDAR's revolutions as ``sensor_msgs/LaserScan`` messages (CDR), one per revolution, on
``/<sensor name>/scan``.

ROS angles turn counter-clockwise (REP 103) while the RPLIDAR's turn clockwise, so the
message's ``angle_min`` is minus the first sample's angle and ``angle_increment`` negative
(the samples in the order taken). ``frame_id`` is ``base_link``: the scan is drawn from the
robot's centre (a LIDAR mounted off the centre would need its own frame on ``/tf``). A sample
without a return is ``+inf`` (REP 117: no return within range); ``intensities`` carry the
samples' quality. The header's stamp is the revolution's first sample's instant.
"""

import math

import numpy as np

from .messages import TYPESTORE

__all__ = ["SCAN_TYPE", "LaserScans"]

SCAN_TYPE = "sensor_msgs/msg/LaserScan"
_T = TYPESTORE.types


def _stamp(ns):
    return _T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


class LaserScans:
    """Encodes each LIDAR revolution of the ``FrameRecord`` s once (a revolution lasts
    several frames)."""

    def __init__(self):
        self._last = {}  # sensor name -> start time of the last revolution encoded

    def encode(self, record):
        """``[(topic, stamp_ns, cdr_bytes), ...]``: the revolutions new in ``record``."""
        out = []
        for name, reading in (getattr(record, "sensors", None) or {}).items():
            scan = getattr(reading, "scan", None)
            if scan is None or self._last.get(name) == scan.start_time:
                continue
            self._last[name] = scan.start_time
            out.append((f"/{name}/scan", round(record.sim_time * 1e9), self.message(scan)))
        return out

    @staticmethod
    def message(scan):
        """The CDR bytes of one ``sim.world.lidar.Revolution``."""
        ranges = np.array(scan.ranges, dtype=np.float32)
        ranges[ranges <= 0] = np.inf
        n = len(ranges)
        first = -math.radians(scan.first_deg)
        step = -math.radians(scan.step_deg)
        msg = _T[SCAN_TYPE](
            header=_T["std_msgs/msg/Header"](
                stamp=_stamp(round(scan.start_time * 1e9)), frame_id="base_link"
            ),
            angle_min=first,
            angle_max=first + step * (n - 1),
            angle_increment=step,
            time_increment=scan.time_increment,
            scan_time=scan.scan_time,
            range_min=scan.range_min,
            range_max=scan.range_max,
            ranges=ranges,
            intensities=np.array(scan.qualities, dtype=np.float32),
        )
        return TYPESTORE.serialize_cdr(msg, SCAN_TYPE)
