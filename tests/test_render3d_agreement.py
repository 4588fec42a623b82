"""The raster and the 3D renderer mean the same scene: with shadows off (and no sensor model),
the person in red is at the same image column (centroid within 2 columns) and of the same
size (red pixel count within 15%) across distances and bearings. The expected column is
also the pinhole's own: ``W/2 - f tan(bearing)``, ``f = (W/2) / tan(hfov/2)``."""

import math

import pytest
from render3d_scenes import HFOV, POSE, H, W, mujoco_missing, person_scene, red_pixels

from fpga_robotics.sim.camera.raster import CameraRenderer

pytestmark = mujoco_missing

DISTANCES = (2.0, 3.0, 4.5, 6.0)
BEARINGS = (-25.0, -10.0, 0.0, 15.0, 25.0)


@pytest.fixture(scope="module")
def renderers():
    from fpga_robotics.sim.camera.render3d import MujocoRenderer, Render3DOptions

    return CameraRenderer(W, H, HFOV), MujocoRenderer(W, H, HFOV, Render3DOptions(shadows=False))


@pytest.mark.parametrize("distance", DISTANCES)
def test_the_person_is_at_the_same_column_and_size_in_both_renderers(renderers, distance):
    raster, mujoco = renderers
    f = (W / 2) / math.tan(HFOV / 2)
    for bearing in BEARINGS:
        scene = person_scene(distance, bearing)
        n_raster, col_raster = red_pixels(raster.render(scene, POSE))
        n_3d, col_3d = red_pixels(mujoco.render(scene, POSE))
        where = f"at {distance} m, bearing {bearing} deg"
        assert n_raster > 50 and n_3d > 50, where
        assert abs(col_3d - col_raster) <= 2.0, where
        assert abs(n_3d - n_raster) <= 0.15 * n_raster, (where, n_3d, n_raster)
        # The pinhole's column of the person's centre.
        expected = W / 2 - f * math.tan(math.radians(bearing))
        assert abs(col_3d - expected) <= 2.0, where


def test_shadows_change_the_frame_but_not_where_the_person_is():
    from fpga_robotics.sim.camera.render3d import MujocoRenderer, Render3DOptions

    scene = person_scene(3.0, 10.0)
    plain = MujocoRenderer(W, H, HFOV, Render3DOptions(shadows=False)).render(scene, POSE)
    shaded = MujocoRenderer(W, H, HFOV, Render3DOptions(shadows=True)).render(scene, POSE)
    assert (plain != shaded).any(axis=2).sum() > 100  # the walls' and the person's shadows
    # Shadows darken: hardly a pixel gets brighter (a few at the person's outline) by more than
    # OpenGL's rounding, one level times the light's gain (ambient 0.6 + intensity 0.5: 1.1).
    assert (shaded.astype(int) > plain.astype(int) + 2).any(axis=2).mean() < 0.002
    assert abs(red_pixels(shaded)[1] - red_pixels(plain)[1]) <= 2.0
