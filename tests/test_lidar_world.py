"""The LIDAR's physics by hand: each sample's angle and start flag, the distances to walls,
furniture and people at known poses, dark and glancing surfaces, and its seeded noise."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.lidar import LidarParams, Scan, cast, sample_angles

EXACT = LidarParams(noise_frac=0.0, dark_return=0.0)


def _world(**room):
    """A 4 x 2 m room, nobody in it, the robot out of the way."""
    return World.from_config(
        {
            "room": {"width": 4.0, "depth": 2.0, **room},
            "robot": {"model": "gopigo3", "start": [0.3, 0.3]},
            "people": [],
        }
    )


def test_sample_angles_and_start_flags():
    # 5.5 rev/s at 2000 samples/s: 360 * 5.5 / 2000 = 0.99 degrees = 63.36 q6 a sample.
    q6, exact, start = sample_angles(LidarParams(), 0, 1100)
    assert q6[:4].tolist() == [0, 63, 126, 190]  # floor(63.36 i)
    assert exact[1] == pytest.approx(0.99) and exact[100] == pytest.approx(99.0)
    # Revolution k starts at the first i with 63.36 i >= 23040 k: 363.6.. -> 364, 727.2.. ->
    # 728, 1090.9.. -> 1091.
    assert np.flatnonzero(start).tolist() == [0, 364, 728, 1091]
    assert q6[364] == math.floor(364 * 63.36) - 23040  # 23063 - 23040 = 23
    assert q6[363] == math.floor(363 * 63.36)  # 22999: 359.4 degrees


def test_walls_at_known_poses():
    world = _world()
    # From (1, 1) facing +x: ahead the wall x = 4 (3 m), clockwise 90 degrees the wall y = 0
    # (1 m), behind x = 0 (1 m), at 270 degrees y = 2 (1 m).
    angles = np.radians([0.0, 90.0, 180.0, 270.0])
    dist, cos_inc, _ = cast(world, 1.0, 1.0, 0.0 - angles, 0.2)
    assert dist == pytest.approx([3.0, 1.0, 1.0, 1.0])
    assert cos_inc == pytest.approx([1.0, 1.0, 1.0, 1.0])
    # 45 degrees clockwise: down to y = 0 at x = 2, sqrt(2) m away, met at 45 degrees.
    dist, cos_inc, _ = cast(world, 1.0, 1.0, [-math.pi / 4], 0.2)
    assert dist[0] == pytest.approx(math.sqrt(2)) and cos_inc[0] == pytest.approx(math.sqrt(0.5))
    # Facing +y (heading 90 degrees), 90 degrees clockwise points to +x: 3 m.
    dist, _, _ = cast(world, 1.0, 1.0, [math.pi / 2 - math.pi / 2], 0.2)
    assert dist[0] == pytest.approx(3.0)


def test_samples_from_a_pose_hit_the_walls():
    world = _world()
    samples = Scan(EXACT, np.random.default_rng(0)).samples(world, 0, 364, 1.0, 1.0, 0.0, 0.2)
    by_index = {s.index: s for s in samples}
    # Sample 0 (0 degrees): the wall x = 4, 3000 mm = 12000 q2.
    assert by_index[0].distance_q2 == 12000 and by_index[0].start and by_index[0].quality == 15
    # Sample 100 (99 degrees clockwise, 9 degrees past "right"): wall y = 0, 1 / cos(9 deg).
    assert by_index[100].distance_m == pytest.approx(1.0 / math.cos(math.radians(9)), abs=3e-4)
    # Sample 200 (198 degrees: 18 past behind, to the left): wall x = 0 at 1 / cos(18 deg).
    assert by_index[200].distance_m == pytest.approx(1.0 / math.cos(math.radians(18)), abs=3e-4)


def test_furniture_under_the_plane_is_not_seen_people_are():
    box = {"name": "box", "type": "box", "center": [2.0, 1.0], "size": [0.2, 0.2], "height": 0.1}
    world = World.from_config(
        {
            "room": {"width": 4.0, "depth": 2.0, "furniture": [box]},
            "robot": {"model": "gopigo3", "start": [0.3, 0.3]},
            "people": [{"name": "p", "waypoints": [[1.0, 1.6]], "radius": 0.2}],
        }
    )
    # The box's near side is at x = 1.9: 0.9 m ahead at the plane 0.05 m, under it at 0.2 m.
    assert cast(world, 1.0, 1.0, [0.0], 0.05)[0][0] == pytest.approx(0.9)
    assert cast(world, 1.0, 1.0, [0.0], 0.2)[0][0] == pytest.approx(3.0)
    # The person at (1, 1.6), radius 0.2, 270 degrees clockwise (+y): 0.6 - 0.2 = 0.4 m.
    assert tuple(world.people[0].body.position) == pytest.approx((1.0, 1.6))
    assert cast(world, 1.0, 1.0, [math.pi / 2], 0.2)[0][0] == pytest.approx(0.4)


def test_dark_and_glancing_surfaces_drop_out():
    dark = _world(wall_color=[0.04, 0.04, 0.04])
    scan = Scan(LidarParams(noise_frac=0.0), np.random.default_rng(1))
    samples = scan.samples(dark, 0, 364, 1.0, 1.0, 0.0, 0.2)
    # Luminance 0.04 < dark_return 0.06: no return anywhere: distance 0 and quality 0.
    assert all(s.distance_q2 == 0 and s.quality == 0 for s in samples)
    bright = _world()
    samples = scan.samples(bright, 0, 364, 1.0, 1.0, 0.0, 0.2)
    # Bright walls (luminance 0.78): a ray returns unless it meets the wall more than 80
    # degrees off its normal or the signal 0.78 cos(i) falls under 2 x 0.06 (i > 81 deg).
    for s in samples:
        a = math.radians(s.index * 0.99 % 360)  # exact; angle_q6 is rounded down
        d = np.array([math.cos(-a), math.sin(-a)])
        # The wall the ray meets: its normal is along x or y, whichever the hit is on.
        t = [
            (4.0 - 1.0) / d[0] if d[0] > 1e-12 else math.inf,
            (0.0 - 1.0) / d[0] if d[0] < -1e-12 else math.inf,
            (2.0 - 1.0) / d[1] if d[1] > 1e-12 else math.inf,
            (0.0 - 1.0) / d[1] if d[1] < -1e-12 else math.inf,
        ]
        k = int(np.argmin(t))
        cos_i = abs(d[0]) if k < 2 else abs(d[1])
        if cos_i < math.cos(math.radians(80)):
            assert s.distance_q2 == 0
        else:
            assert s.distance_m == pytest.approx(t[k], abs=3e-4)


def test_seeded_noise_is_one_percent_and_repeats():
    world = _world()
    params = LidarParams(dark_return=0.0)
    a = Scan(params, np.random.default_rng(5)).samples(world, 0, 2000, 1.0, 1.0, 0.0, 0.2)
    b = Scan(params, np.random.default_rng(5)).samples(world, 0, 2000, 1.0, 1.0, 0.0, 0.2)
    assert a == b
    # The wall x = 4 is 3 m ahead: a sample at a small angle a sees it 3 / cos(a) away.
    rel = np.array(
        [
            s.distance_m / (3.0 / math.cos(math.radians(s.index * 0.99 % 360))) - 1.0
            for s in a
            if 0.5 < s.angle_deg < 15.0
        ]
    )
    assert len(rel) > 50
    assert 0.007 < rel.std() < 0.013 and abs(rel.mean()) < 0.004
