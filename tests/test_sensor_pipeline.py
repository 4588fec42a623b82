"""The OV7670 sensor model as a whole and in the closed loop: seeding, the plain path left
as it was, the turn rate's blur, the scenario's parameters."""

import dataclasses

import numpy as np
import pytest

from fpga_robotics.bench.camera import typical_scene
from fpga_robotics.loop.compressed import ClosedLoop
from fpga_robotics.scenario.load import DEFAULTS, load_scenario
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.camera.sensor import PARAMS, OV7670Params, OV7670Sensor
from fpga_robotics.sim.camera.sensor.blur import motion_blur


@pytest.fixture(scope="module")
def room_frame():
    scene = typical_scene()
    return CameraRenderer(160, 120, 1.047).render(scene, CameraPose(2.0, 3.0, 0.0, height=0.3))


def frames(seed, image, n=4, **params):
    cam = OV7670Sensor(160, 120, OV7670Params(**params), rng=np.random.default_rng(seed))
    return [cam.process(image, turn_rate=0.3 * k) for k in range(n)]


def test_same_seed_same_frames_other_seed_other_noise(room_frame):
    a, b, c = frames(5, room_frame), frames(5, room_frame), frames(6, room_frame)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not np.array_equal(a[-1], c[-1])
    for f in a:
        assert f.dtype == np.uint8 and f.shape == (120, 160, 3)
        assert not np.any(f & 0x0F)  # RGB444 levels


@pytest.mark.parametrize("bayer", ["BGGR", "off"])
def test_a_black_frame_with_read_noise_stays_in_the_adc_range(bayer):
    # Read noise takes dark pixels below zero; the ADC clips them to code 0, at full gain too.
    cam = OV7670Sensor(160, 120, OV7670Params(bayer=bayer), rng=np.random.default_rng(2))
    for _ in range(3):
        out = cam.process(np.zeros((120, 160, 3), np.uint8))
    assert cam.aec.gain == cam.params.max_gain
    # At 32x the read noise (1/398 of full scale before the gain) shows; the mean stays dark.
    assert out.max() > 0 and out.mean() < 48


def test_other_resolutions_and_odd_sizes(room_frame):
    for w, h in ((640, 480), (161, 121), (16, 2)):
        img = np.ascontiguousarray(np.resize(room_frame, (h, w, 3)))
        out = OV7670Sensor(w, h, rng=np.random.default_rng(0)).process(img)
        assert out.shape == (h, w, 3)
    with pytest.raises(ValueError, match=r"\(120, 160, 3\) uint8"):
        OV7670Sensor(160, 120, rng=np.random.default_rng(0)).process(room_frame[:, :80])


def test_the_turn_rate_blurs_by_rate_times_exposure_times_focal_length(room_frame):
    f = focal_length(160, 1.047)
    cam = OV7670Sensor(
        160,
        120,
        OV7670Params(aec=False, exposure=0.5, settle_frames=0),
        rng=np.random.default_rng(0),
        frame_period=1 / 30,
        focal_px=f,
    )
    light = cam.light(room_frame, turn_rate=-2.0)
    length = 2.0 * (0.5 / 30) * f  # 4.62 px
    assert cam.last_blur_px == pytest.approx(length)
    expected = motion_blur(cam._radiance.take(room_frame), length)
    assert np.allclose(light, expected.reshape(-1).take(cam._mosaic_index), atol=1e-6)
    assert np.array_equal(
        cam.light(room_frame, 0.0),
        cam._radiance.take(room_frame).reshape(-1).take(cam._mosaic_index),
    )
    sharp = OV7670Sensor(
        160, 120, OV7670Params(motion_blur=False, settle_frames=0), rng=np.random.default_rng(0)
    )
    sharp.light(room_frame, turn_rate=5.0)
    assert sharp.last_blur_px == 0.0


def test_the_parameter_table_and_the_dataclass_agree():
    assert [f.name for f in dataclasses.fields(OV7670Params)] == list(PARAMS)
    defaults = DEFAULTS["camera"]["ov7670"]
    assert OV7670Params.from_dict(defaults) == OV7670Params()


def test_plain_is_the_default_and_its_frames_are_todays():
    # The plain path: the renderer with camera.noise_std from the stream [seed, 0xCA3E], as
    # before the sensor model existed.
    s = load_scenario("divider")
    assert s.camera.sensor == "plain"
    loop = ClosedLoop(s, design=ModelBackend(s.params))
    assert loop.camera.sensor is None and loop.camera.sensor_state() is None
    pose, rgb, _ = loop.capture(0.0)
    expected = CameraRenderer(160, 120, s.camera.hfov).render(
        loop.world.scene(),
        pose,
        noise_std=s.camera.noise_std,
        rng=np.random.default_rng([loop.seed, 0xCA3E]),
    )
    assert np.array_equal(rgb, expected)


def test_ov7670_in_the_loop_is_seeded_and_leaves_the_world_alone():
    plain = load_scenario("lighting")
    ov = load_scenario("lighting", ["camera.sensor=ov7670", "camera.ov7670.max_gain=8"])
    assert ov.camera.ov7670.max_gain == 8.0
    loops = [ClosedLoop(s, design=ModelBackend(s.params)) for s in (plain, ov, ov)]
    captures = [lp.capture(0.0) for lp in loops]
    assert np.array_equal(captures[1][1], captures[2][1])  # same seed, same frame
    assert not np.any(captures[1][1] & 0x0F)
    state = loops[1].camera.sensor_state()
    assert state["frames"] == 1 + ov.camera.ov7670.settle_frames
    assert 0 < state["exposure_s"] <= ov.camera.frame_period and 1 <= state["gain"] <= 8
    # The world (people, their random speeds) is the same whichever sensor looks at it.
    for lp in loops:
        lp.advance_physics(240)
    people = [[(p.x, p.y) for p in lp.world.people_states()] for lp in loops]
    assert people[0] == people[1] == people[2]
