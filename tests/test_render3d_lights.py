"""The 3D renderer's light levels: every lamp up to ``MAX_LAMPS`` is drawn (more are refused,
not dropped)."""

import dataclasses

import pytest
from render3d_scenes import HFOV, POSE, H, W, mujoco_missing

from fpga_robotics.sim.camera.render3d import Lamp, Render3DOptions
from fpga_robotics.sim.camera.render3d.options import MAX_LAMPS
from fpga_robotics.sim.camera.scene import Lighting
from fpga_robotics.sim.world import World

#: A spot on the back wall (x = 8 m), in front of the camera.
SPOT = Lamp((6.5, 3.0, 2.0), (8.0, 3.0, 1.0), (0.5, 0.5, 0.5), 30.0, False)


def _room(ambient, intensity):
    scene = World.from_config({"people": []}, 0).scene()
    return dataclasses.replace(scene, lighting=Lighting(ambient, intensity))


def _dark_lamps(n):
    """Lamps on the floor behind the camera (x = 0.5 m), out of its view."""
    return tuple(
        Lamp((0.5, 0.5 + 0.5 * i, 2.0), (0.5, 0.5 + 0.5 * i, 0.0), (0.5, 0.5, 0.5), 10.0, False)
        for i in range(n)
    )


def _render(ambient, intensity, lamps):
    from fpga_robotics.sim.camera.render3d import MujocoRenderer

    options = Render3DOptions(shadows=False, textures=False, lamps=lamps)
    return MujocoRenderer(W, H, HFOV, options).render(_room(ambient, intensity), POSE)


def test_more_lamps_than_drawn_are_refused():
    with pytest.raises(ValueError, match=f"at most {MAX_LAMPS} lamps"):
        Render3DOptions(lamps=_dark_lamps(MAX_LAMPS + 1))


@mujoco_missing
def test_the_last_lamp_allowed_is_drawn():
    wall = (slice(H // 4, H // 2), slice(W // 4, 3 * W // 4))
    without = _render(0.2, 0.0, _dark_lamps(MAX_LAMPS - 1))[wall].astype(int)
    lit = _render(0.2, 0.0, _dark_lamps(MAX_LAMPS - 1) + (SPOT,))[wall].astype(int)
    # The spot: levels well above the ambient-only wall (albedo 0.8 x 0.2 x 255 = 41).
    assert without.max() <= 42
    assert lit.max() > without.max() + 40


@mujoco_missing
def test_light_summing_over_1_is_as_bright_as_the_raster_draws_it():
    # Ambient 0.8 and a directional light of 0.5 from (1, 0.5, -1): the floor and the back
    # wall (facing -x) each get 0.8 + 0.5 * 2/3, so red = albedo * 1.133 * 255 (the floor's
    # albedo 0.55, the wall's 0.8), not the albedo alone.
    image = _render(0.8, 0.5, ()).astype(float)
    floor, wall = image[H - 10 :, 40:120, 0], image[H // 2 - 15 : H // 2 - 5, 40:120, 0]
    assert floor.mean() == pytest.approx(0.55 * (0.8 + 0.5 * 2 / 3) * 255, abs=2)
    assert wall.mean() == pytest.approx(0.8 * (0.8 + 0.5 * 2 / 3) * 255, abs=2)


@mujoco_missing
def test_a_lamps_light_grows_with_its_color():
    dark = _render(0.2, 0.0, ()).astype(int)

    def added(level):
        lamp = dataclasses.replace(SPOT, color=(level,) * 3)
        return (_render(0.2, 0.0, (lamp,)).astype(int) - dark)[..., 0].max()

    # Where the spot is brightest: albedo 0.8 x the lamp's level x 255 (less its cone's fall).
    assert added(0.5) > 80
    assert added(1.0) == pytest.approx(2 * added(0.5), abs=4)
