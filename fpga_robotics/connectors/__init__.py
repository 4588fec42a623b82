"""Connectors between the design and the simulated world (the API: ``base.py``,
docs/connectors.md): what the design's pins see of the world and what they do to it.
Importing this package registers every shipped kind: ``camera`` (rendered frames in),
``wheels`` (wheel commands out, after the actuation delay), ``bumper`` (a contact switch)."""

from .base import CONNECTORS, Connector, ConnectorError, Mount, Pin, PinIO, register
from .bumper import BumperConnector
from .camera import CameraConnector, camera_pose, in_view
from .motors import MotorConnector

__all__ = [
           "CONNECTORS",
           "BumperConnector",
           "CameraConnector",
           "Connector",
           "ConnectorError",
           "MotorConnector",
           "Mount",
           "Pin",
           "PinIO",
           "camera_pose",
           "in_view",
           "register",
]
