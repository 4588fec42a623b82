"""The robot's world: top-down pymunk physics in metres and seconds.

``World.from_config(cfg, seed)`` builds a room with walls and furniture, a TurtleBot2 or
GoPiGo3 driven by wheel DPS commands through a motor model, scripted people and time-varying
lighting; ``world.scene()`` describes it for the camera renderer. See docs/scenarios.md.
"""

from .config import WORLD_SECTIONS, WorldConfigError, parse_world_config
from .kinematics import dps_to_twist, twist_to_wheels, wheels_to_twist
from .markings import FloorLine
from .robots import GOPIGO3, ROBOT_MODELS, TURTLEBOT2, RobotSpec
from .world import World, is_removal_event, removal_event

__all__ = [
    "GOPIGO3",
    "ROBOT_MODELS",
    "TURTLEBOT2",
    "WORLD_SECTIONS",
    "FloorLine",
    "RobotSpec",
    "World",
    "WorldConfigError",
    "dps_to_twist",
    "is_removal_event",
    "parse_world_config",
    "removal_event",
    "twist_to_wheels",
    "wheels_to_twist",
]
