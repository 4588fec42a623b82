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
