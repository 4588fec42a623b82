"""Coloured floor patches in the raster camera (sim/camera/floor_patches.py): drawn where the
pinhole model puts them, lit as the floor, under the walls and people, noise after them."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length
from fpga_robotics.sim.camera.scene import Band, CameraPose, Cylinder, Lighting, Scene, Wall

W, H, HFOV = 160, 120, 1.047
LIGHT = Lighting(ambient=0.6, intensity=0.5, direction=(1.0, 0.5, -1.0))
PATCH = (((1.0, -0.5), (2.0, -0.5), (2.0, 0.5), (1.0, 0.5)), (0.8, 0.1, 0.1))


def _scene(**kw):
    wall = Wall(6.0, -5.0, 6.0, 5.0, 2.5, (0.7, 0.7, 0.7))
    return Scene(walls=(wall,), floor_color=(0.5, 0.5, 0.45), lighting=LIGHT, **kw)


def _lit(albedo):
    d = np.array(LIGHT.direction) / np.linalg.norm(LIGHT.direction)
    shade = LIGHT.ambient + LIGHT.intensity * max(0.0, -d[2])
    return np.clip(np.array(albedo) * shade * 255 + 0.5, 0, 255).astype(np.uint8)


def test_a_patch_is_drawn_between_its_near_and_far_edges():
    renderer = CameraRenderer(W, H, HFOV)
    pose = CameraPose(0.0, 0.0, 0.0, height=0.3, tilt=0.0)
    image = renderer.render(_scene(floor_patches=(PATCH,)), pose)
    plain = renderer.render(_scene(), pose)
    f = focal_length(W, HFOV)
    # Centre column: a floor point at depth p is at row centre H/2 - 0.5 + f h / p.
    near, far = H / 2 - 0.5 + f * 0.3 / 1.0, H / 2 - 0.5 + f * 0.3 / 2.0
    col = W // 2
    red = np.all(image[:, col] == _lit(PATCH[1]), axis=1)
    rows = np.nonzero(red)[0]
    assert rows.min() == pytest.approx(far, abs=1.0) and rows.max() == pytest.approx(near, abs=1.0)
    # Everything else is the plain image: the wall, the rest of the floor.
    outside = ~np.all(image == _lit(PATCH[1]), axis=2)
    np.testing.assert_array_equal(image[outside], plain[outside])
    # The patch is 1 m wide at 1.5 m: about f * 1 / 1.5 columns at its middle row.
    mid = round(H / 2 - 0.5 + f * 0.3 / 1.5)
    width = int(np.all(image[mid] == _lit(PATCH[1]), axis=1).sum())
    assert width == pytest.approx(f / 1.5, abs=2)


def test_people_stand_on_the_patch_and_a_later_patch_covers_an_earlier_one():
    renderer = CameraRenderer(W, H, HFOV)
    pose = CameraPose(0.0, 0.0, 0.0, height=0.3)
    person = Cylinder(1.5, 0.0, 0.2, (Band(0.0, 1.7, (0.1, 0.1, 0.8)),))
    blue = np.array(_lit((0.1, 0.1, 0.8)))
    under = (((0.5, -1.0), (3.0, -1.0), (3.0, 1.0), (0.5, 1.0)), (0.1, 0.7, 0.1))
    image = renderer.render(
        Scene(cylinders=(person,), floor_patches=(under, PATCH), lighting=LIGHT), pose
    )
    col = W // 2
    assert np.all(image[:, col] == _lit(PATCH[1]), axis=1).sum() > 0  # the later one on top
    assert np.all(image[:, col] == _lit(under[1]), axis=1).sum() > 0
    # The person is drawn over the floor (blue where the ray meets the cylinder).
    assert (np.abs(image[:, col].astype(int) - blue).sum(axis=1) < 60).sum() > 10


def test_noise_comes_after_the_patches_and_is_seeded():
    renderer = CameraRenderer(W, H, HFOV)
    pose = CameraPose(0.0, 0.0, 0.0, height=0.3)
    scene = _scene(floor_patches=(PATCH,))
    clean = renderer.render(scene, pose)
    a = renderer.render(scene, pose, noise_std=3.0, rng=np.random.default_rng(1))
    b = renderer.render(scene, pose, noise_std=3.0, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)
    diff = a.astype(int) - clean
    assert abs(diff.mean()) < 0.2 and diff.std() == pytest.approx(3.0, rel=0.1)


def test_the_world_draws_its_coloured_terrain():
    from fpga_robotics.sim.world import World

    world = World.from_config(
        {
            "room": {
                "terrain": [
                    {
                        "name": "mat",
                        "center": [3.0, 3.0],
                        "size": [1.0, 1.0],
                        "color": [0.8, 0.1, 0.1],
                    },
                    {"name": "wet", "center": [5.0, 3.0], "size": [1.0, 1.0], "friction": 0.3},
                ]
            },
            "robot": {"start": [1.5, 3.0]},
            "people": [],
        },
        seed=0,
    )
    scene = world.scene()
    assert len(scene.floor_patches) == 1  # the wet patch has no colour: not drawn
    ((poly, color),) = scene.floor_patches
    assert color == (0.8, 0.1, 0.1) and len(poly) == 4
    assert math.isclose(min(p[0] for p in poly), 2.5) and math.isclose(max(p[1] for p in poly), 3.5)


def test_triangulation_covers_any_simple_polygon():
    from fpga_robotics.sim.camera.render3d.floor_patches import triangulate

    def area(poly):
        return (
            abs(
                sum(
                    x0 * y1 - x1 * y0
                    for (x0, y0), (x1, y1) in zip(poly, list(poly[1:]) + [poly[0]])
                )
            )
            / 2
        )

    square = ((0, 0), (2, 0), (2, 2), (0, 2))
    l_shape = ((0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3))  # not convex, area 5
    for poly, n in ((square, 2), (l_shape, 4), (tuple(reversed(l_shape)), 4)):
        tris = triangulate(poly)
        assert len(tris) == n
        assert sum(area(t) for t in tris) == pytest.approx(area(poly))
        # Every triangle lies inside the polygon (its centroid does).
        from fpga_robotics.sim.world.terrain import polygon_contains

        for t in tris:
            cx, cy = sum(p[0] for p in t) / 3, sum(p[1] for p in t) / 3
            assert polygon_contains(poly, cx, cy)


def test_the_3d_model_has_one_flat_mesh_per_triangle():
    from fpga_robotics.sim.camera.render3d.floor_patches import LIFT, patch_assets_and_geoms

    scene = _scene(
        floor_patches=(PATCH, (((0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)), (0.2, 0.3, 0.9)))
    )
    assets, geoms = patch_assets_and_geoms(scene)
    assert len(assets) == len(geoms) == 2 + 4
    assert 'rgba="0.8 0.1 0.1 1"' in geoms[0] and 'contype="0"' in geoms[0]
    # Six vertices a triangle, at LIFT / 2 and LIFT: above the floor, below anything on it.
    zs = {float(v) for a in assets for v in a.split('vertex="')[1].rstrip('"/>').split()[2::3]}
    assert zs == {LIFT / 2, LIFT}
