"""The room: walls around ``0..width x 0..depth`` and furniture, as physics shapes, as
renderer walls and as the viewer's map."""

import pymunk

from ..camera.scene import Wall

__all__ = [
    "WALL_THICKNESS",
    "add_static_shapes",
    "furniture_faces",
    "map_data",
    "room_segments",
    "scene_walls",
]

#: Collision thickness of the room walls, m (outside the room, so the inner faces are
#: exactly at 0 and width/depth).
WALL_THICKNESS = 0.1


def room_segments(room):
    """The four walls as ``((x0, y0), (x1, y1))``, counter-clockwise around the room."""
    w, d = room.width, room.depth
    corners = ((0.0, 0.0), (w, 0.0), (w, d), (0.0, d))
    return [(corners[i], corners[(i + 1) % 4]) for i in range(4)]


def furniture_faces(item):
    """Visible vertical faces of one piece of furniture: a box's four sides, a divider's two
    long faces."""
    c = item.corners()
    if item.kind == "divider":
        return [(c[0], c[1]), (c[2], c[3])]
    return [(c[i], c[(i + 1) % 4]) for i in range(4)]


def scene_walls(room, removed=frozenset()):
    """Every static vertical surface as ``sim.scene.Wall`` (room walls then furniture, but
    the items named in ``removed``)."""
    walls = [
        Wall(a[0], a[1], b[0], b[1], room.height, tuple(room.wall_color), "room")
        for a, b in room_segments(room)
    ]
    for item in room.furniture:
        if item.name in removed:
            continue
        walls += [
            Wall(a[0], a[1], b[0], b[1], item.height, tuple(item.color), item.kind, item.name)
            for a, b in furniture_faces(item)
        ]
    return tuple(walls)


def add_static_shapes(space, room, *, wall_type, furniture_type, friction):
    """Add the walls and furniture to ``space``; returns ``{shape: (kind, name)}``."""
    body = space.static_body
    r = WALL_THICKNESS / 2
    w, d = room.width, room.depth
    shapes = {}
    # Centre lines a half thickness outside the room, extended past the corners.
    for a, b in (
        ((-2 * r, -r), (w + 2 * r, -r)),
        ((w + r, -2 * r), (w + r, d + 2 * r)),
        ((w + 2 * r, d + r), (-2 * r, d + r)),
        ((-r, d + 2 * r), (-r, -2 * r)),
    ):
        shape = pymunk.Segment(body, a, b, r)
        shapes[shape] = ("wall", None)
    for item in room.furniture:
        shape = pymunk.Poly(body, item.corners())
        shapes[shape] = ("furniture", item.name)
    for shape, (kind, _) in shapes.items():
        shape.collision_type = wall_type if kind == "wall" else furniture_type
        shape.friction = friction
        shape.elasticity = 0.0
    space.add(*shapes)
    return shapes


def map_data(room, removed=frozenset()):
    """``(walls, obstacles, obstacle_colors, bounds)`` for ``records.WorldMap`` (without the
    furniture named in ``removed``)."""
    walls = room_segments(room)
    present = [item for item in room.furniture if item.name not in removed]
    obstacles = [item.corners() for item in present]
    colors = [tuple(round(c * 255) for c in item.color) for item in present]
    return walls, obstacles, colors, (0.0, 0.0, room.width, room.depth)
