"""SimCamera: a forward-looking pinhole camera on the robot, ray cast from a ``Scene`` in numpy.

The world is 2.5-D: vertical walls standing on the floor, upright cylinders (people) made of
coloured bands, a flat floor and a flat ceiling. That lets the renderer cast one ray per image
column instead of one per pixel:

1. For each column, intersect its ray (in the ground plane) with every wall segment and every
   cylinder; a hit's *depth* is its distance along the camera's forward axis.
2. Keep the ``max_layers`` nearest hits per column as its depth layers. When a column has
   more hits than that, hits hidden behind a single nearer one (a box's far side) are
   dropped first, so they do not use up the budget.
3. A hit at depth ``p`` spanning heights ``z0..z1`` covers the rows whose rays pass through
   that height range at that depth: a contiguous run of rows given by the pinhole formula
   ``row = H/2 - 0.5 - f * (z - h) / p`` (tilt aside). Each column therefore splits into a few
   runs of rows, each showing the nearest hit that covers it, or the floor / ceiling.
4. The runs are painted with a cumulative sum down the columns and one palette lookup, so the
   per-pixel work is a handful of whole-image operations whatever the scene. Where a C++
   compiler is present, a compiled pass (``camera_kernel``) paints the runs and adds the
   sensor noise straight into the RGB888 image instead, with the same bytes.

Lighting is Lambertian with ambient (``Scene.lighting``); sensor noise is optional, seeded by
the caller's generator. docs/camera.md has the details and the measured speed.

Conventions: pixel ``(row, col)`` has its centre at ``(col + 0.5, row + 0.5)``; the optical axis
passes through the image centre ``(W/2, H/2)``; the focal length in pixels is
``f = (W/2) / tan(hfov/2)`` for both axes (square pixels). Image right is the camera's right, so
turning the camera left (heading +) moves the world to the right in the image.

Tilt is applied as a rotation of each column's vertical ray fan (``elevation = atan(v/f) +
tilt``): exact at the centre column and with the camera level (tilt 0, the usual case); with
tilt, vertical edges stay vertical instead of converging (no keystone).
"""

import contextlib
import ctypes
import functools
import math
import numbers
import statistics
from dataclasses import dataclass

import cv2
import numpy as np

from fpga_robotics.hw.validate import check_int

from .floor_patches import paint_floor_patches
from .kernel import NoiseTable, camera_kernel
from .scene import CameraPose, Scene

__all__ = [
    "DEFAULT_HFOV",
    "DEFAULT_MAX_LAYERS",
    "VERTICAL_MARGIN",
    "CameraRenderer",
    "floor_shade",
    "focal_length",
    "max_hfov",
    "max_tilt",
    "render",
    "silhouette_columns",
    "vertical_fov",
]

#: Horizontal field of view of the published system's camera, radians.
DEFAULT_HFOV = 1.047
#: Depth layers composited per column (nearest hits kept).
DEFAULT_MAX_LAYERS = 6
#: Hits closer than this (metres along the forward axis) are ignored (near clipping plane).
NEAR = 1e-3
# Sensor noise is drawn in blocks of about this many values (cache-sized).
_NOISE_BLOCK = 32768
#: Every ray stays at least this far (radians) from looking straight up or down.
VERTICAL_MARGIN = 0.02


@dataclass(frozen=True)
class _Walls:
    """Wall segments of a scene as arrays, shape (N,) each; built once per walls tuple."""

    x0: np.ndarray
    y0: np.ndarray
    ex: np.ndarray  # segment vector x1 - x0
    ey: np.ndarray
    length: np.ndarray
    height: np.ndarray
    albedo: np.ndarray  # (N, 3)
    block: np.ndarray = None  # (6, N): the six arrays above in one (the compiled stage's)


@dataclass(frozen=True)
class _Cylinders:
    """Cylinders as arrays (C,), and their bands flattened to arrays (B,)."""

    x: np.ndarray
    y: np.ndarray
    radius: np.ndarray
    band_owner: np.ndarray  # cylinder index of each band
    band_z0: np.ndarray
    band_z1: np.ndarray
    band_albedo: np.ndarray  # (B, 3)
    bands: tuple = ()  # the Band tuples they were made of (reused while these stay)
    centres: np.ndarray = None  # (3, C): x, y, radius in one (the compiled stage's)


def focal_length(width, hfov):
    """The pinhole focal length in pixels, ``(width/2) / tan(hfov/2)`` (square pixels)."""
    return (width / 2) / math.tan(hfov / 2)


def silhouette_columns(distance, bearing, radius, width, hfov):
    """``(left, right)``: the image columns (continuous pixels, 0 = the left edge) of the
    silhouette of an upright cylinder of ``radius`` whose axis stands ``distance`` from the
    camera at ``bearing`` (rad, left positive, in front of the camera): its tangents from the
    camera, ``bearing +- asin(radius / distance)``, at ``W/2 - f tan(angle)``. An edge at or
    behind the camera's plane is at -inf (left) or +inf (right); a camera inside the cylinder
    has it on both sides."""
    if distance <= radius:
        return -math.inf, math.inf
    a = math.asin(radius / distance)
    f, c = focal_length(width, hfov), width / 2
    left = -math.inf if bearing + a >= math.pi / 2 else c - f * math.tan(bearing + a)
    right = math.inf if bearing - a <= -math.pi / 2 else c - f * math.tan(bearing - a)
    return left, right


def vertical_fov(width, height, hfov):
    """The vertical field of view (rad) of a ``width`` x ``height`` image whose horizontal
    field of view is ``hfov`` (square pixels: ``2 atan((height/2) / f)``)."""
    return 2 * math.atan((height / 2) / focal_length(width, hfov))


def max_tilt(width, height, hfov):
    """The largest ``|tilt|`` (rad) the renderer draws for this image size and ``hfov``: the
    top and bottom rows stay ``VERTICAL_MARGIN`` away from looking straight up or down.
    Negative when even a level camera's rows would (``hfov`` too wide for the image's
    aspect ratio; see ``max_hfov``)."""
    return math.pi / 2 - VERTICAL_MARGIN - vertical_fov(width, height, hfov) / 2


def max_hfov(width, height, tilt=0.0):
    """The widest ``hfov`` (rad) the renderer draws at this image size with this tilt."""
    half_vfov = math.pi / 2 - VERTICAL_MARGIN - abs(tilt)
    return 2 * math.atan((width / height) * math.tan(half_vfov))


def _albedo(color, what):
    try:
        rgb = tuple(float(c) for c in color)
    except TypeError:
        rgb = ()
    if len(rgb) != 3 or not all(math.isfinite(c) and c >= 0.0 for c in rgb):
        raise ValueError(f"{what} colour must be three albedos (r, g, b) >= 0, got {color!r}")
    return rgb


def _walls_arrays(walls):
    n = len(walls)
    a = np.empty((n, 6))
    albedo = np.empty((n, 3))
    for i, w in enumerate(walls):
        a[i] = (w.x0, w.y0, w.x1 - w.x0, w.y1 - w.y0, 0.0, w.height)
        albedo[i] = _albedo(w.color, f"wall {i}")
    a[:, 4] = np.hypot(a[:, 2], a[:, 3])
    if not np.all(np.isfinite(a)):
        raise ValueError("wall coordinates and heights must be finite numbers")
    if np.any(a[:, 4] <= 0.0):
        i = int(np.argmin(a[:, 4]))
        raise ValueError(f"wall {i} has zero length ({walls[i]}); give it two distinct ends")
    # Contiguous columns: the compiled stage reads them as plain arrays.
    a = np.ascontiguousarray(a.T)
    return _Walls(a[0], a[1], a[2], a[3], a[4], a[5], albedo, a)


def _cylinder_arrays(cylinders, previous=None):
    """The cylinders as arrays; ``previous`` (the arrays of an earlier tuple) lends its band
    arrays when every cylinder wears the very same bands (people move, their looks stay)."""
    centres = np.empty((len(cylinders), 3))
    for i, c in enumerate(cylinders):
        centres[i] = (c.x, c.y, c.radius)
    bands = tuple(c.bands for c in cylinders)
    same_bands = (
        previous is not None
        and len(previous.bands) == len(bands)
        and all(a is b for a, b in zip(bands, previous.bands))
    )
    if not same_bands:
        owner, z, albedo = [], [], []
        for i, c in enumerate(cylinders):
            for band in c.bands:
                owner.append(i)
                z.append((band.z0, band.z1))
                albedo.append(_albedo(band.color, f"cylinder {i} band"))
    if not np.all(np.isfinite(centres)) or np.any(centres[:, 2] <= 0.0):
        raise ValueError("cylinders need finite centres and a radius > 0")
    centres = np.ascontiguousarray(centres.T)
    if same_bands:
        return _Cylinders(
            centres[0],
            centres[1],
            centres[2],
            previous.band_owner,
            previous.band_z0,
            previous.band_z1,
            previous.band_albedo,
            bands,
            centres,
        )
    z = np.ascontiguousarray(np.asarray(z, dtype=float).reshape(-1, 2).T)
    return _Cylinders(
        centres[0],
        centres[1],
        centres[2],
        np.asarray(owner, dtype=np.intp),
        z[0],
        z[1],
        np.asarray(albedo, dtype=float).reshape(-1, 3),
        bands,
        centres,
    )


class CameraRenderer:
    """Pinhole camera renderer for one image size, with its per-resolution tables cached.

    Parameters
    ----------
    width, height : int
        Image size in pixels.
    hfov : float
        Horizontal field of view, radians (0 < hfov < pi). The vertical field of view follows
        from square pixels: ``2 * atan((height/2) / f)``.
    max_layers : int
        Depth layers composited per column: the nearest ``max_layers`` wall / band hits in a
        column are drawn, farther ones are not (their rows would show floor or ceiling).
        Each wall crossed and each band of a person crossed is one hit.

    Attributes
    ----------
    focal : float
        Focal length in pixels, ``(width/2) / tan(hfov/2)``.
    column_angles : np.ndarray
        (width,) angle of each column's ray from the optical axis, radians, positive to the
        left (counter-clockwise, like the heading).

    Notes
    -----
    ``render`` is not thread safe (it reuses scratch buffers); use one renderer per thread.
    """

    def __init__(self, width, height, hfov=DEFAULT_HFOV, *, max_layers=DEFAULT_MAX_LAYERS):
        check_int("width", width, 1)
        check_int("height", height, 1)
        check_int("max_layers", max_layers, 1)
        if isinstance(hfov, bool) or not isinstance(hfov, numbers.Real) or not 0 < hfov < math.pi:
            raise ValueError(f"hfov must be an angle in radians between 0 and pi, got {hfov!r}")
        self.width = int(width)
        self.height = int(height)
        self.hfov = float(hfov)
        self.max_layers = int(max_layers)
        self.focal = focal_length(self.width, self.hfov)
        # Lateral offset (to the right) of each column's ray per metre forward.
        self._slope = (np.arange(self.width) + 0.5 - self.width / 2) / self.focal
        self._slope_sq1 = 1.0 + self._slope**2
        self.column_angles = -np.arctan(self._slope)
        # Continuous row of the optical axis, and the vertical half field of view.
        self._row_axis = self.height / 2 - 0.5
        self._half_vfov = math.atan((self.height / 2) / self.focal)
        #: The largest ``|pose.tilt|`` this renderer draws (``max_tilt``).
        self.max_tilt = max_tilt(self.width, self.height, self.hfov)
        if self.max_tilt < 0:
            raise ValueError(
                f"hfov {self.hfov!r} rad at {self.width}x{self.height} gives a vertical field of "
                f"view of {2 * self._half_vfov:.4f} rad: the top and bottom rows would look "
                f"straight up or down; at this size hfov must be at most "
                f"{max_hfov(self.width, self.height):.4f} rad"
            )
        # Scratch: run starts are counted into a (H+1, W) grid, then summed down the columns.
        # Run ids go up to width * runs per column; int16 sums faster when they fit.
        runs = 2 * self.max_layers + 2
        self._id_dtype = np.int16 if self.width * runs < 2**15 else np.int32
        self._counts = np.zeros((self.height + 1, self.width), dtype=self._id_dtype)
        self._run_ids = np.empty((self.height, self.width), dtype=self._id_dtype)
        self._one = self._id_dtype(1)  # a typed scalar keeps np.add.at on its fast path
        self._row_dtype = np.int16 if self.height < 2**15 - 2 else np.int32
        self._rgba = np.empty((self.height, self.width), dtype=np.uint32)
        self._rgba_bytes = self._rgba.view(np.uint8).reshape(self.height, self.width, 4)
        self._noise_rows = max(1, _NOISE_BLOCK // (3 * self.width))
        self._noise = np.empty((self._noise_rows, self.width, 3), dtype=np.int8)
        self._noise_std = self._noise_levels = self._noise_compiled = None
        self._cols = np.arange(self.width)
        self._col_index = self._cols[:, None]  # row selector for per-column gathers
        self._walls_key = self._walls = None
        self._cyls_key = self._cyls = None
        #: The compiled stages, or None (numpy); the image is the same either way.
        self._kernel = camera_kernel()
        self._surfaces_key = self._surfaces_value = None
        self._scratch = np.empty(0)
        self._scratch_address = _address(self._scratch)
        self._hit_scratch = self._hit_walls = self._hit_owner = None
        self._slope_address = _address(self._slope)
        self._slope_sq1_address = _address(self._slope_sq1)
        self._layer_starts = self._layer_palette = None
        self._draw_for = None  # (bit generator, its next_uint64, its state): see _direct_draw

    def __repr__(self):
        return (
            f"CameraRenderer(width={self.width}, height={self.height}, hfov={self.hfov}, "
            f"max_layers={self.max_layers})"
        )

    def row_elevations(self, tilt=0.0):
        """(height,) elevation of each row's ray at the centre column, radians (up positive)."""
        v = self.height / 2 - (np.arange(self.height) + 0.5)
        return np.arctan(v / self.focal) + tilt

    # -- scene geometry, converted once per walls / cylinders tuple -------------------------

    def _geometry(self, scene):
        if scene.walls is not self._walls_key:
            self._walls = _walls_arrays(scene.walls)
            self._walls_key = scene.walls
        if scene.cylinders is not self._cyls_key:
            self._cyls = _cylinder_arrays(scene.cylinders, self._cyls)
            self._cyls_key = scene.cylinders
        return self._walls, self._cyls

    # -- rows covered by a height range at a depth -------------------------------------------

    def _rows_of(self, slope, tilt):
        """Continuous image row where a ray with vertical slope ``dz/depth`` lands."""
        if tilt == 0.0:
            return self._row_axis - self.focal * slope
        lim = math.pi / 2 - 1e-6
        return self._row_axis - self.focal * np.tan(np.clip(np.arctan(slope) - tilt, -lim, lim))

    # -- the frame ---------------------------------------------------------------------------

    def render(self, scene, pose, noise_std=0.0, rng=None):
        """Render ``scene`` seen from ``pose``.

        Parameters
        ----------
        scene : Scene
        pose : CameraPose
        noise_std : float
            Standard deviation of additive Gaussian sensor noise, in 8-bit units (0 = none).
        rng : numpy.random.Generator
            Required when ``noise_std > 0``; the noise is a function of its state only.

        Returns
        -------
        np.ndarray
            (height, width, 3) uint8 RGB image.
        """
        if not isinstance(scene, Scene):
            raise TypeError(
                f"scene must be a fpga_robotics.sim.camera.scene.Scene, not {type(scene)}"
            )
        if not isinstance(pose, CameraPose):
            raise TypeError(
                f"pose must be a fpga_robotics.sim.camera.scene.CameraPose, not {type(pose)}"
            )
        if noise_std:
            _check_noise(noise_std, rng)
        if scene.floor_patches:
            image = paint_floor_patches(self, scene, pose, floor_shade(scene.lighting))
            if noise_std:
                self._add_noise(image, noise_std, rng)
            return image
        starts, palette = self._runs(scene, pose)
        if self._kernel is not None:
            return self._paint_compiled(starts, palette, noise_std, rng)
        # One 4-byte palette lookup per pixel, then RGBA -> RGB: ~3x faster than taking
        # 3-byte rows; cvtColor returns a fresh image for the caller.
        palette.take(self._paint_runs(starts), out=self._rgba)
        image = cv2.cvtColor(self._rgba_bytes, cv2.COLOR_RGBA2RGB)
        if noise_std:
            self._add_noise(image, noise_std, rng)
        return image

    def _paint_compiled(self, starts, palette, noise_std, rng):
        """The image from the runs in one compiled pass, noise included (same bytes as the
        numpy path: the same random bits, in the same order, index the same table)."""
        image = np.empty((self.height, self.width, 3), dtype=np.uint8)
        if starts.base is self._layer_starts is not None:  # the compiled layers' buffers
            starts_at, palette_at = self._layer_addresses
        else:
            starts = np.ascontiguousarray(starts, dtype=np.int32)
            palette = np.ascontiguousarray(palette, dtype=np.uint32)
            starts_at, palette_at = starts.ctypes.data, palette.ctypes.data
        noise, table, draw = None, (None, None, 0, None, 0), (None, None)
        if noise_std:
            self._noise_table(float(noise_std))
            if self._noise_compiled is None:
                self._noise_compiled = NoiseTable(self._noise_levels)
            table = self._noise_compiled.arguments
            draw = self._direct_draw(rng)
            if draw[0] is None:
                indices = self._noise_indices(rng)  # held until the call returns
                noise = indices.__array_interface__["data"][0]
        with rng.bit_generator.lock if noise_std else contextlib.nullcontext():
            self._kernel.paint(
                starts_at,
                starts.shape[1],
                palette_at,
                self.width,
                self.height,
                image.__array_interface__["data"][0],
                noise,
                *table,
                *draw,
            )
        return image

    def _direct_draw(self, rng):
        """``(next_uint64, state)`` addresses of ``rng``'s bit generator when the compiled
        stage may draw the noise bits itself: a PCG64 (whose ``random_raw`` is its
        ``next_uint64``) and rows of whole 64-bit draws; else ``(None, None)``."""
        bits = rng.bit_generator
        if type(bits) is not np.random.PCG64 or (3 * self.width) % 4:
            return None, None
        if self._draw_for is None or self._draw_for[0] is not bits:
            c = bits.ctypes
            self._draw_for = (
                bits,
                ctypes.cast(c.next_uint64, ctypes.c_void_p).value,
                c.state_address,
            )
        return self._draw_for[1:]

    def _noise_indices(self, rng):
        """The 16-bit table index of every byte of the image, row-major: the values
        ``_add_noise`` draws block by block, in one array."""
        bits = rng.bit_generator.random_raw
        size = self.height * self.width * 3
        if (3 * self.width) % 4 == 0:  # every block a whole number of 64-bit draws
            return bits(size // 4).view(np.uint16)
        indices = np.empty(size, dtype=np.uint16)
        block = self._noise_rows * self.width * 3
        for start in range(0, size, block):
            n = min(block, size - start)
            indices[start : start + n] = bits(-(-n // 4)).view(np.uint16)[:n]
        return indices

    def _add_noise(self, image, noise_std, rng):
        _check_noise(noise_std, rng)
        # Inverse-CDF sampling: 16 random bits of the caller's generator per value pick one of
        # 65536 equally likely quantiles of N(0, std), rounded to 8-bit levels. The raw bits
        # come 8 bytes at a time (several times faster than drawing normals). Blocks of rows
        # keep the bits, the indices and the noise in cache.
        table = self._noise_table(float(noise_std))
        bits = rng.bit_generator.random_raw
        step = self._noise_rows
        for r in range(0, self.height, step):
            rows = image[r : r + step]
            idx = bits(-(-rows.size // 4)).view(np.uint16)[: rows.size].reshape(rows.shape)
            noise = table.take(idx, out=self._noise[: rows.shape[0]])
            cv2.add(rows, noise, dst=rows, dtype=cv2.CV_8U)  # saturating at 0 and 255

    def _noise_table(self, noise_std):
        if self._noise_std != noise_std:
            levels = np.clip(np.rint(noise_std * _normal_quantiles()), -127, 127)
            self._noise_levels = levels.astype(np.int8)
            self._noise_compiled = None  # the compiled stage's forms, made when needed
            self._noise_std = noise_std
        return self._noise_levels

    def _runs(self, scene, pose):
        """Each column's run start rows (W, R), ascending from 0, and the flat palette
        (W * R) of packed RGBA uint32: column c's run j has colour ``palette[c * R + j]``."""
        W, H = self.width, self.height
        cx, cy, h, tilt = float(pose.x), float(pose.y), float(pose.height), float(pose.tilt)
        if not all(map(math.isfinite, (cx, cy, h, tilt, pose.heading))):
            raise ValueError(f"camera pose must be finite numbers, got {pose}")
        ceiling = float(scene.ceiling_height)
        if not (0.0 < h < ceiling):
            raise ValueError(
                f"camera height {h} m must be between the floor (0) and the ceiling ({ceiling} m)"
            )
        if abs(tilt) > self.max_tilt:
            raise ValueError(
                f"camera tilt {tilt:.4f} rad with a vertical field of view of "
                f"{2 * self._half_vfov:.4f} rad would look straight up or down; keep "
                f"|tilt| <= {self.max_tilt:.4f} rad"
            )
        ambient, intensity, light = _light(scene.lighting)
        walls, cyls = self._geometry(scene)
        floor_rgb = _lit(scene.floor_color, floor_shade(scene.lighting), "floor")
        ceil_rgb = _lit(scene.ceiling_color, ambient + intensity * max(0.0, light[2]), "ceiling")
        horizon = min(H, max(0, math.ceil(self._rows_of(0.0, tilt))))  # first floor row

        z0, z1, albedo = self._surfaces(walls, cyls, ceiling)
        if not len(z0):  # an empty scene: floor and ceiling only
            return self._paint_background(horizon, floor_rgb, ceil_rgb)
        hits = self._hits_compiled if self._kernel is not None else self._hits
        depth, shade = hits(walls, cyls, cx, cy, pose.heading, ambient, intensity, light)
        if self._kernel is not None and tilt == 0.0:
            layers = self._layers_compiled(
                depth, shade, z0, z1, albedo, h, horizon, floor_rgb, ceil_rgb
            )
            if layers is not None:
                return layers
            return self._paint_background(horizon, floor_rgb, ceil_rgb)
        n = depth.shape[1]

        # Usually every hit of a column fits in the layer budget: then draw them all. Else
        # take the 2k nearest as candidates and drop the hidden ones first (below). Equal
        # depths (the bands of one person) keep the surfaces' order: a stable sort.
        most = int(np.count_nonzero(depth < np.inf, axis=1).max())
        if most == 0:
            return self._paint_background(horizon, floor_rgb, ceil_rgb)
        k = min(self.max_layers, most)
        m = min(2 * k, most)
        ci = self._col_index
        cand = np.argsort(depth, axis=1, kind="stable")
        if n > m:
            cand = cand[:, :m]
        row_start, row_end = self._rows_covered(depth[ci, cand], z0[cand], z1[cand], h, tilt)
        if m == k:
            sel = cand  # (W, k) surface of each layer, nearest first
        else:
            # A candidate whose rows all lie within those of a nearer one is hidden: a box's
            # far side behind its near side, a wall behind a taller one. Drop those (and
            # misses) before keeping the k nearest, so they do not use up the layer budget.
            hidden = (
                (row_start[:, :, None] <= row_start[:, None, :])
                & (row_end[:, :, None] >= row_end[:, None, :])
                & _nearer(m)
            ).any(axis=1)
            hidden |= row_start >= row_end
            keep = np.argsort(hidden, axis=1, kind="stable")[:, :k]  # visible first, by depth
            sel = cand[ci, keep]
            gone = hidden[ci, keep]
            row_start = np.where(gone, H, row_start[ci, keep])
            row_end = np.where(gone, H, row_end[ci, keep])
        # Layer k is a sentinel covering every row: "no surface here".
        rs = np.zeros((W, k + 1), dtype=self._row_dtype)
        re = np.full((W, k + 1), H + 1, dtype=self._row_dtype)
        rs[:, :k] = row_start
        re[:, :k] = row_end
        # Colour of each layer, then the ceiling (k) and the floor (k + 1), per column.
        colors = np.empty((W, k + 2, 3))
        colors[:, :k] = albedo[sel] * shade[ci, sel][:, :, None]
        colors[:, k] = ceil_rgb
        colors[:, k + 1] = floor_rgb
        colors = _packed_colors(colors)

        # Each column splits into runs at the layers' edges and the horizon; a run shows the
        # nearest layer covering its first row, else ceiling (above the horizon) or floor.
        starts = np.empty((W, 2 * k + 2), dtype=self._row_dtype)
        starts[:, 0] = 0
        starts[:, 1] = horizon
        starts[:, 2 : k + 2] = rs[:, :k]
        starts[:, k + 2 :] = re[:, :k]
        starts.sort(axis=1)
        s = starts[:, :, None]
        layer = ((rs[:, None, :] <= s) & (s < re[:, None, :])).argmax(axis=2)  # (W, runs)
        layer += (layer == k) & (starts >= horizon)  # no surface: ceiling or floor
        return starts, colors[ci, layer].ravel()

    def _layers_compiled(self, depth, shade, z0, z1, albedo, h, horizon, floor_rgb, ceil_rgb):
        """The rest of ``_runs`` for a level camera in one compiled pass: run starts
        (W, 2k + 2) and palette, or None when no column sees a surface."""
        W, n = depth.shape
        if self._layer_starts is None:
            runs = 2 * self.max_layers + 2
            self._layer_starts = np.empty(W * runs, dtype=np.int32)
            self._layer_palette = np.empty(W * runs, dtype=np.uint32)
            self._layer_addresses = (
                self._layer_starts.ctypes.data,
                self._layer_palette.ctypes.data,
            )
        depth_at, shade_at = self._hit_addresses
        z0_at, z1_at, albedo_at = self._surfaces_addresses
        k = self._kernel.layers(
            W,
            self.height,
            n,
            depth_at,
            shade_at,
            z0_at,
            z1_at,
            albedo_at,
            h,
            self._row_axis,
            self.focal,
            self.max_layers,
            horizon,
            *map(float, ceil_rgb),
            *map(float, floor_rgb),
            *self._layer_addresses,
        )
        if k == 0:
            return None
        runs = 2 * k + 2
        return self._layer_starts[: W * runs].reshape(W, runs), self._layer_palette[: W * runs]

    def _surfaces(self, walls, cyls, ceiling):
        """Bottom and top height (clipped to the floor and the ceiling) and albedo of every
        surface, walls first, then bands; kept while the geometry arrays are the same."""
        key = (walls, cyls.band_z0, ceiling)
        if self._surfaces_key is None or any(a is not b for a, b in zip(key, self._surfaces_key)):
            z0 = np.concatenate([np.zeros(len(walls.x0)), cyls.band_z0])
            z1 = np.concatenate([walls.height, cyls.band_z1])
            albedo = np.concatenate([walls.albedo, cyls.band_albedo])
            # The floor and ceiling hide anything below 0 or above the ceiling.
            self._surfaces_value = (np.maximum(z0, 0.0), np.minimum(z1, ceiling), albedo)
            self._surfaces_addresses = tuple(map(_address, self._surfaces_value))
            self._surfaces_key = key
        return self._surfaces_value

    def _hits(self, walls, cyls, cx, cy, heading, ambient, intensity, light):
        """Depth (inf: no hit) and shade of every surface in every column, (W, surfaces),
        for a camera at ``(cx, cy)`` looking along ``heading``."""
        W = self.width
        ch, sh = math.cos(heading), math.sin(heading)
        # Column ray directions with a forward component of 1: the ray parameter is the depth.
        dx = (ch + self._slope * sh)[:, None]
        dy = (sh - self._slope * ch)[:, None]
        depths, shades = [], []
        with np.errstate(divide="ignore", invalid="ignore"):
            if len(walls.x0):
                qx, qy = walls.x0 - cx, walls.y0 - cy
                # Unit normal turned towards the camera (the camera's side of the wall line).
                side = np.where(walls.ey * qx - walls.ex * qy > 0.0, -1.0, 1.0) / walls.length
                ndotl = side * (walls.ey * light[0] - walls.ex * light[1])
                wall_shade = ambient + intensity * np.maximum(0.0, -ndotl)
                denom = dx * walls.ey - dy * walls.ex
                t = (qx * walls.ey - qy * walls.ex) / denom
                s = (qx * dy - qy * dx) / denom
                depths.append(np.where((s >= 0.0) & (s <= 1.0) & (t > NEAR), t, np.inf))
                shades.append(np.broadcast_to(wall_shade, (W, len(wall_shade))))
            if len(cyls.band_owner):
                qx, qy, r = cx - cyls.x, cy - cyls.y, cyls.radius
                b = dx * qx + dy * qy
                c = qx * qx + qy * qy - r * r  # > 0: camera outside the cylinder
                disc = b * b - self._slope_sq1[:, None] * c
                t = (-b - np.sqrt(disc)) / self._slope_sq1[:, None]
                t = np.where((disc >= 0.0) & (t > NEAR) & (c > 0.0), t, np.inf)
                # Outward normal at the hit point, (q + t d) / r (horizontal).
                th = np.where(t < np.inf, t, 0.0)  # keeps misses finite (they are not drawn)
                ndotl = ((qx + th * dx) * light[0] + (qy + th * dy) * light[1]) / r
                shade = ambient + intensity * np.maximum(0.0, -ndotl)
                own = cyls.band_owner
                depths.append(t[:, own])
                shades.append(shade[:, own])
        depth = np.concatenate(depths, axis=1) if len(depths) > 1 else depths[0]
        shade = np.concatenate(shades, axis=1) if len(shades) > 1 else shades[0]
        return depth, shade

    def _hits_compiled(self, walls, cyls, cx, cy, heading, ambient, intensity, light):
        """``_hits`` in one compiled pass (the same values to the bit); the arrays are
        scratch, valid until the next frame."""
        n_walls, n_cyls, n_bands = len(walls.x0), len(cyls.x), len(cyls.band_owner)
        n = n_walls + n_bands
        if self._hit_scratch is None or self._hit_scratch[0].shape[1] != n:
            self._hit_scratch = (np.empty((self.width, n)), np.empty((self.width, n)))
            self._hit_addresses = tuple(map(_address, self._hit_scratch))
        if len(self._scratch) < n_walls + 2 * n_cyls:
            self._scratch = np.empty(n_walls + 2 * n_cyls)
            self._scratch_address = _address(self._scratch)
        if walls is not self._hit_walls:  # addresses kept with the arrays they point into
            self._hit_walls, self._walls_address = walls, _address(walls.block)
        if cyls.band_owner is not self._hit_owner:
            self._hit_owner, self._owner_address = cyls.band_owner, _address(cyls.band_owner)
        self._kernel.hits(
            self.width,
            self._slope_address,
            self._slope_sq1_address,
            math.cos(heading),
            math.sin(heading),
            cx,
            cy,
            n_walls,
            self._walls_address,
            n_cyls,
            _address(cyls.centres),
            n_bands,
            self._owner_address,
            NEAR,
            ambient,
            intensity,
            float(light[0]),
            float(light[1]),
            self._scratch_address,
            *self._hit_addresses,
        )
        return self._hit_scratch

    def _rows_covered(self, depth, z0, z1, h, tilt):
        """Rows ``row_start <= row < row_end`` where surfaces at ``depth`` spanning heights
        ``z0..z1`` are seen (pixel centres inside the span); (H, H) for no hit."""
        H = self.height
        hit = np.isfinite(depth)
        p = np.where(hit, depth, 1.0)
        row_start = np.ceil(self._rows_of((z1 - h) / p, tilt))
        row_end = np.floor(self._rows_of((z0 - h) / p, tilt)) + 1.0
        row_start = np.where(hit, np.clip(row_start, 0, H), H).astype(self._row_dtype)
        row_end = np.where(hit, np.clip(row_end, 0, H), H).astype(self._row_dtype)
        return row_start, row_end

    def _paint_runs(self, starts):
        """Run id of every pixel: column c's runs are c*R .. c*R+R-1, starting at ``starts``."""
        W, runs = self.width, starts.shape[1]
        counts = self._counts
        counts.fill(0)
        counts[0] = self._cols * runs
        # Every run start after the first adds one; starts equal to H land in the spare row.
        pos = starts[:, 1:].astype(np.intp) * W + self._col_index
        np.add.at(counts.reshape(-1), pos.ravel(), self._one)
        np.cumsum(counts[:-1], axis=0, out=self._run_ids)
        return self._run_ids

    def _paint_background(self, horizon, floor_rgb, ceil_rgb):
        starts = np.empty((self.width, 2), dtype=self._row_dtype)
        starts[:, 0] = 0
        starts[:, 1] = horizon
        palette = np.empty((self.width, 2, 3))
        palette[:, 0] = ceil_rgb if horizon > 0 else floor_rgb
        palette[:, 1] = floor_rgb
        return starts, _packed_colors(palette).ravel()


def _check_noise(noise_std, rng):
    if not (math.isfinite(noise_std) and noise_std > 0):
        raise ValueError(f"noise_std must be a finite number >= 0, got {noise_std!r}")
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            "noise_std > 0 needs rng=numpy.random.Generator (e.g. np.random.default_rng(seed))"
            " so that the noise is reproducible"
        )


def _address(array):
    """The data address of a C-contiguous float64 or int64 array (checked: the compiled
    stage reads it as such)."""
    assert array.flags.c_contiguous and array.dtype.itemsize == 8, array.dtype
    return array.__array_interface__["data"][0]


@functools.lru_cache(maxsize=1)
def _normal_quantiles():
    """The 65536 quantiles of N(0, 1) at probabilities (i + 0.5) / 65536 (|q| < 4.4)."""
    inv_cdf = statistics.NormalDist().inv_cdf
    return np.array([inv_cdf((i + 0.5) / 65536) for i in range(65536)])


@functools.lru_cache(maxsize=64)
def _nearer(m):
    """(m, m) bool: candidate i is nearer than candidate j (both sorted by depth)."""
    return np.triu(np.ones((m, m), dtype=bool), 1)


def _light(lighting):
    ambient, intensity = float(lighting.ambient), float(lighting.intensity)
    d = np.asarray(lighting.direction, dtype=float)
    norm = float(np.linalg.norm(d)) if d.shape == (3,) else 0.0
    if not (math.isfinite(norm) and norm > 0.0):
        raise ValueError(
            f"lighting.direction must be a non-zero (dx, dy, dz) vector, got {lighting.direction!r}"
        )
    if not (ambient >= 0.0 and intensity >= 0.0):
        raise ValueError(
            f"lighting.ambient and lighting.intensity must be >= 0, got {ambient}, {intensity}"
        )
    return ambient, intensity, d / norm


def floor_shade(lighting):
    """How bright the flat floor is lit: ambient plus the light falling on it (Lambert)."""
    ambient, intensity, light = _light(lighting)
    return ambient + intensity * max(0.0, -light[2])


def _lit(color, shade, what):
    return np.asarray(_albedo(color, what)) * shade


def _packed_colors(rgb):
    """Linear colours (..., 3) to 8-bit (rounded, clipped), packed as RGBA uint32 (...)."""
    rgba = np.zeros(rgb.shape[:-1] + (4,), dtype=np.uint8)
    rgba[..., :3] = np.clip(rgb * 255.0 + 0.5, 0.0, 255.0)
    return rgba.view(np.uint32)[..., 0]


@functools.lru_cache(maxsize=8)
def _renderer(width, height, hfov):
    return CameraRenderer(width, height, hfov)


def render(scene, pose, width, height, hfov=DEFAULT_HFOV, *, noise_std=0.0, rng=None):
    """Render ``scene`` from ``pose`` at ``width`` x ``height``; (height, width, 3) uint8.

    Convenience wrapper around a cached :class:`CameraRenderer` per (width, height, hfov).
    ``noise_std`` (8-bit units) adds Gaussian sensor noise drawn from ``rng`` (required then).
    """
    return _renderer(width, height, hfov).render(scene, pose, noise_std=noise_std, rng=rng)
