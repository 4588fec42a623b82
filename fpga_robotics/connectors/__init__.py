"""Connectors between the design and the simulated world: what the design's ports see of the
world (``CameraConnector``: rendered frames in) and what they do to it (``MotorConnector``:
wheel commands out, after the actuation delay)."""

from .camera import CameraConnector, camera_pose, in_view
from .motors import MotorConnector

__all__ = ["CameraConnector", "MotorConnector", "camera_pose", "in_view"]
