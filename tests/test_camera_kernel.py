"""The camera's compiled per-pixel stage gives the numpy path's bytes, noise included."""

import math

import numpy as np
import pytest

from fpga_robotics.bench.camera import camera_loop, typical_scene
from fpga_robotics.sim.camera.kernel import camera_kernel
from fpga_robotics.sim.camera.raster import CameraRenderer
from fpga_robotics.sim.camera.scene import CameraPose, Scene


def _have_compiler():
    from fpga_robotics.sim.backends.base import BackendError
    from fpga_robotics.sim.backends.toolchain import find_compiler

    try:
        find_compiler()
    except BackendError:
        return False
    return True


pytestmark = pytest.mark.skipif(not _have_compiler(), reason="no C++ compiler here")


def test_the_compiled_stages_build_where_there_is_a_compiler():
    assert camera_kernel() is not None


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
    scene = Scene(
        walls=typical_scene().walls,
        cylinders=(),
        floor_color=(0.0, 0.0, 0.0),
        ceiling_color=(1.0, 1.0, 1.0),
    )
    pose = CameraPose(4.0, 3.0, 0.3)
    a = compiled.render(scene, pose, noise_std=60.0, rng=np.random.default_rng(1))
    b = numpy_path.render(scene, pose, noise_std=60.0, rng=np.random.default_rng(1))
    np.testing.assert_array_equal(a, b)
    assert (a == 255).any() and (a == 0).any()


def test_empty_scene_and_tilt_equal_numpy():
    compiled, numpy_path = pair(48, 40)
    for scene, tilt in (
        (Scene(walls=(), cylinders=()), 0.0),
        (typical_scene(), 0.2),
        (typical_scene(), -0.3),
    ):
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
        compiled.render(typical_scene(), pose, noise_std=float("nan"), rng=np.random.default_rng(0))


def random_room(rng):
    """Walls in every direction (some parallel to columns' rays), people with bands, one of
    them around the camera now and then."""
    from fpga_robotics.sim.camera.scene import Band, Cylinder, Lighting, Wall

    walls = []
    for _ in range(int(rng.integers(0, 12))):
        x0, y0 = rng.uniform(-1, 9, 2)
        if rng.random() < 0.2:  # axis-aligned, like most rooms
            x1, y1 = (
                (x0 + rng.uniform(0.1, 4), y0)
                if rng.random() < 0.5
                else (x0, y0 + rng.uniform(0.1, 4))
            )
        else:
            x1, y1 = rng.uniform(-1, 9, 2)
        walls.append(Wall(x0, y0, x1, y1, rng.uniform(0.2, 3.0), tuple(rng.uniform(0, 1, 3))))
    people = []
    for _ in range(int(rng.integers(0, 5))):
        bands = tuple(
            Band(z, z + rng.uniform(0.1, 0.9), tuple(rng.uniform(0, 1, 3)))
            for z in np.sort(rng.uniform(0, 1.8, int(rng.integers(0, 4))))
        )
        people.append(Cylinder(rng.uniform(0, 8), rng.uniform(0, 6), rng.uniform(0.05, 0.6), bands))
    lighting = Lighting(rng.uniform(0, 1), rng.uniform(0, 1), tuple(rng.uniform(-1, 1, 3)))
    # Mostly level (the compiled layer stage), sometimes tilted (numpy's, after compiled hits).
    tilt = 0.0 if rng.random() < 0.7 else rng.uniform(-0.3, 0.3)
    pose = CameraPose(
        rng.uniform(0, 8),
        rng.uniform(0, 6),
        rng.uniform(-math.pi, math.pi),
        height=rng.uniform(0.1, 2.0),
        tilt=tilt,
    )
    if people and rng.random() < 0.2:
        pose = CameraPose(people[0].x, people[0].y, pose.heading, height=pose.height)
    return Scene(walls=tuple(walls), cylinders=tuple(people), lighting=lighting), pose


@pytest.mark.parametrize("seed, max_layers", [(0, 3), (1, 3), (2, 6), (3, 1)])
def test_compiled_stages_equal_numpy_to_the_bit_on_random_rooms(seed, max_layers):
    # Few layers for many surfaces: the hidden-candidate and layer-budget paths run often.
    rng = np.random.default_rng(seed)
    compiled, numpy_path = pair(96, 72, max_layers=max_layers)
    for _ in range(80):
        scene, pose = random_room(rng)
        noise = float(rng.choice([0.0, 3.0]))
        a = compiled.render(scene, pose, noise_std=noise, rng=np.random.default_rng(1))
        b = numpy_path.render(scene, pose, noise_std=noise, rng=np.random.default_rng(1))
        np.testing.assert_array_equal(a, b)
        # The hit arrays themselves, not only the image they make.
        walls, cyls = compiled._geometry(scene)
        if not len(walls.x0) + len(cyls.band_owner):
            continue
        args = (walls, cyls, pose.x, pose.y, pose.heading, 0.4, 0.7, np.array([0.3, -0.8, -0.5]))
        for got, want in zip(compiled._hits_compiled(*args), numpy_path._hits(*args), strict=True):
            np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("bits", [np.random.PCG64, np.random.MT19937, np.random.Philox])
def test_noise_bits_drawn_in_the_kernel_or_by_numpy_are_the_same(bits):
    # A PCG64 is drawn from in the compiled stage (its next_uint64 is its random_raw); other
    # generators' bits come from random_raw. The image and the generator's state agree.
    compiled, numpy_path = pair(64, 48)
    assert (compiled._direct_draw(np.random.Generator(bits(1)))[0] is not None) == (
        bits is np.random.PCG64
    )
    rng_a, rng_b = np.random.Generator(bits(9)), np.random.Generator(bits(9))
    for pose in camera_loop(3):
        a = compiled.render(typical_scene(), pose, noise_std=2.5, rng=rng_a)
        b = numpy_path.render(typical_scene(), pose, noise_std=2.5, rng=rng_b)
        np.testing.assert_array_equal(a, b)
    assert rng_a.bit_generator.random_raw() == rng_b.bit_generator.random_raw()
