"""Connectors between the design and the simulated world (the API: ``base.py``,
docs/connectors.md): what the design's pins see of the world and what they do to it.
Importing this package registers every shipped kind: ``camera`` (rendered frames in),
``wheels`` (wheel commands out, after the actuation delay), ``bumper`` (a contact switch),
``ultrasound`` (an HC-SR04: TRIG out, ECHO in), ``line_sensors`` (KY-033s under the
robot), ``lidar``/``lidar_uart`` (an RPLIDAR A1 class scanner) and ``servo`` (a pan servo
turning what is mounted on it)."""

from fpga_robotics.loop.connectors.base import (
    CONNECTORS,
    Connector,
    ConnectorError,
    Mount,
    Pin,
    PinIO,
    register,
)
from fpga_robotics.loop.connectors.bumper import BumperConnector
from fpga_robotics.loop.connectors.camera import CameraConnector, camera_pose, in_view
from fpga_robotics.loop.connectors.lidar import LidarConnector, LidarUartConnector
from fpga_robotics.loop.connectors.line_sensors import LineSensorsConnector
from fpga_robotics.loop.connectors.motors import MotorConnector
from fpga_robotics.loop.connectors.servo import ServoConnector
from fpga_robotics.loop.connectors.ultrasound import UltrasoundConnector

__all__ = [
    "CONNECTORS",
    "BumperConnector",
    "CameraConnector",
    "Connector",
    "ConnectorError",
    "LidarConnector",
    "LidarUartConnector",
    "LineSensorsConnector",
    "MotorConnector",
    "Mount",
    "Pin",
    "PinIO",
    "ServoConnector",
    "UltrasoundConnector",
    "camera_pose",
    "in_view",
    "register",
]
