"""What the camera renderer needs to know about the world at one instant.

The physics world (``fpga_robotics.sim.world``) builds a ``Scene`` each frame; the renderer
(``fpga_robotics.sim.camera``) turns it into an image. Keeping this description plain data
lets either side change without the other, and lets tests build scenes by hand.

Units: metres, radians; world frame x right, y up (top-down), z up from the floor.
Colours are albedos as (r, g, b) floats in 0..1; the lights decide the final brightness.
"""

from dataclasses import dataclass, field

__all__ = ["Band", "CameraPose", "Cylinder", "Lighting", "Scene", "Wall"]


@dataclass(frozen=True)
class Wall:
    """A vertical rectangle standing on the floor along a segment (walls, furniture sides)."""

    x0: float
    y0: float
    x1: float
    y1: float
    height: float
    color: tuple  # albedo (r, g, b) in 0..1
    #: What the face belongs to, for renderers that draw solids (sim.render3d): "room" (the
    #: room's walls), "box" or "divider" (a piece of furniture named ``part``), "" (a lone wall).
    kind: str = ""
    part: str = ""


@dataclass(frozen=True)
class Band:
    """A horizontal slice of a cylinder between heights z0 and z1, of one colour."""

    z0: float
    z1: float
    color: tuple


@dataclass(frozen=True)
class Cylinder:
    """An upright cylinder (a person: legs, shirt, head as bands)."""

    x: float
    y: float
    radius: float
    bands: tuple  # of Band, any order, may leave gaps
    #: How a person moves, for renderers that draw bodies (sim.render3d): the direction they
    #: face (rad, counter-clockwise from +x), their speed (m/s) and the distance they have
    #: walked since the start (m), which sets the phase of their gait.
    facing: float = 0.0
    speed: float = 0.0
    walked: float = 0.0


@dataclass(frozen=True)
class Lighting:
    """Ambient light plus one directional light (a window, a lamp far away).

    ``direction`` points from the light towards the scene, (dx, dy, dz), normalised by the
    renderer. The lit value of a surface is ``albedo * (ambient + intensity * max(0, -n.d))``.
    """

    ambient: float = 0.6
    intensity: float = 0.5
    direction: tuple = (1.0, 0.5, -1.0)


@dataclass(frozen=True)
class Scene:
    walls: tuple = ()
    cylinders: tuple = ()
    floor_color: tuple = (0.55, 0.55, 0.5)
    ceiling_color: tuple = (0.9, 0.9, 0.9)
    ceiling_height: float = 2.5
    lighting: Lighting = field(default_factory=Lighting)
    #: Coloured floor patches drawn on the floor: ``((polygon, albedo), ...)``, the last one
    #: drawn over the others (``[[room.terrain]]`` with a ``color``).
    floor_patches: tuple = ()


@dataclass(frozen=True)
class CameraPose:
    """The camera's position and heading in the world (from the robot's pose and mount)."""

    x: float
    y: float
    heading: float  # radians, counter-clockwise from +x
    height: float = 0.3  # mount height above the floor, m
    tilt: float = 0.0  # radians, positive looks up
