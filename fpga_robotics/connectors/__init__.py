"""Connectors between the design and the simulated world (the API: ``base.py``,
docs/connectors.md): what the design's pins see of the world and what they do to it.
Importing this package registers every shipped kind: ``camera`` (rendered frames in),
``wheels`` (wheel commands out, after the actuation delay), ``bumper`` (a contact switch),
``ultrasound`` (an HC-SR04: TRIG out, ECHO in) and ``line_sensors`` (KY-033s under the
robot)."""

from .base import CONNECTORS, Connector, ConnectorError, Mount, Pin, PinIO, register
from .bumper import BumperConnector
from .camera import CameraConnector, camera_pose, in_view
from .line_sensors import LineSensorsConnector
from .motors import MotorConnector
from .ultrasound import UltrasoundConnector

__all__ = [
           "CONNECTORS",
           "BumperConnector",
           "CameraConnector",
           "Connector",
           "ConnectorError",
           "LineSensorsConnector",
           "MotorConnector",
           "Mount",
           "Pin",
           "PinIO",
           "UltrasoundConnector",
           "camera_pose",
           "in_view",
           "register",
]
