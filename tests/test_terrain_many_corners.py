"""A terrain patch of thousands of corners (a round carpet traced from a floor plan) loads,
builds its lookup grid and draws in seconds, with the same answers as the point-by-point
rules: ``polygon_contains`` for the even-odd fill, every pair of edges for a crossing."""

import math
import time

import numpy as np
import pytest

from fpga_robotics.sim.camera import floor_patches
from fpga_robotics.sim.camera.floor_patches import patch_index
from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.config import WorldConfigError, _crossing_edges
from fpga_robotics.sim.world.terrain import polygon_contains


def _star(rng, n, cx, cy, r_min, r_max):
    """A simple polygon: ``n`` corners at increasing angles, random radii."""
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    radii = rng.uniform(r_min, r_max, n)
    return [(cx + r * math.cos(a), cy + r * math.sin(a)) for a, r in zip(angles, radii)]


def _first_crossing(polygon):
    """Every pair of non-neighbouring edges, in order: the first that cross strictly."""

    def side(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    n = len(polygon)
    for i in range(n):
        a, b = polygon[i], polygon[(i + 1) % n]
        for j in range(i + 2, n - 1 if i == 0 else n):
            c, d = polygon[j], polygon[(j + 1) % n]
            if side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0:
                return i, j
    return None


@pytest.mark.parametrize("banded_from", [1, floor_patches.BANDED_FROM, 10**9])
def test_patch_index_is_the_even_odd_rule_of_each_point(banded_from, monkeypatch):
    """Both ways of testing the points, every point against every edge and the sorted
    slices level with each edge, and the default's choice between them (40 and 7 corners
    below it, 100 above)."""
    monkeypatch.setattr(floor_patches, "BANDED_FROM", banded_from)
    rng = np.random.default_rng(3)
    polygons = [
        _star(rng, 40, 4, 3, 0.5, 2.5),
        _star(rng, 7, 5, 3, 0.2, 1.5),
        _star(rng, 100, 2, 4, 0.3, 1.2),
    ]
    x, y = rng.uniform(0, 8, 3000), rng.uniform(0, 6, 3000)
    got = patch_index(polygons, x.reshape(60, 50), y.reshape(60, 50)).ravel()
    for px, py, k in zip(x, y, got):
        inside = [i for i, poly in enumerate(polygons) if polygon_contains(poly, px, py)]
        assert k == (inside[-1] if inside else -1)  # the last polygon that holds it
    assert (got == 0).sum() > 100 and (got == 1).sum() > 100 and (got == 2).sum() > 100


@pytest.mark.parametrize("seed", range(6))
def test_the_first_crossing_is_that_of_every_pair_of_edges(seed):
    rng = np.random.default_rng(seed)
    simple = _star(rng, 60, 4, 3, 1.0, 2.0)
    tangled = simple[:]
    i, j = sorted(rng.choice(60, 2, replace=False))
    tangled[i], tangled[j] = tangled[j], tangled[i]  # two corners swapped: edges cross
    assert _crossing_edges(simple) is None
    assert _first_crossing(tangled) is not None
    assert _crossing_edges(tangled) == _first_crossing(tangled)


def _round_carpet(n):
    points = [
        [50 + 40 * math.cos(2 * math.pi * i / n), 50 + 40 * math.sin(2 * math.pi * i / n)]
        for i in range(n)
    ]
    return {
        "room": {
            "width": 100,
            "depth": 100,
            "terrain": [{"name": "round", "points": points, "friction": 0.5}],
        },
        "robot": {"start": [50, 50]},
        "people": [],
    }


def test_a_round_carpet_of_5000_corners_builds_in_seconds():
    # Before: 24 s of CPU time to check its edges for a crossing and 23 s to build the
    # lookup grid (every grid corner against every edge); now about 1 s each.
    start = time.process_time()
    world = World.from_config(_round_carpet(5000), seed=0)
    assert time.process_time() - start < 12.0
    assert world.terrain.at(50, 50).name == "round"
    assert world.terrain.at(50 + 39.9, 50) is not None
    assert world.terrain.at(50 + 40.1, 50) is None
    assert world.terrain.at(95, 95) is None


def test_a_crossing_among_thousands_of_corners_is_named():
    config = _round_carpet(3000)
    points = config["room"]["terrain"][0]["points"]
    points[1000], points[2000] = points[2000], points[1000]
    with pytest.raises(WorldConfigError, match=r"points cross themselves: the edge points\[999\]"):
        World.from_config(config, seed=0)
