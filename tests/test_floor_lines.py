"""Floor markings ([[room.lines]], sim/world/markings.py): geometry by hand, validation that
names the key, the painted band's polygons, the world's floor colour, the map and the camera
image where the pinhole model puts a line."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.camera.floor_patches import patch_index
from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length
from fpga_robotics.sim.world import World, WorldConfigError
from fpga_robotics.sim.world.markings import MITRE_TURN, FloorLine

SQUARE = ((1.0, 1.0), (3.0, 1.0), (3.0, 3.0), (1.0, 3.0))


def test_distance_cover_arc_and_length_of_a_closed_square():
    line = FloorLine("sq", SQUARE, 0.02, closed=True)
    assert line.length == pytest.approx(8.0)
    assert line.distance(2.0, 1.3) == pytest.approx(0.3)
    assert line.distance(0.5, 0.5) == pytest.approx(math.hypot(0.5, 0.5))  # the corner
    assert line.covers(2.0, 1.0099) and not line.covers(2.0, 1.0101)
    assert line.arc_position(2.5, 1.1) == pytest.approx(1.5)
    assert line.arc_position(3.1, 2.0) == pytest.approx(3.0)
    assert line.arc_position(1.05, 1.5) == pytest.approx(7.5)  # on the closing segment
    x = np.array([2.0, 2.0]), np.array([1.0, 2.0])
    np.testing.assert_array_equal(line.covers(*x), [True, False])


def test_an_open_line_has_round_ends():
    line = FloorLine("l", ((0.0, 0.0), (1.0, 0.0)), 0.1)
    assert line.length == pytest.approx(1.0)
    assert line.covers(1.04, 0.0) and not line.covers(1.04, 0.04)  # 0.0566 > 0.05
    assert line.arc_position(-1.0, 0.0) == 0.0 and line.arc_position(2.0, 0.0) == 1.0


def _sample_band(line, n=40000, seed=0):
    x0, y0, x1, y1 = line.bounds
    rng = np.random.default_rng(seed)
    x = rng.uniform(x0 - 0.05, x1 + 0.05, n)
    y = rng.uniform(y0 - 0.05, y1 + 0.05, n)
    return x, y, line.distance(x, y)


@pytest.mark.parametrize("closed", [False, True])
def test_the_polygons_paint_the_band_without_gaps(closed):
    # A curve of many short segments (gentle bends, mitred) with one sharp corner (a disc).
    pts = [(2.0 + math.cos(a), 2.0 + math.sin(a)) for a in np.linspace(0, 1.5 * math.pi, 60)]
    pts.append((2.0, 2.0))
    line = FloorLine("c", tuple(pts), 0.05, closed=closed)
    x, y, d = _sample_band(line)
    polys = line.polygons()
    painted = patch_index(polys, x, y) >= 0
    half = line.width / 2
    # Every point well inside the band is painted; nothing far outside is. The mitres stick
    # out by at most half * (1 / cos(MITRE_TURN / 2) - 1), the discs' polygons fall short of
    # the circle by half * (1 - cos(pi / 16)).
    assert painted[d < half * math.cos(math.pi / 16) - 1e-9].all()
    assert not painted[d > half / math.cos(MITRE_TURN / 2) + 1e-9].any()


def test_config_lines_are_validated_with_the_key_path():
    def bad(line, match):
        with pytest.raises(WorldConfigError, match=match):
            World.from_config({"room": {"lines": [line]}, "people": []})

    bad({"points": [[1, 1]]}, r"room\.lines\[0\]\.points must be an array of at least 2")
    bad({"points": [[1, 1], [2, 1]], "closed": True}, r"at least 3 points")
    bad({"points": [[1, 1], [20, 1]]}, r"room\.lines\[0\]\.points\[1\] \[20, 1\] is outside")
    bad({"points": [[1, 1], [2, 1]], "width": 0}, r"room\.lines\[0\]\.width must be > 0")
    bad({"points": [[1, 1], [2, 1]], "color": [2, 0, 0]}, r"room\.lines\[0\]\.color\[0\]")
    bad({"points": [[1, 1], [1, 1]]}, r"has no length")
    bad({"points": [[1, 1], [2, 1]], "colour": [0, 0, 0]}, r"did you mean 'color'")
    with pytest.raises(WorldConfigError, match=r"room\.lines\[1\]\.name 'a' is used twice"):
        World.from_config(
            {
                "room": {
                    "lines": [
                        {"name": "a", "points": [[1, 1], [2, 1]]},
                        {"name": "a", "points": [[1, 2], [2, 2]]},
                    ]
                }
            }
        )


def test_the_world_floor_colour_map_and_scene():
    world = World.from_config(
        {
            "room": {
                "floor_color": [0.6, 0.6, 0.6],
                "terrain": [{"center": [2.0, 2.0], "size": [1.0, 1.0], "color": [0.2, 0.8, 0.2]}],
                "lines": [
                    {"name": "tape", "points": [[1.0, 2.0], [3.0, 2.0]], "width": 0.02},
                    {"points": [[2.0, 1.0], [2.0, 3.0]], "width": 0.04, "color": [1.0, 1.0, 1.0]},
                ],
            },
            "people": [],
        }
    )
    assert [line.name for line in world.floor_lines] == ["tape", "line1"]
    assert world.floor_color_at(1.2, 2.009) == (0.0, 0.0, 0.0)  # tape off the patch
    assert world.floor_color_at(1.2, 2.011) == (0.6, 0.6, 0.6)  # the floor
    assert world.floor_color_at(2.3, 2.2) == (0.2, 0.8, 0.2)  # the patch
    assert world.floor_color_at(2.0, 2.0) == (1.0, 1.0, 1.0)  # the later line on top
    rng = np.random.default_rng(0)
    x, y = rng.uniform(1.4, 2.6, 3000), rng.uniform(1.4, 2.6, 3000)
    np.testing.assert_array_equal(
        world.floor_colors_at(x, y), [world.floor_color_at(a, b) for a, b in zip(x, y)]
    )
    world_map = world.world_map()
    assert world_map.lines == [[(1.0, 2.0), (3.0, 2.0)], [(2.0, 1.0), (2.0, 3.0)]]
    assert world_map.line_widths == [0.02, 0.04]
    assert world_map.line_colors == [(0, 0, 0), (255, 255, 255)]
    patches = world.scene().floor_patches
    assert patches[0][1] == (0.2, 0.8, 0.2)  # the terrain first, the lines drawn over it
    assert {c for _, c in patches[1:]} == {(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)}


def test_a_line_is_drawn_where_the_pinhole_model_puts_it(tmp_path):
    # A 5 cm black line across the view 1.5 m ahead of a camera 0.3 m high at (1, 3).
    w, h, hfov = 160, 120, 1.047
    world = World.from_config(
        {
            "room": {"lines": [{"points": [[2.5, 1.0], [2.5, 5.0]], "width": 0.05}]},
            "robot": {
                "start": [0.92, 3.0],
                "camera_height": 0.3,
                "camera_forward": 0.08,
                "camera_tilt_deg": 0,
            },
            "people": [],
        }
    )
    pose = world.camera_pose()
    assert pose.x == pytest.approx(1.0)
    image = CameraRenderer(w, h, hfov).render(world.scene(), pose)
    f = focal_length(w, hfov)
    # Floor at depth p is at row H/2 - 0.5 + f h / p: the band spans depths 1.475..1.525 m.
    near, far = h / 2 - 0.5 + f * 0.3 / 1.475, h / 2 - 0.5 + f * 0.3 / 1.525
    black = np.all(image == 0, axis=2)
    rows = np.nonzero(black[:, w // 2])[0]
    assert rows.size >= 1
    assert rows.min() >= math.floor(far) and rows.max() <= math.ceil(near)
    assert black[round((near + far) / 2)].all()  # across the whole width of the image
    assert black.sum() == pytest.approx(w * rows.size, rel=0.05)
