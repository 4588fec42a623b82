"""The MJCF model built from a scenario's scene (sim.render3d.mjcf): furniture as solids of the
scenario's size, one person's body per cylinder, a light per lamp, textures that keep the
surfaces' colours."""

import numpy as np
import pytest
from render3d_scenes import mujoco_missing

from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.render3d import Render3DOptions
from fpga_robotics.sim.camera.render3d.mjcf import build_model_xml
from fpga_robotics.sim.world import World

pytestmark = mujoco_missing


@pytest.fixture(scope="module")
def divider():
    from fpga_robotics.sim.camera.render3d import load_mujoco

    mujoco = load_mujoco()  # off-screen (EGL), as the renderer imports it
    scenario = load_scenario("divider_3d")
    scene = World.from_config(scenario.world, 0).scene()
    spec = build_model_xml(scene, scenario.camera.render3d, 160, 120, 45.0)
    return scene, spec, mujoco.MjModel.from_xml_string(spec.xml)


def test_the_divider_is_one_board_of_its_size(divider):
    _, _, model = divider
    boxes = [
        (model.geom_pos[i], model.geom_size[i])
        for i in range(model.ngeom)
        if model.geom_type[i] == 6 and model.geom_bodyid[i] == 0
    ]  # mjGEOM_BOX, static
    # The scenario's divider: 3.0 x 0.04 m, 1.8 m high, centred at (7.3, 3.0), turned 90 deg.
    match = [(p, s) for p, s in boxes if np.allclose(p, (7.3, 3.0, 0.9), atol=1e-6)]
    assert len(match) == 1
    assert match[0][1] == pytest.approx((1.5, 0.02, 0.9), abs=1e-6)
    # The room: four slabs 2.5 m high outside the 8 x 6 m floor.
    walls = [(p, s) for p, s in boxes if s[2] == pytest.approx(1.25)]
    assert len(walls) == 4
    assert sorted(round(float(p[0]), 3) for p, _ in walls) == [-0.025, 4.0, 4.0, 8.025]


def test_a_body_per_person_and_a_light_per_lamp(divider):
    scene, spec, model = divider
    assert len(spec.people) == len(scene.cylinders) == 1
    assert model.nmocap == 2  # the camera and the person
    assert model.nlight == 1 + 1  # the scenario's light and its lamp
    assert model.njnt == 8  # hips, knees, shoulders, elbows


def test_textures_average_to_the_surface_colour(divider):
    scene, spec, _ = divider
    wood = scene.walls[-1].color
    grains = [
        t
        for t in spec.textures.values()
        if np.allclose(t.reshape(-1, 3).mean(axis=0) / 255, wood, atol=0.02)
    ]
    assert grains, "no texture averages to the divider's colour"
    flat = build_model_xml(scene, Render3DOptions(textures=False), 160, 120, 45.0)
    for t in flat.textures.values():
        assert (t == t.reshape(-1, 3)[0]).all()  # textures off: one colour each
