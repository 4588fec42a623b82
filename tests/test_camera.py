"""SimCamera renderer: pinhole geometry, occlusion, lighting and noise against hand-computed
expectations and an independent per-pixel ray caster."""

import math
import subprocess
import sys

import numpy as np
import pytest

from fpga_robotics.sim.camera.frames import to_rgb444, unpack_rgb444
from fpga_robotics.sim.camera.raster import CameraRenderer, render
from fpga_robotics.sim.camera.scene import Band, CameraPose, Cylinder, Lighting, Scene, Wall

HFOV = 1.047
FLAT = Lighting(ambient=1.0, intensity=0.0)  # colours come out as 255 * albedo
RED, GREEN, BLUE = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
GREY = (0.5, 0.5, 0.5)


def focal(width, hfov=HFOV):
    return (width / 2) / math.tan(hfov / 2)


def scene_of(walls=(), cylinders=(), lighting=FLAT, **kw):
    kw.setdefault("floor_color", GREY)
    kw.setdefault("ceiling_color", (0.6, 0.6, 0.6))
    return Scene(walls=tuple(walls), cylinders=tuple(cylinders), lighting=lighting, **kw)


def pillar(x, y, radius=0.2, color=RED, z0=0.0, z1=2.0):
    return Cylinder(x, y, radius, (Band(z0, z1, color),))


def to8(value):
    """A linear value in 0..1 as the renderer's 8-bit output (rounded half up)."""
    return math.floor(value * 255 + 0.5)


def is_color(img, rgb):
    return np.all(img.astype(int) == [to8(c) for c in rgb], axis=-1)


def box(x0, y0, x1, y1, height, color):
    return [
        Wall(x0, y0, x1, y0, height, color),
        Wall(x1, y0, x1, y1, height, color),
        Wall(x1, y1, x0, y1, height, color),
        Wall(x0, y1, x0, y0, height, color),
    ]


# -- an independent reference: one exact 3-D pinhole ray per pixel -----------------------------


def reference_render(scene, pose, width, height, hfov=HFOV):
    """Slow per-pixel ray caster (tilt 0): nearest of walls, cylinder fronts, floor, ceiling."""
    f = focal(width, hfov)
    u = np.arange(width) + 0.5 - width / 2  # right
    v = height / 2 - (np.arange(height) + 0.5)  # up
    U, V = np.meshgrid(u, v)
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    dx = f * c + U * s  # forward * f + right * u, right = (sin, -cos)
    dy = f * s - U * c
    dz = V
    lt = scene.lighting
    d = np.asarray(lt.direction, float)
    d = d / np.linalg.norm(d)
    best = np.full(U.shape, np.inf)
    color = np.zeros(U.shape + (3,))

    def offer(t, rgb):
        nonlocal best
        better = t < best
        best = np.where(better, t, best)
        color[better] = rgb[better] if np.ndim(rgb) == 3 else rgb

    with np.errstate(divide="ignore", invalid="ignore"):
        h = pose.height
        t = np.where(dz < 0, -h / dz, np.inf)
        offer(t, np.asarray(scene.floor_color) * (lt.ambient + lt.intensity * max(0, -d[2])))
        t = np.where(dz > 0, (scene.ceiling_height - h) / dz, np.inf)
        offer(t, np.asarray(scene.ceiling_color) * (lt.ambient + lt.intensity * max(0, d[2])))
        for w in scene.walls:
            ex, ey = w.x1 - w.x0, w.y1 - w.y0
            qx, qy = w.x0 - pose.x, w.y0 - pose.y
            den = dx * ey - dy * ex
            t = (qx * ey - qy * ex) / den
            sp = (qx * dy - qy * dx) / den
            z = h + t * dz
            ok = (
                (t > 0)
                & (sp >= 0)
                & (sp <= 1)
                & (z >= 0)
                & (z <= min(w.height, scene.ceiling_height))
            )
            n = np.array([ey, -ex]) / math.hypot(ex, ey)
            if n @ np.array([pose.x - w.x0, pose.y - w.y0]) < 0:
                n = -n
            shade = lt.ambient + lt.intensity * max(0.0, -(n[0] * d[0] + n[1] * d[1]))
            offer(np.where(ok, t, np.inf), np.asarray(w.color) * shade)
        for cyl in scene.cylinders:
            qx, qy = pose.x - cyl.x, pose.y - cyl.y
            a = dx * dx + dy * dy
            b = dx * qx + dy * qy
            cc = qx * qx + qy * qy - cyl.radius**2
            t = (-b - np.sqrt(b * b - a * cc)) / a
            z = h + t * dz
            nx, ny = (qx + t * dx) / cyl.radius, (qy + t * dy) / cyl.radius
            shade = lt.ambient + lt.intensity * np.maximum(0.0, -(nx * d[0] + ny * d[1]))
            for band in cyl.bands:
                ok = (t > 0) & (z >= band.z0) & (z <= band.z1)
                rgb = np.asarray(band.color) * shade[..., None]
                offer(np.where(ok, t, np.inf), rgb)
    return np.clip(color * 255 + 0.5, 0, 255).astype(np.uint8)


def random_scene(seed):
    rng = np.random.default_rng(seed)
    walls = box(0, 0, 8, 6, 2.5, tuple(rng.uniform(0.3, 0.9, 3)))
    for _ in range(3):
        x, y = rng.uniform(1, 7), rng.uniform(1, 5)
        w, d = rng.uniform(0.2, 1.2, 2)
        walls += box(x, y, x + w, y + d, rng.uniform(0.5, 2.0), tuple(rng.uniform(0, 1, 3)))
    people = []
    for _ in range(3):
        bands = (
            Band(0.0, 0.8, tuple(rng.uniform(0, 1, 3))),
            Band(0.8, 1.4, tuple(rng.uniform(0, 1, 3))),
            Band(1.5, 1.7, tuple(rng.uniform(0, 1, 3))),
        )
        people.append(Cylinder(rng.uniform(1, 7), rng.uniform(1, 5), 0.2, bands))
    lighting = Lighting(0.5, 0.5, (rng.uniform(-1, 1), rng.uniform(-1, 1), -1.0))
    pose = CameraPose(rng.uniform(0.5, 7.5), rng.uniform(0.5, 5.5), rng.uniform(-math.pi, math.pi))
    return scene_of(walls, people, lighting), pose


def mismatch_fraction(a, b):
    return float(np.mean(np.any(np.abs(a.astype(int) - b.astype(int)) > 1, axis=-1)))


@pytest.mark.parametrize("seed", range(4))
def test_matches_per_pixel_reference(seed):
    scene, pose = random_scene(seed)
    got = CameraRenderer(64, 48, max_layers=32).render(scene, pose)
    # A pixel centre exactly on an edge may fall either way; nothing else may differ.
    assert mismatch_fraction(got, reference_render(scene, pose, 64, 48)) < 0.002


def test_default_layer_budget_matches_reference_on_a_typical_room():
    scene, pose = random_scene(7)
    got = render(scene, pose, 80, 60)
    assert mismatch_fraction(got, reference_render(scene, pose, 80, 60)) < 0.005


def stepped_boxes():
    """Four boxes in a row, each taller than the one before, then the back wall: 9 hits in
    the middle columns, 5 of them visible (the boxes' far sides are hidden)."""
    walls = [Wall(9.0, -9, 9.0, 9, 2.5, GREEN)]
    for i, height in enumerate((0.4, 0.8, 1.2, 1.6)):
        x = 2.0 + 1.5 * i
        walls += box(x, -1.0, x + 0.5, 1.0, height, (0.2 * i + 0.2, 0.3, 0.8 - 0.15 * i))
    return scene_of(walls, ceiling_height=2.5), CameraPose(0.0, 0.0, 0.0, height=0.3)


def test_hidden_far_sides_do_not_use_up_the_layer_budget():
    scene, pose = stepped_boxes()
    ref = reference_render(scene, pose, 64, 48)
    assert mismatch_fraction(CameraRenderer(64, 48, max_layers=5).render(scene, pose), ref) == 0
    # With fewer layers than visible surfaces the farthest ones are lost (floor/ceiling).
    assert mismatch_fraction(CameraRenderer(64, 48, max_layers=3).render(scene, pose), ref) > 0.01


# -- output ----------------------------------------------------------------------------------


@pytest.mark.parametrize("size", [(16, 12), (33, 17), (160, 120)])
def test_shape_dtype_and_function_matches_class(size):
    w, h = size
    scene = scene_of(box(-3, -3, 3, 3, 2.5, GREEN), [pillar(1.5, 0.0)])
    pose = CameraPose(0.0, 0.0, 0.0)
    img = render(scene, pose, w, h)
    assert img.shape == (h, w, 3) and img.dtype == np.uint8 and img.flags.c_contiguous
    np.testing.assert_array_equal(img, CameraRenderer(w, h).render(scene, pose))


def test_empty_scene_is_ceiling_above_floor_below():
    img = render(scene_of(), CameraPose(0, 0, 0.3), 40, 30)
    assert is_color(img[:15], (0.6, 0.6, 0.6)).all()
    assert is_color(img[15:], GREY).all()


# -- pinhole geometry ------------------------------------------------------------------------


@pytest.mark.parametrize("heading", [0.0, 1.0, -2.5])
def test_cylinder_straight_ahead_is_centred_and_shrinks_like_a_pinhole(heading):
    w, h, r = 160, 120, 0.25
    f = focal(w)
    widths = []
    for dist in (1.0, 2.0, 4.0, 8.0):
        cx, cy = 10 + dist * math.cos(heading), 5 + dist * math.sin(heading)
        img = render(scene_of(cylinders=[pillar(cx, cy, r)]), CameraPose(10, 5, heading), w, h)
        red = is_color(img, RED)
        cols = np.nonzero(red[h // 2])[0]
        # Symmetric about the optical axis x = W/2, i.e. column index W/2 - 0.5 on average.
        assert abs(cols.mean() + 0.5 - w / 2) <= 1.0
        assert abs(np.nonzero(red)[1].mean() + 0.5 - w / 2) <= 1.0
        # Tangent rays at +-asin(r/d); the image half-width is f * tan of that.
        expected = 2 * f * math.tan(math.asin(r / dist))
        assert abs(len(cols) - expected) <= 2.0, (dist, len(cols), expected)
        assert np.all(np.diff(cols) == 1)  # one solid run
        widths.append(len(cols))
    assert widths == sorted(widths, reverse=True)


def test_cylinder_to_the_left_appears_left_where_the_pinhole_puts_it():
    w, h = 160, 120
    f = focal(w)
    angle = 0.3  # left of the heading (counter-clockwise)
    img = render(
        scene_of(cylinders=[pillar(3 * math.cos(angle), 3 * math.sin(angle), 0.1)]),
        CameraPose(0, 0, 0),
        w,
        h,
    )
    cols = np.nonzero(is_color(img, RED)[h // 2])[0]
    assert cols.mean() + 0.5 == pytest.approx(w / 2 - f * math.tan(angle), abs=1.0)
    assert cols.max() < w / 2


def test_turning_left_moves_the_world_right_in_the_image():
    w, h = 160, 120
    f = focal(w)
    scene = scene_of(cylinders=[pillar(3.0, 0.0, 0.1)])
    for turn in (0.2, -0.35):
        img = render(scene, CameraPose(0, 0, turn), w, h)
        cols = np.nonzero(is_color(img, RED)[h // 2])[0]
        # The object is now at -turn from the heading: image x = W/2 + f * tan(turn).
        assert cols.mean() + 0.5 == pytest.approx(w / 2 + f * math.tan(turn), abs=1.0)
        assert (cols.mean() > w / 2) == (turn > 0)


def first_row(mask_column):
    rows = np.nonzero(mask_column)[0]
    return rows.min(), rows.max()


@pytest.mark.parametrize("dist,wall_h,cam_h", [(3.0, 1.2, 0.3), (5.0, 2.0, 0.5), (2.0, 0.2, 0.3)])
def test_wall_edges_follow_the_pinhole_formula_in_every_column(dist, wall_h, cam_h):
    w, h = 160, 120
    f = focal(w)
    scene = scene_of([Wall(dist, -20, dist, 20, wall_h, GREEN)])
    img = render(scene, CameraPose(0, 0, 0, height=cam_h), w, h)
    green = is_color(img, GREEN)
    # Edge at image y = H/2 - f*(z - h)/d; the first row whose centre lies past it is drawn.
    top = math.ceil(h / 2 - f * (wall_h - cam_h) / dist - 0.5)
    bottom = math.ceil(h / 2 + f * cam_h / dist - 0.5) - 1
    for col in (0, 40, 80, 159):  # a straight wall stays a straight edge (no fisheye)
        assert first_row(green[:, col]) == (max(top, 0), min(bottom, h - 1))


@pytest.mark.parametrize("tilt", [0.15, -0.2])
def test_tilt_moves_horizon_and_edges(tilt):
    w, h = 160, 120
    f = focal(w)
    img = render(scene_of(), CameraPose(0, 0, 0, tilt=tilt), w, h)
    floor = is_color(img[:, w // 2], GREY)
    # The horizon (elevation 0) sits at y = H/2 + f * tan(tilt).
    assert np.nonzero(floor)[0].min() == math.ceil(h / 2 + f * math.tan(tilt) - 0.5)
    dist, wall_h, cam_h = 4.0, 1.0, 0.3
    img = render(
        scene_of([Wall(dist, -9, dist, 9, wall_h, GREEN)]), CameraPose(0, 0, 0, cam_h, tilt), w, h
    )
    y_top = h / 2 - f * math.tan(math.atan((wall_h - cam_h) / dist) - tilt)
    y_bottom = h / 2 - f * math.tan(math.atan(-cam_h / dist) - tilt)
    top, bottom = first_row(is_color(img[:, w // 2], GREEN))
    assert top == math.ceil(y_top - 0.5) and bottom == math.ceil(y_bottom - 0.5) - 1


# -- occlusion -------------------------------------------------------------------------------


def test_person_hides_the_wall_and_the_wall_shows_above_the_head():
    w, h = 160, 120
    f = focal(w)
    cam_h, d_person, d_wall = 0.3, 3.0, 6.0
    person = Cylinder(
        d_person,
        0.0,
        0.2,
        (
            Band(0.0, 0.5, BLUE),
            Band(0.55, 0.9, RED),  # a gap 0.5..0.55 shows what is behind
            Band(0.9, 1.0, (1.0, 1.0, 0.0)),
        ),
    )
    scene = scene_of([Wall(d_wall, -9, d_wall, 9, 2.5, GREEN)], [person], ceiling_height=2.5)
    img = render(scene, CameraPose(0, 0, 0, cam_h), w, h)
    col = img[:, w // 2]
    near = d_person - 0.2  # the front of the cylinder in the centre column
    head_top = math.ceil(h / 2 - f * (1.0 - cam_h) / near - 0.5)
    wall_top = math.ceil(h / 2 - f * (2.5 - cam_h) / d_wall - 0.5)
    green_rows = np.nonzero(is_color(col, GREEN))[0]
    # Above the head: the wall, from its top edge down to the head.
    assert set(range(max(wall_top, 0), head_top)) <= set(green_rows)
    # In front of the person the wall is hidden, except through the gap between the bands.
    gap = range(
        math.ceil(h / 2 - f * (0.55 - cam_h) / near - 0.5),
        math.ceil(h / 2 - f * (0.5 - cam_h) / near - 0.5),
    )
    assert len(gap) >= 1
    assert set(green_rows) - set(range(max(wall_top, 0), head_top)) == set(gap)
    assert is_color(col[head_top], (1.0, 1.0, 0.0))
    # Beside the person the wall is seen all the way down to the floor.
    side = is_color(img[:, 5], GREEN)
    assert side[head_top : h // 2 + 1].all()


def test_low_divider_in_front_of_the_back_wall():
    w, h = 120, 90
    f = focal(w)
    cam_h, d_div, d_wall = 0.3, 3.0, 7.0
    wood = (0.55, 0.27, 0.15)
    walls = [Wall(d_wall, -9, d_wall, 9, 2.5, GREEN)] + box(d_div, -1, d_div + 0.1, 1, 1.2, wood)
    img = render(scene_of(walls), CameraPose(0, 0, 0, cam_h), w, h)
    col = img[:, w // 2]
    div_top = math.ceil(h / 2 - f * (1.2 - cam_h) / d_div - 0.5)
    div_bottom = math.ceil(h / 2 + f * cam_h / d_div - 0.5) - 1
    wall_top = math.ceil(h / 2 - f * (2.5 - cam_h) / d_wall - 0.5)
    assert first_row(is_color(col, wood)) == (div_top, div_bottom)
    assert first_row(is_color(col, GREEN)) == (wall_top, div_top - 1)
    assert is_color(col[div_bottom + 1 :], GREY).all()  # then the floor
    assert is_color(col[:wall_top], (0.6, 0.6, 0.6)).all()  # and the ceiling above


def test_walls_taller_than_the_ceiling_are_cut_by_it():
    w, h = 80, 60
    img = render(
        scene_of([Wall(2.0, -9, 2.0, 9, 5.0, GREEN)], ceiling_height=1.0),
        CameraPose(0, 0, 0, 0.3),
        w,
        h,
    )
    top = math.ceil(h / 2 - focal(w) * (1.0 - 0.3) / 2.0 - 0.5)
    assert first_row(is_color(img[:, w // 2], GREEN))[0] == top
    assert is_color(img[:top, w // 2], (0.6, 0.6, 0.6)).all()


def test_objects_behind_the_camera_are_not_drawn():
    img = render(scene_of(cylinders=[pillar(-2.0, 0.0)]), CameraPose(0, 0, 0), 80, 60)
    assert not is_color(img, RED).any()


# -- lighting --------------------------------------------------------------------------------


def test_doubling_ambient_without_direct_light_doubles_every_pixel():
    scene, pose = random_scene(3)
    dim = Scene(
        scene.walls,
        scene.cylinders,
        (0.5, 0.4, 0.3),
        (0.7, 0.6, 0.5),
        2.5,
        Lighting(ambient=0.5, intensity=0.0),
    )
    bright = Scene(
        dim.walls,
        dim.cylinders,
        dim.floor_color,
        dim.ceiling_color,
        2.5,
        Lighting(ambient=1.0, intensity=0.0),
    )
    a = render(dim, pose, 80, 60).astype(int)
    b = render(bright, pose, 80, 60).astype(int)
    assert np.abs(b - 2 * a).max() <= 1  # rounding of each image only
    assert a.max() > 20


def test_surface_facing_the_light_is_brighter_by_the_lambert_term():
    albedo = (0.6, 0.5, 0.4)
    light = Lighting(ambient=0.4, intensity=0.5, direction=(1.0, 0.0, 0.0))  # towards +x
    scene = scene_of([Wall(3.0, -9, 3.0, 9, 2.5, albedo)], lighting=light)
    w, h = 80, 60
    # From x=0 the visible face looks towards -x, into the light: fully lit.
    lit = render(scene, CameraPose(0, 0, 0), w, h)[h // 2, w // 2]
    # From x=6, looking back, the face looks along +x, away from the light: ambient only.
    dark = render(scene, CameraPose(6, 0, math.pi), w, h)[h // 2, w // 2]
    np.testing.assert_allclose(lit, np.round(np.multiply(albedo, 0.9) * 255), atol=1)
    np.testing.assert_allclose(dark, np.round(np.multiply(albedo, 0.4) * 255), atol=1)


def test_cylinder_shading_follows_its_normal():
    light = Lighting(ambient=0.3, intensity=0.6, direction=(0.0, -1.0, 0.0))  # travels -y
    w, h = 160, 120
    img = render(
        scene_of(cylinders=[pillar(2.0, 0.0, 0.4, (1.0, 1.0, 1.0))], lighting=light),
        CameraPose(0, 0, 0),
        w,
        h,
    ).astype(int)
    row = img[h // 2 + 5]
    cols = np.nonzero(row[:, 1] > 0.25 * 255)[0]
    cols = cols[(cols > 20) & (cols < 140)]  # the cylinder's silhouette
    values = row[cols, 0]
    # Normals turn from +y (image left, facing the light) to -y (right, facing away).
    assert np.all(np.diff(values) <= 1)
    assert values[0] > values[-1] + 60
    assert values[-1] == to8(0.3)  # the right side gets ambient only
    # Floor (normal +z) with light travelling horizontally: ambient only.
    assert tuple(img[-1, 0]) == (to8(0.5 * 0.3),) * 3


def test_red_shirt_of_the_default_person_passes_the_red_filter():
    """The world's default person under the default lighting, seen from every side."""
    from fpga_robotics.sim.world import World

    world = World.from_config({}, seed=0)
    scene = world.scene()
    (person,) = scene.cylinders
    shirt = next(b for b in person.bands if b.color == (0.85, 0.1, 0.1))
    assert scene.lighting == Lighting()  # ambient 0.6, intensity 0.5
    w, h = 160, 120
    f = focal(w)
    renderer = CameraRenderer(w, h)
    for k, angle in enumerate(np.linspace(0, 2 * math.pi, 8, endpoint=False)):
        dist = 3.0
        pose = CameraPose(
            person.x + dist * math.cos(angle),
            person.y + dist * math.sin(angle),
            angle + math.pi,
            height=0.3,
        )
        noise = {"noise_std": 2.0, "rng": np.random.default_rng(k)} if k % 2 else {}
        r, g, b = unpack_rgb444(to_rgb444(renderer.render(scene, pose, **noise), w, h))
        red = (r - np.maximum(g, b)) >= 6  # docs/contract.md colour filter, color_sel red, D = 6
        near = dist - person.radius
        rows = slice(
            math.ceil(h / 2 - f * (shirt.z1 - 0.3) / near) + 1,
            math.ceil(h / 2 - f * (shirt.z0 - 0.3) / near) - 1,
        )
        half = f * math.tan(math.asin(person.radius / dist))
        cols = slice(math.ceil(w / 2 - 0.9 * half), math.floor(w / 2 + 0.9 * half))
        assert red[rows, cols].all(), f"shirt not red seen from angle {angle:.2f}"
        # Nothing else in the default room (walls, floor, trousers, skin) passes.
        outside = np.ones_like(red)
        outside[rows.start - 2 : rows.stop + 2, cols.start - 2 : cols.stop + 2] = False
        assert not red[outside].any()


def test_red_filter_of_the_golden_model_agrees():
    model = pytest.importorskip("fpga_robotics.sim.models.follow_target")
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.hw.pixel import COLOR_SELECT
    from fpga_robotics.sim.world import World

    world = World.from_config({}, seed=0)
    scene = world.scene()
    (person,) = scene.cylinders
    # Look at the target from 2.4 m, from the robot's side of it.
    rx, ry, _ = world.robot_pose()
    away = math.atan2(ry - person.y, rx - person.x)
    pose = CameraPose(
        person.x + 2.4 * math.cos(away), person.y + 2.4 * math.sin(away), away + math.pi
    )
    img = render(scene, pose, 160, 120)
    match = model.color_match(to_rgb444(img, 160, 120), COLOR_SELECT["red"], FollowTargetParams())
    r, g, b = unpack_rgb444(to_rgb444(img, 160, 120))
    mine = r - np.maximum(g, b) >= 6
    np.testing.assert_array_equal(match, mine)
    cols = np.nonzero(match)[1]
    assert match.sum() > 200  # the shirt, centred
    assert abs(cols.mean() + 0.5 - 80) <= 1.0


# -- noise -----------------------------------------------------------------------------------


def test_noise_is_seeded_zero_mean_with_the_requested_spread():
    scene, pose = random_scene(1)
    r = CameraRenderer(160, 120)
    clean = r.render(scene, pose).astype(int)
    a = r.render(scene, pose, noise_std=4.0, rng=np.random.default_rng(11))
    b = r.render(scene, pose, noise_std=4.0, rng=np.random.default_rng(11))
    c = r.render(scene, pose, noise_std=4.0, rng=np.random.default_rng(12))
    np.testing.assert_array_equal(a, b)
    assert (a != c).mean() > 0.5
    d = a.astype(int) - clean
    assert abs(d.mean()) < 0.1
    assert d.std() == pytest.approx(4.0, rel=0.05)
    for ch in range(3):  # every channel gets noise
        assert d[..., ch].std() == pytest.approx(4.0, rel=0.1)
    # Successive frames from one generator differ (fresh noise every frame).
    g = np.random.default_rng(5)
    assert (r.render(scene, pose, noise_std=4.0, rng=g) != r.render(scene, pose, 4.0, g)).any()


def test_noise_saturates_instead_of_wrapping():
    white = scene_of(floor_color=(1.2, 1.2, 1.2), ceiling_color=(0.0, 0.0, 0.0))
    img = render(white, CameraPose(0, 0, 0), 64, 48, noise_std=8.0, rng=np.random.default_rng(0))
    assert img[24:].min() > 200 and img[24:].max() == 255  # floor: 255 minus |noise|
    assert img[:24].max() < 60 and img[:24].min() == 0  # ceiling: 0 plus noise


# -- errors ----------------------------------------------------------------------------------


def test_noise_without_a_generator_is_refused():
    with pytest.raises(TypeError, match="rng"):
        render(scene_of(), CameraPose(0, 0, 0), 16, 12, noise_std=1.0)


@pytest.mark.parametrize(
    "args,match",
    [
        ((0, 10), "width"),
        ((10, -1), "height"),
        ((10, 10, 0.0), "hfov"),
        ((10, 10, 3.2), "hfov"),
    ],
)
def test_bad_renderer_arguments(args, match):
    with pytest.raises(ValueError, match=match):
        CameraRenderer(*args)


@pytest.mark.parametrize(
    "args,match",
    [
        ((10.0, 10), "width must be an int"),
        ((10, True), "height must be an int"),
    ],
)
def test_renderer_sizes_must_be_integers(args, match):
    with pytest.raises(TypeError, match=match):
        CameraRenderer(*args)
    assert CameraRenderer(np.int64(16), np.int32(12)).width == 16  # numpy integers are fine


def test_tilt_and_field_of_view_limits_by_hand():
    from fpga_robotics.sim.camera.raster import VERTICAL_MARGIN, max_hfov, max_tilt, vertical_fov

    # A square image sees as far vertically as horizontally.
    assert vertical_fov(100, 100, math.pi / 2) == pytest.approx(math.pi / 2)
    assert max_tilt(100, 100, math.pi / 2) == pytest.approx(math.pi / 4 - VERTICAL_MARGIN)
    assert max_hfov(100, 100) == pytest.approx(math.pi - 2 * VERTICAL_MARGIN)
    # 160x120 at the published hfov: f = 80 / tan(0.5235) = 138.6 px, vfov = 2 atan(60 / f).
    f = 80 / math.tan(1.047 / 2)
    assert vertical_fov(160, 120, 1.047) == pytest.approx(2 * math.atan(60 / f))
    assert max_tilt(160, 120, 1.047) == pytest.approx(1.1422, abs=1e-4)
    # A tilt uses up the vertical room: the widest hfov shrinks accordingly.
    assert max_tilt(160, 120, max_hfov(160, 120, 0.5)) == pytest.approx(0.5)


def test_the_package_hands_out_the_names_the_docs_use():
    # docs/camera.md and docs/scenarios.md name these as fpga_robotics.sim.camera.<name>.
    import fpga_robotics.sim.camera as package
    from fpga_robotics.sim.camera import raster, scene

    for name in ("VERTICAL_MARGIN", "max_tilt", "max_hfov", "vertical_fov", "CameraRenderer"):
        assert getattr(package, name) is getattr(raster, name)
    assert package.CameraPose is scene.CameraPose
    assert sorted(package.__all__) == sorted(package._HOMES)
    with pytest.raises(AttributeError, match="no attribute 'NEAR'"):
        package.NEAR  # noqa: B018 - a name of raster the package does not hand out


@pytest.mark.parametrize("w,h,hfov", [(160, 120, 1.047), (32, 24, 2.0), (20, 40, 1.0)])
def test_the_renderer_draws_exactly_up_to_max_tilt(w, h, hfov):
    r = CameraRenderer(w, h, hfov)
    assert r.max_tilt == max_tilt_of(w, h, hfov)
    for tilt in (r.max_tilt, -r.max_tilt):
        assert r.render(scene_of(), CameraPose(0, 0, 0, tilt=tilt)).shape == (h, w, 3)
    beyond = math.nextafter(r.max_tilt, math.inf)
    with pytest.raises(ValueError, match=r"keep \|tilt\| <= "):
        r.render(scene_of(), CameraPose(0, 0, 0, tilt=beyond))


def max_tilt_of(w, h, hfov):
    from fpga_robotics.sim.camera.raster import max_tilt

    return max_tilt(w, h, hfov)


def test_an_hfov_too_wide_for_the_aspect_ratio_is_refused_at_construction():
    # A tall image: the vertical field of view is wider than the horizontal one. The old
    # message asked for |tilt| < -0.019 rad at the first frame.
    with pytest.raises(
        ValueError,
        match=r"at 40x160 gives a vertical field of view of .* "
        r"hfov must be at most 2\.98",
    ):
        CameraRenderer(40, 160, 3.0)
    assert CameraRenderer(40, 160, 2.97).max_tilt > 0
    with pytest.raises(ValueError, match="hfov must be at most 3.11"):
        CameraRenderer(160, 120, 3.1405)


def test_bad_pose_and_scene():
    r = CameraRenderer(32, 24)
    with pytest.raises(ValueError, match="height"):
        r.render(scene_of(), CameraPose(0, 0, 0, height=3.0))
    with pytest.raises(ValueError, match="tilt"):
        r.render(scene_of(), CameraPose(0, 0, 0, tilt=1.4))
    with pytest.raises(ValueError, match="zero length"):
        r.render(scene_of([Wall(1, 1, 1, 1, 1.0, GREEN)]), CameraPose(0, 0, 0))
    with pytest.raises(ValueError, match="colour"):
        r.render(scene_of([Wall(1, 0, 1, 1, 1.0, (1, 0))]), CameraPose(0, 0, 0))
    with pytest.raises(ValueError, match="direction"):
        r.render(scene_of(lighting=Lighting(direction=(0, 0, 0))), CameraPose(0, 0, 0))
    with pytest.raises(TypeError, match="CameraPose"):
        r.render(scene_of(), (0, 0, 0))


# -- benchmark CLI ---------------------------------------------------------------------------


def test_benchmark_cli_prints_a_line_per_size(capsys):
    from fpga_robotics.bench.camera import main
    from fpga_robotics.cli.errors import UsageError

    assert main(["--frames", "2", "--repeats", "1", "--sizes", "32x24,40x30"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert [ln.split()[0] for ln in lines[-2:]] == ["32x24", "40x30"]
    assert all(float(v) > 0 for v in lines[-1].split()[1:])
    with pytest.raises(UsageError, match="WIDTHxHEIGHT"):
        main(["--sizes", "160by120"])
    with pytest.raises(UsageError, match="1..4096"):
        main(["--sizes", "100000x100000"])


@pytest.mark.parametrize(
    "args,message",
    [
        (
            ["--sizes", "160by120"],
            "fpga-robotics bench camera: error: a size is WIDTHxHEIGHT, e.g. 160x120; got '160by120'",
        ),
        (
            ["--frames", "0"],
            "fpga-robotics bench camera: error: --frames must be 1..1000000, got 0",
        ),
        (
            ["--sizes", "160x120,4x1000"],
            (
                "fpga-robotics bench camera: error: a size 4x1000 is too tall for the camera's hfov "
                "1.047 rad: the renderer draws at most 0.3947 rad at that size (the top and bottom "
                "rows would look straight up or down); keep the height at most 86.6 times the width"
            ),
        ),
        (
            ["--noise", "1e300"],
            "fpga-robotics bench camera: error: --noise must be a number of 8-bit levels in 0..64, got 1e+300",
        ),
    ],
)
def test_benchmark_command_line_reports_bad_arguments_in_one_line(args, message):
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.bench", "camera", *args],
        capture_output=True,
        check=False,
        text=True,
    )
    assert (proc.returncode, proc.stdout) == (2, "")
    assert proc.stderr.splitlines() == [message]


def test_non_finite_pose_is_refused():
    with pytest.raises(ValueError, match="finite"):
        render(scene_of(), CameraPose(0, float("nan"), 0), 16, 12)
