"""The camera's compiled per-pixel stage gives the numpy path's bytes, noise included."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.camera import CameraRenderer
from fpga_robotics.sim.camera_bench import camera_loop, typical_scene
from fpga_robotics.sim.camera_pixels import pixel_kernel
from fpga_robotics.sim.scene import CameraPose, Scene

pytestmark = pytest.mark.skipif(pixel_kernel() is None, reason="no C++ compiler here")


def pair(width, height, **kw):
    """Two renderers of one size: the compiled stage and the numpy path."""
    compiled = CameraRenderer(width, height, **kw)
    numpy_path = CameraRenderer(width, height, **kw)
    numpy_path._kernel = None
    assert compiled._kernel is not None
    return compiled, numpy_path


# Widths divisible by 4 draw the noise in one call; 162 and 30 block by block as numpy does.
@pytest.mark.parametrize("size", [(160, 120), (640, 480), (162, 122), (30, 7)])
@pytest.mark.parametrize("noise", [0.0, 2.0, 40.0])
def test_compiled_pixels_equal_numpy_in_a_room(size, noise):
    compiled, numpy_path = pair(*size)
    scene = typical_scene()
    rng_a, rng_b = np.random.default_rng(5), np.random.default_rng(5)
    for pose in camera_loop(6):
        a = compiled.render(scene, pose, noise_std=noise, rng=rng_a)
        b = numpy_path.render(scene, pose, noise_std=noise, rng=rng_b)
        assert a.shape == b.shape == (size[1], size[0], 3) and a.dtype == np.uint8
        assert a.flags.c_contiguous
        np.testing.assert_array_equal(a, b)
    # Both drew exactly the same random bits: the streams are still in step.
    assert rng_a.bit_generator.random_raw() == rng_b.bit_generator.random_raw()


def test_noise_saturates_at_both_ends_like_the_numpy_path():
    # A white wall and a black floor under heavy noise: clipping at 255 and 0 both happen.
    compiled, numpy_path = pair(64, 48)
    scene = Scene(walls=typical_scene().walls, cylinders=(), floor_color=(0.0, 0.0, 0.0),
                  ceiling_color=(1.0, 1.0, 1.0))
    pose = CameraPose(4.0, 3.0, 0.3)
    a = compiled.render(scene, pose, noise_std=60.0, rng=np.random.default_rng(1))
    b = numpy_path.render(scene, pose, noise_std=60.0, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)
    assert (a == 255).any() and (a == 0).any()


def test_empty_scene_and_tilt_equal_numpy():
    compiled, numpy_path = pair(48, 40)
    for scene, tilt in ((Scene(walls=(), cylinders=()), 0.0), (typical_scene(), 0.2),
                        (typical_scene(), -0.3)):
        pose = CameraPose(3.0, 2.0, math.pi / 5, height=0.4, tilt=tilt)
        np.testing.assert_array_equal(compiled.render(scene, pose), numpy_path.render(scene, pose))


def test_each_render_is_a_new_image():
    compiled, _ = pair(32, 24)
    scene = typical_scene()
    poses = camera_loop(2)
    first = compiled.render(scene, poses[0])
    kept = first.copy()
    compiled.render(scene, poses[1])
    np.testing.assert_array_equal(first, kept)


def test_bad_noise_arguments_are_the_same_errors():
    compiled, _ = pair(32, 24)
    pose = CameraPose(3.0, 2.0, 0.0)
    with pytest.raises(TypeError, match="rng=numpy.random.Generator"):
        compiled.render(typical_scene(), pose, noise_std=2.0)
    with pytest.raises(ValueError, match="finite number"):
        compiled.render(typical_scene(), pose, noise_std=float("nan"),
                        rng=np.random.default_rng(0))
