"""A camera knocked off its pose (``camera.yaw_offset_deg``) and a drifting exposure
(``camera.exposure_drift``): the pose and the frames against their formulas, seeded, and
today's runs unchanged when they are 0."""

import math

import numpy as np
import pytest

from fpga_robotics.loop.connectors.camera import DRIFT_TAU, CameraConnector, ExposureDrift
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sim.camera.raster import focal_length


def test_the_yaw_offset_turns_the_camera_and_the_pitch_adds_to_the_tilt():
    cam = CameraConnector(
        160, 120, 1.047, mount_height=0.3, mount_forward=0.1, tilt=0.05, yaw_offset=math.radians(10)
    )
    faced = []
    pose = cam.pose((1.0, 2.0, 0.3), lambda heading: faced.append(heading) or 0.02)
    assert pose.heading == pytest.approx(0.3 + math.radians(10))
    assert pose.tilt == pytest.approx(0.07)
    assert faced == [pose.heading]  # the slope's pitch along the way the camera faces
    # The mount stays where it is on the robot: only the direction turns.
    assert (pose.x, pose.y) == pytest.approx((1.0 + 0.1 * math.cos(0.3), 2.0 + 0.1 * math.sin(0.3)))


def test_the_target_column_moves_by_the_pinhole_amount_with_the_yaw_offset():
    # The person stands still straight ahead; a camera turned 8 degrees left sees them
    # f tan(8 deg) pixels right of the centre.
    base = ['camera.resolution="80x60"', "sim.duration=0.2", "design.kp_num=0"]
    plain = run_scenario(load_scenario("approach", base), backend="model")
    turned = run_scenario(
        load_scenario("approach", [*base, "camera.yaw_offset_deg=8"]), backend="model"
    )
    shift = turned.trajectory["target_column"][0] - plain.trajectory["target_column"][0]
    assert shift == pytest.approx(focal_length(80, 1.047) * math.tan(math.radians(8)), rel=1e-6)
    # The design sees the same: its centroid moves right by about as much.
    assert turned.trajectory["centroid_x"][0] - plain.trajectory["centroid_x"][0] == pytest.approx(
        shift, abs=2.5
    )


def test_the_drift_has_its_stated_deviation_and_correlation_time():
    period = 1 / 30
    drift = ExposureDrift(0.2, period, np.random.default_rng(5))
    assert drift.gain() == 1.0  # frame 0 unchanged
    logs = np.log([drift.gain() for _ in range(300_000)])
    assert logs.std() == pytest.approx(0.2, rel=0.06)
    lag = round(DRIFT_TAU / period)
    r = np.corrcoef(logs[:-lag], logs[lag:])[0, 1]
    assert r == pytest.approx(math.exp(-1), abs=0.06)


def test_the_drift_scales_the_frame_and_is_seeded():
    a = ExposureDrift(0.3, 1 / 30, np.random.default_rng(1))
    b = ExposureDrift(0.3, 1 / 30, np.random.default_rng(1))
    frame = np.arange(256, dtype=np.uint8).reshape(16, 16, 1).repeat(3, axis=2)
    np.testing.assert_array_equal(a.apply(frame), frame)  # frame 0
    b.apply(frame)
    out_a, out_b = a.apply(frame), b.apply(frame)
    np.testing.assert_array_equal(out_a, out_b)
    g = math.exp(a.log_gain)
    want = np.clip(np.floor(frame.astype(np.float64) * g + 0.5), 0, 255)
    assert np.abs(out_a.astype(int) - want).max() <= 1


def test_zero_drift_and_offset_leave_runs_unchanged():
    base = ['camera.resolution="80x60"', "sim.duration=1"]
    a = run_scenario(load_scenario("follow_person", base), backend="model")
    b = run_scenario(
        load_scenario(
            "follow_person", [*base, "camera.exposure_drift=0", "camera.yaw_offset_deg=0"]
        ),
        backend="model",
    )
    for key in a.trajectory:
        np.testing.assert_array_equal(a.trajectory[key], b.trajectory[key], err_msg=key)
    drifting = run_scenario(
        load_scenario("follow_person", [*base, "camera.exposure_drift=0.5"]), backend="model"
    )
    again = run_scenario(
        load_scenario("follow_person", [*base, "camera.exposure_drift=0.5"]), backend="model"
    )
    np.testing.assert_array_equal(drifting.trajectory["x"], again.trajectory["x"])


@pytest.mark.parametrize(
    "item, message",
    [
        ("camera.yaw_offset_deg=60", "camera.yaw_offset_deg"),
        ("camera.exposure_drift=-0.1", "camera.exposure_drift"),
    ],
)
def test_bad_values_are_one_line_errors(item, message):
    with pytest.raises(ScenarioError, match=message) as info:
        load_scenario("follow_person", [item])
    assert "\n" not in str(info.value)
