"""What the world hands the renderer and the viewer: scene walls, people, map, camera."""

import math

import pytest

from fpga_robotics.sim.camera.scene import Band, Scene, Wall
from fpga_robotics.sim.world import World


def length(wall):
    return math.hypot(wall.x1 - wall.x0, wall.y1 - wall.y0)


def test_room_walls_enclose_the_room_at_the_configured_height():
    world = World.from_config(
        {"room": {"width": 5.0, "depth": 4.0, "height": 3.0, "wall_color": [0.5, 0.6, 0.7]}}, seed=0
    )
    scene = world.scene()
    assert isinstance(scene, Scene)
    assert len(scene.walls) == 4
    assert sorted(length(w) for w in scene.walls) == [4.0, 4.0, 5.0, 5.0]
    corners = {(w.x0, w.y0) for w in scene.walls} | {(w.x1, w.y1) for w in scene.walls}
    assert corners == {(0, 0), (5, 0), (5, 4), (0, 4)}
    assert all(w.height == 3.0 and w.color == (0.5, 0.6, 0.7) for w in scene.walls)
    assert scene.ceiling_height == 3.0


def test_box_has_four_faces_and_divider_two_long_faces():
    room = {
        "furniture": [
            {
                "name": "table",
                "center": [3.0, 1.0],
                "size": [1.2, 0.8],
                "height": 0.7,
                "color": [0.3, 0.3, 0.3],
            },
            {
                "name": "divider",
                "type": "divider",
                "center": [6.0, 3.0],
                "size": [2.0, 0.04],
                "angle_deg": 90,
            },
        ]
    }
    world = World.from_config({"room": room}, seed=0)
    walls = world.scene().walls[4:]
    table, divider = walls[:4], walls[4:]
    assert sorted(round(length(w), 9) for w in table) == [0.8, 0.8, 1.2, 1.2]
    assert all(w.height == 0.7 and w.color == (0.3, 0.3, 0.3) for w in table)
    assert len(divider) == 2
    assert all(length(w) == pytest.approx(2.0) for w in divider)
    # Turned 90 degrees: the long faces run along y, 2 cm either side of x = 6.
    assert sorted(round(w.x0, 9) for w in divider) == [5.98, 6.02]
    assert all(w.x0 == pytest.approx(w.x1) for w in divider)
    assert all(w.color == (0.55, 0.27, 0.15) and w.height == 1.6 for w in divider)


def test_people_are_banded_cylinders_where_they_stand():
    people = [
        {"name": "target", "waypoints": [[4.0, 2.0]]},
        {
            "name": "short",
            "waypoints": [[6.0, 4.0]],
            "height": 1.4,
            "radius": 0.15,
            "shirt_color": [0.1, 0.2, 0.9],
            "trousers_color": [0.9, 0.9, 0.9],
        },
    ]
    scene = World.from_config({"people": people}, seed=0).scene()
    default, short = scene.cylinders
    assert (default.x, default.y, default.radius) == (4.0, 2.0, 0.2)
    bands = sorted(default.bands, key=lambda b: b.z0)
    heights = [z for b in bands for z in (b.z0, b.z1)]
    assert heights == pytest.approx([0, 0.85, 0.85, 1.45, 1.5, 1.75])
    assert bands[1].color == (0.85, 0.1, 0.1)  # red shirt
    assert max(bands[0].color) < 0.3  # dark trousers
    assert bands[2].color[0] > bands[2].color[2] > 0.3  # skin
    assert short.radius == 0.15
    tops = sorted((b.z1, b.color) for b in short.bands)
    assert tops[-1][0] == pytest.approx(1.4)
    assert tops[1] == (pytest.approx(1.45 * 1.4 / 1.75), (0.1, 0.2, 0.9))
    assert tops[0][1] == (0.9, 0.9, 0.9)
    assert all(isinstance(b, Band) for b in short.bands)


def test_scene_follows_people_as_they_walk():
    people = [{"waypoints": [[2.0, 1.0], [6.0, 1.0]], "speed": 1.0, "loop": False}]
    world = World.from_config({"people": people}, seed=0)
    for _ in range(200):
        world.step(1 / 200)
    (cyl,) = world.scene().cylinders
    assert (cyl.x, cyl.y) == pytest.approx((3.0, 1.0), abs=1e-9)


def test_world_map_has_walls_obstacles_and_bounds():
    room = {
        "width": 6.0,
        "depth": 5.0,
        "furniture": [
            {"center": [2.0, 2.0], "size": [1.0, 0.5], "angle_deg": 30, "color": [1.0, 0.5, 0.0]}
        ],
    }
    world_map = World.from_config({"room": room}, seed=0).world_map()
    assert world_map.bounds == (0.0, 0.0, 6.0, 5.0)
    assert len(world_map.walls) == 4
    (poly,) = world_map.obstacles
    area = 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]))
    assert area == pytest.approx(0.5)  # 1.0 x 0.5, counter-clockwise (positive)
    assert world_map.obstacle_colors == [(255, 128, 0)]


def test_camera_pose_is_the_mount_on_the_robot():
    world = World.from_config(
        {
            "robot": {
                "start": [2.0, 3.0],
                "heading_deg": 90,
                "camera_height": 0.4,
                "camera_forward": 0.1,
                "camera_tilt_deg": 5,
            }
        },
        seed=0,
    )
    pose = world.camera_pose()
    assert (pose.x, pose.y) == pytest.approx((2.0, 3.1))
    assert pose.heading == pytest.approx(math.pi / 2)
    assert pose.height == 0.4 and pose.tilt == pytest.approx(math.radians(5))


def test_scene_walls_are_scene_walls():
    assert all(isinstance(w, Wall) for w in World.from_config({}, seed=0).scene().walls)
