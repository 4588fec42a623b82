"""Scenes shared by the 3D renderer's tests: a person in red placed by distance and bearing
in front of the camera, in the default room."""

import dataclasses
import math

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.models.follow_target import color_match
from fpga_robotics.sim.world import World

mujoco_missing = pytest.mark.skipif(
    __import__("importlib").util.find_spec("mujoco") is None,
    reason='needs the optional install: pip install -e ".[realistic]"',
)

W, H, HFOV = 160, 120, 1.047
#: The camera: 1 m from the room's left wall, level, 0.3 m high, looking along +x.
POSE = CameraPose(1.0, 3.0, 0.0, 0.3)


def person_scene(distance, bearing_deg, **person):
    """The default room with one standing person (default look: red shirt) ``distance`` m
    from ``POSE`` at ``bearing_deg`` (left positive), facing the camera."""
    b = math.radians(bearing_deg)
    x, y = POSE.x + distance * math.cos(b), POSE.y + distance * math.sin(b)
    world = World.from_config({"people": [{"waypoints": [[x, y]], **person}]}, 0)
    scene = world.scene()
    cyl = dataclasses.replace(scene.cylinders[0], facing=b + math.pi)
    return dataclasses.replace(scene, cylinders=(cyl,))


def red_pixels(image):
    """The design's red match (default parameters) of an RGB888 frame: ``(count, mean
    column)``, the column NaN when nothing matches."""
    params = FollowTargetParams(width=image.shape[1], height=image.shape[0])
    match = color_match(to_rgb444(image, image.shape[1], image.shape[0]), "red", params)
    cols = np.nonzero(match)[1]
    return int(cols.size), (float(cols.mean() + 0.5) if cols.size else math.nan)
