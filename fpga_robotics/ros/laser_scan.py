"""A LIDAR's revolutions as ``sensor_msgs/LaserScan`` messages (CDR), one per revolution, on
``/<sensor name>/scan``.

The scan's frame is ``<sensor name>_link``: ``base_link`` moved to where the sensor sits
(its mount's ``forward``, ``left`` and ``height``) but not turned, placed on ``/tf`` with
each revolution. So the angles are the robot's: 0 is the robot's forward whatever the
mount's yaw, which the angles include. ROS angles turn counter-clockwise (REP 103) while the
RPLIDAR's turn clockwise, so ``angle_min`` is the mount's yaw minus the first sample's angle
and ``angle_increment`` is negative (the samples in the order taken). A sample without a
return is ``+inf`` (REP 117: no return within range); ``intensities`` carry the samples'
quality. The header's stamp is the revolution's first sample's instant.
"""

import math

import numpy as np

from .messages import TYPESTORE

__all__ = ["SCAN_TYPE", "LaserScans"]

SCAN_TYPE = "sensor_msgs/msg/LaserScan"
_TF_TYPE = "tf2_msgs/msg/TFMessage"
_T = TYPESTORE.types


def _stamp(ns):
    return _T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _frame(name):
    """The frame of sensor ``name``'s scans."""
    return f"{name}_link"


class LaserScans:
    """Encodes each LIDAR revolution of the ``FrameRecord`` s once (a revolution lasts
    several frames)."""

    def __init__(self):
        self._last = {}  # sensor name -> start time of the last revolution encoded

    def encode(self, record):
        """``[(topic, stamp_ns, cdr_bytes), ...]``: for each revolution new in ``record``,
        its frame's place on ``/tf`` and the scan."""
        out = []
        for name, reading in (getattr(record, "sensors", None) or {}).items():
            scan = getattr(reading, "scan", None)
            if scan is None or self._last.get(name) == scan.start_time:
                continue
            self._last[name] = scan.start_time
            ns = round(record.sim_time * 1e9)
            out.append(("/tf", ns, self.place(name, scan)))
            out.append((f"/{name}/scan", ns, self.message(name, scan)))
        return out

    @staticmethod
    def place(name, scan):
        """The CDR bytes of the ``/tf`` message placing the scans' frame in ``base_link``."""
        transform = _T["geometry_msgs/msg/TransformStamped"](
            header=_T["std_msgs/msg/Header"](
                stamp=_stamp(round(scan.start_time * 1e9)), frame_id="base_link"
            ),
            child_frame_id=_frame(name),
            transform=_T["geometry_msgs/msg/Transform"](
                translation=_T["geometry_msgs/msg/Vector3"](
                    x=float(scan.mount_forward),
                    y=float(scan.mount_left),
                    z=float(scan.mount_height),
                ),
                rotation=_T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            ),
        )
        return TYPESTORE.serialize_cdr(_T[_TF_TYPE](transforms=[transform]), _TF_TYPE)

    @staticmethod
    def message(name, scan):
        """The CDR bytes of one ``sim.world.lidar.Revolution`` of sensor ``name``."""
        ranges = np.array(scan.ranges, dtype=np.float32)
        ranges[ranges <= 0] = np.inf
        n = len(ranges)
        # The first sample's direction from the robot's forward, counter-clockwise.
        first = math.radians(math.remainder(scan.mount_yaw_deg - scan.first_deg, 360.0))
        step = -math.radians(scan.step_deg)
        msg = _T[SCAN_TYPE](
            header=_T["std_msgs/msg/Header"](
                stamp=_stamp(round(scan.start_time * 1e9)), frame_id=_frame(name)
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
