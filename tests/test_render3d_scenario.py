"""``camera.renderer`` and the 3D renderer's keys: defaults, bad values as one-line errors,
the closed loop in either renderer, and a missing MuJoCo or OpenGL as exit code 2 with the
install command."""

import os
import subprocess
import sys

import numpy as np
import pytest
from render3d_scenes import mujoco_missing

from fpga_robotics.loop.connectors.camera import CameraConnector
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sim.camera.raster import CameraRenderer
from fpga_robotics.sim.camera.render3d import Lamp


def test_the_raster_is_the_default_and_the_keys_have_defaults():
    cam = load_scenario("follow_person").camera
    assert cam.renderer == "raster"
    assert cam.render3d.shadows and cam.render3d.textures and cam.render3d.lamps == ()
    assert isinstance(CameraConnector(160, 120, 1.0, mount_height=0.3).renderer, CameraRenderer)


def test_lamps_and_options_are_read():
    cam = load_scenario(
        "follow_person",
        [
            "camera.renderer=mujoco",
            "camera.shadows=false",
            "camera.shadow_size=512",
            "camera.floor=tiles",
            "camera.shine=0.4",
            "camera.lamps=[{pos = [7, 3, 2.4], aim = [7.3, 3, 1], color = [1, 0.6, 0.3]}]",
        ],
    ).camera
    o = cam.render3d
    assert (o.shadows, o.shadow_size, o.floor, o.shine) == (False, 512, "tiles", 0.4)
    assert o.lamps == (Lamp((7.0, 3.0, 2.4), (7.3, 3.0, 1.0), (1.0, 0.6, 0.3), 45.0, True),)


def test_a_3d_key_set_for_the_raster_is_refused():
    # The raster reads none of them: set without the 3D renderer, it changed nothing.
    with pytest.raises(
        ScenarioError, match=r'^camera\.shine is not used: camera\.renderer is "raster"'
    ):
        load_scenario("follow_person", ["camera.shine=0.4"])
    with pytest.raises(ScenarioError, match=r"^camera\.lamps is not used"):
        load_scenario("follow_person", ["camera.lamps=[{pos = [1, 2, 2], aim = [1, 2, 0]}]"])
    # A 3D scenario's own keys stay when its renderer is switched to the raster.
    assert load_scenario("divider_3d", ["camera.renderer=raster"]).camera.renderer == "raster"


@pytest.mark.parametrize(
    "override, message",
    [
        ("camera.renderer=vulkan", "camera.renderer must be one of 'raster', 'mujoco'"),
        ("camera.shadow_size=10", "camera.shadow_size must be an integer in 64..8192"),
        ("camera.floor=marble", "camera.floor must be one of"),
        ("camera.shine=2", "camera.shine must be a number in 0..1"),
        ("camera.shadows=3", "camera.shadows must be true or false"),
        ("camera.lamps=[{pos = [1, 2, 2]}]", "camera.lamps[0].aim is required"),
        ("camera.lamps=[{pos = [1, 2, 2], aim = [1, 2, 2]}]", "must differ from its pos"),
        ("camera.lamps=[{pos = [1, 2], aim = [1, 2, 0]}]", "camera.lamps[0].pos must be an array"),
        (
            "camera.lamps=[{pos = [1, 2, 2], aim = [1, 2, 0], colour = [1, 1, 1]}]",
            "unknown key camera.lamps[0].colour",
        ),
        (
            "camera.lamps=[" + ", ".join(["{pos = [1, 2, 2], aim = [1, 2, 0]}"] * 7) + "]",
            "camera.lamps must hold at most 6 lamps",
        ),
    ],
)
def test_bad_values_are_named(override, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [override])
    assert message in str(info.value)


def _run(*args, env=None):
    return subprocess.run(
        [sys.executable, "-m", "fpga_robotics.run", *args],
        env=env,
        capture_output=True,
        check=False,
        text=True,
        timeout=120,
    )


def test_missing_mujoco_is_one_line_with_the_install_command(tmp_path):
    # A module named mujoco that fails to import, first on the path.
    (tmp_path / "mujoco.py").write_text("raise ImportError('no mujoco here')\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    r = _run(
        "--set",
        "camera.renderer=mujoco",
        "--duration",
        "0.1",
        "--rerun",
        "off",
        "--backend",
        "model",
        env=env,
    )
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1
    assert 'pip install -e ".[realistic]"' in r.stderr and "libegl1" in r.stderr


@mujoco_missing
def test_no_opengl_is_one_line_too():
    env = {**os.environ, "MUJOCO_GL": "nonexistent"}
    r = _run(
        "--set",
        "camera.renderer=mujoco",
        "--duration",
        "0.1",
        "--rerun",
        "off",
        "--backend",
        "model",
        env=env,
    )
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1
    assert "OpenGL" in r.stderr and "libegl1" in r.stderr


def test_a_missing_gl_library_is_one_line_too(tmp_path):
    # As PyOpenGL fails on MUJOCO_GL=osmesa without libOSMesa, during ``import mujoco``.
    (tmp_path / "mujoco.py").write_text(
        "raise AttributeError(\"'NoneType' object has no attribute 'glGetError'\")\n"
    )
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "MUJOCO_GL": "osmesa"}
    r = _run(
        "--set",
        "camera.renderer=mujoco",
        "--duration",
        "0.1",
        "--rerun",
        "off",
        "--backend",
        "model",
        env=env,
    )
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1
    assert "no off-screen OpenGL context" in r.stderr and "MUJOCO_GL=osmesa" in r.stderr


@mujoco_missing
def test_the_closed_loop_runs_in_3d_and_repeats_with_the_seed():
    scenario = load_scenario("follow_person", ["camera.renderer=mujoco", "sim.duration=1.0"])

    def frames(seed):
        out = []
        r = run_scenario(
            scenario,
            seed=seed,
            backend="model",
            on_frame=lambda rec: out.append(rec.camera_rgb.copy()),
        )
        return r, out

    r1, a = frames(1)
    _, b = frames(1)
    assert len(a) == 30 and all(np.array_equal(x, y) for x, y in zip(a, b))
    assert r1.summary["found_fraction"] > 0.9  # the design sees the person in red
