"""Behaviour envelopes: what the design promises at robot level, as bands computed from its
parameters (``FollowTargetParams``) and the camera's geometry, not from what the design
reports (its ``found`` only picks the frames each law applies to).

Per frame, the target's pixel count in the tracking window is bounded from where the target
stands (pinhole camera, the person an upright cylinder of coloured bands): ``count_bounds``.
The proximity levels those counts allow give the law's forward speed (``base_dps``), and the
target's image column gives the centroid error ``e`` and so the law's turn
(``(kp_num * e) >> kp_shift``, wheels saturating at ``max_dps``). The design's wheel commands
(``motor_left``, ``motor_right``: forward ``(L + R) / 2``, turn ``(L - R) / 2``) must fall in
those bands. Stated tolerances (nothing tuned to a run):

- count: the silhouette's width and each band's rows +-1 pixel (edge quantisation), the rows
  inside the window the fewest (lower bound) and the most (upper bound) the band covers at
  any depth from the body's point nearest the camera to its axis (a band cut by the window's
  top or bottom row covers more rows further away); a band counts towards the lower bound
  only if its colour matches at every shade from the darkest light of the scenario (ambient
  alone) to its brightest (ambient plus the light's intensity), towards the upper one if at
  any (the filter is not monotone in brightness);
- centroid error ``e``: +-2 pixels (the centroid's floor and the half-pixel of the column),
  plus half the silhouette's width when a band that may count does not match at every shade
  (then only a lit strip may match, up to the silhouette's edge, and the centroid is its
  middle);
- with the camera's sensor model (``camera.sensor``) no band matches surely (exposure and
  white balance move its colour) and the turn's smear over a frame's exposure adds half its
  length to the centroid's tolerance;
- only frames with the whole silhouette inside the window's columns are judged, with the
  target assumed the only thing of its colour in view (another adds pixels: the robustness
  campaign's known limits show where that fails);
- in a frame where furniture, a divider or another person hides part of the target (the
  trajectory's ``target_hidden``) the count may be anything from 0 to its upper bound and
  the centroid anywhere on the silhouette, as for a lit strip; such a frame does not judge
  the stop distance.

The bounds do not model the plain camera's noise: it is small enough for their slack up to
``NOISE_STD_MODELLED``, and beyond it the envelopes are n/a.

The envelopes read the default laws (``motor_law = "p_control"``, ``lost_motion = "hold"``,
``search_side_from = "centroid"``); a design with another law has them n/a, and so has a run
with the 3D renderer (its people are bodies, not cylinders of bands).
"""

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from fpga_robotics.checks.window import whole_in_window, window_columns
from fpga_robotics.sim.camera.raster import silhouette_columns
from fpga_robotics.sim.models.follow_target import match_table, proximity_level
from fpga_robotics.sim.world.people import person_bands

__all__ = [
    "EnvelopeGeometry",
    "count_bounds",
    "envelope_geometry",
    "envelope_metrics",
    "law_band",
    "lit_strip_frames",
    "stop_distance_m",
    "sure_side",
]

#: Tolerance of the centroid error against the target's image column, pixels.
E_TOLERANCE_PX = 2.0
#: A target within this many pixels of the image centre is "centred" (speed envelope).
CENTRED_PX_FRACTION = 1 / 16
#: The most camera noise (``camera.noise_std``, 8-bit levels) the count bounds' edge slack was
#: measured to absorb (the `robustness` campaign's noise 8 in every 2D scenario; from 10 the
#: filter drops enough of a shaded suit's pixels that lost_target's count leaves its bounds).
NOISE_STD_MODELLED = 8.0


@dataclass(frozen=True)
class EnvelopeGeometry:
    """What the bands need to know of the camera and the target.

    width, height, hfov : the image and its horizontal field of view (rad).
    mount_height, mount_forward, tilt : the camera on the robot (m, m, rad; a frame's tilt
        on a ramp adds the slope's pitch, the trajectory's ``camera_tilt``); ``yaw``: its
        yaw off the heading (rad, left positive).
    radius : the target's radius (m).
    bands_sure, bands_maybe : per colour code, the ``(z0, z1)`` of the target's bands that
        match in every light (lower bound) and in some light (upper bound).
    """

    width: int
    height: int
    hfov: float
    mount_height: float
    mount_forward: float
    tilt: float
    radius: float
    bands_sure: dict
    bands_maybe: dict
    #: The mount's yaw off the robot's heading (rad, left positive).
    yaw: float = 0.0
    #: The longest exposure (s) over which a turning robot smears the image sideways (the
    #: sensor model's motion blur; 0 for the plain camera, which has none).
    exposure_s: float = 0.0
    #: The colour codes for which a band of the target matches in some light but not in all:
    #: its shaded side may drop out and only a lit strip match (``lit_strip_frames``).
    lit_strip_codes: frozenset = frozenset()

    @property
    def focal(self):
        return (self.width / 2) / math.tan(self.hfov / 2)


def _band_matches(color, shades, code, params):
    """Whether a band of albedo ``color`` matches colour ``code`` lit by each of ``shades``."""
    table = match_table(code, params)
    out = []
    for s in shades:
        r, g, b = (min(255, int(c * s * 255.0 + 0.5)) >> 4 for c in color)
        out.append(bool(table[(r << 8) | (g << 4) | b]))
    return out


def _shades(color, darkest, brightest):
    """Shades from ``darkest`` to ``brightest`` that give a band of albedo ``color`` each of
    the RGB444 colours it takes in that range: the ends and one shade between each pair of
    neighbouring level changes (the filter is not monotone in brightness: a channel that
    saturates stops rising while the others go on)."""
    changes = {
        (16 * level - 0.5) / (255.0 * c)
        for c in color
        if c > 0
        for level in range(1, 16)
        if darkest < (16 * level - 0.5) / (255.0 * c) < brightest
    }
    edges = [darkest, *sorted(changes), brightest]
    return [darkest, brightest] + [(a + b) / 2 for a, b in itertools.pairwise(edges)]


def envelope_geometry(scenario, world_config, camera):
    """The ``EnvelopeGeometry`` of a run (``scenario``, its ``WorldConfig``, its
    ``CameraConnector``), or why there is none (a string): no target person, or a renderer
    that draws bodies rather than the cylinders the bounds are computed for."""
    target = next((p for p in world_config.people if p.target), None)
    if target is None:
        return "no target person"
    if scenario.camera.renderer != "raster":
        return (
            f"the bands are computed for the 2D renderer's cylinders; camera.renderer = "
            f"{scenario.camera.renderer!r} draws bodies"
        )
    if scenario.camera.sensor == "plain" and scenario.camera.noise_std > NOISE_STD_MODELLED:
        return (
            f"the count bounds model camera noise up to noise_std {NOISE_STD_MODELLED:g}; "
            f"camera.noise_std = {scenario.camera.noise_std:g} moves pixels across the colour "
            f"filter beyond their slack"
        )
    light = world_config.lighting
    ambients = [light.ambient] + [k[1] for k in light.keyframes]
    brights = [light.ambient + light.intensity] + [k[1] + k[2] for k in light.keyframes]
    darkest, brightest = min(ambients), max(brights)
    sure, maybe = {}, {}
    for code in range(8):
        sure[code], maybe[code] = [], []
        for band in person_bands(target):
            shades = _shades(band.color, darkest, brightest)
            ok = _band_matches(band.color, shades, code, scenario.params)
            if all(ok):
                sure[code].append((band.z0, band.z1))
            if any(ok):
                maybe[code].append((band.z0, band.z1))
    lit_strip = frozenset(code for code in range(8) if sure[code] != maybe[code])
    cam = scenario.camera
    exposure = 0.0
    if cam.sensor != "plain":
        # The sensor model's exposure and white balance change the colour a band takes: no
        # band matches surely, and an exposure may last up to a whole frame.
        sure = {code: [] for code in sure}
        exposure = cam.frame_period
    return EnvelopeGeometry(
        cam.width,
        cam.height,
        cam.hfov,
        camera.mount_height,
        camera.mount_forward,
        camera.tilt,
        target.radius,
        sure,
        maybe,
        yaw=getattr(camera, "yaw_offset", 0.0),
        exposure_s=exposure,
        lit_strip_codes=lit_strip,
    )


def lit_strip_frames(traj, geom):
    """Per frame, whether the colour selected (``color_sel``) may match only a lit strip of
    the target's suit (``EnvelopeGeometry.lit_strip_codes``); None without a geometry."""
    if isinstance(geom, str) or "color_sel" not in traj:
        return None
    return np.isin(np.asarray(traj["color_sel"], np.int64), list(geom.lit_strip_codes))


def _row(z, depth, geom):
    """The image row (continuous) where height ``z`` at ``depth`` (m along the camera's axis)
    lands, as the renderer draws it (``sim.camera.raster``: tilt rotates each column's
    vertical fan of rays; a ray at or past straight up or down is clipped)."""
    lim = math.pi / 2 - 1e-6
    angle = math.atan2(z - geom.mount_height, depth) - geom.tilt
    return geom.height / 2 - geom.focal * math.tan(max(-lim, min(lim, angle)))


def _rows(z0, z1, depth, geom, params):
    """Rows of the window (continuous) a band from ``z0`` to ``z1`` covers at ``depth``."""
    lo, hi = params.margin_y, geom.height - params.margin_y
    return max(0.0, min(_row(z0, depth, geom), hi) - max(_row(z1, depth, geom), lo))


def _depths(distance, bearing, radius):
    """``(near, far)``: depths (m along the camera's axis, the depth the renderer draws a
    column's rows at) between which every visible point of an upright cylinder of ``radius``
    lies, its axis ``distance`` from the camera at ``bearing`` (rad): the point of it nearest
    the camera's plane, and the axis's distance, beyond the silhouette's edges (at most
    ``sqrt(distance**2 - radius**2)``)."""
    return distance * math.cos(bearing) - radius, distance


def _row_span(z0, z1, near, far, geom, params):
    """``(least, most)`` rows of the window (continuous) a band from ``z0`` to ``z1`` covers at
    any depth from ``near`` to ``far``.

    Each edge's row moves monotonically with the depth (towards the horizon), so between the
    depths where an edge crosses the window's top or bottom row the covered rows change
    monotonically, except with both edges inside the window: there they are ``f p (z1 - z0)
    / ((p cos t + z1' sin t)(p cos t + z0' sin t))`` (heights ``z'`` from the camera, tilt
    ``t``), which rises to one maximum at ``p = sqrt(z0' z1') |tan t|`` when both edges lie
    on the same side of the camera. The least and most lie at those depths or the ends."""
    h, t = geom.mount_height, geom.tilt
    inside = []
    for z in (z0, z1):
        for edge in (params.margin_y, geom.height - params.margin_y):
            angle = math.atan((geom.height / 2 - edge) / geom.focal) + t
            if 0 < (z - h) * angle and abs(angle) < math.pi / 2:
                inside.append((z - h) / math.tan(angle))
    if (z0 - h) * (z1 - h) > 0:
        inside.append(math.sqrt((z0 - h) * (z1 - h)) * abs(math.tan(t)))
    depths = [near, far] + [p for p in inside if near < p < far]
    spans = [_rows(z0, z1, p, geom, params) for p in depths]
    return min(spans), max(spans)


def silhouette(distance, bearing, geom):
    """``(left, right)`` image columns of the target's silhouette (continuous pixels)."""
    return silhouette_columns(distance, bearing, geom.radius, geom.width, geom.hfov)


def count_bounds(distance, bearing, code, geom, params):
    """``(lo, hi)``: the target's pixel count in the window for a camera ``distance`` (m) from
    its centre, at ``bearing`` (rad, left positive), colour code ``code``; None when the
    silhouette is not wholly inside the window's columns."""
    if distance <= geom.radius or abs(bearing) >= geom.hfov / 2:
        return None
    left, right = silhouette(distance, bearing, geom)
    if not whole_in_window(left, right, geom.width, params.margin_x):
        return None
    cols = right - left
    near, far = _depths(distance, bearing, geom.radius)
    # Every column shows each band at its own depth: the count lies between the columns
    # times the fewest rows a band covers at any depth from near to far and times the most.
    lo = hi = 0.0
    for z0, z1 in geom.bands_sure[code]:
        lo += max(0.0, cols - 2) * max(0.0, _row_span(z0, z1, near, far, geom, params)[0] - 2)
    for z0, z1 in geom.bands_maybe[code]:
        hi += (cols + 2) * (_row_span(z0, z1, near, far, geom, params)[1] + 2)
    return math.floor(lo), math.ceil(hi)


def _saturate(v, params):
    return max(-params.max_dps, min(params.max_dps, v))


def law_band(levels, e_lo, e_hi, params):
    """The law's ``(forward_min, forward_max, turn_min, turn_max)`` for proximity levels in
    ``levels`` and a centroid error in ``[e_lo, e_hi]`` (pixels): forward ``(L + R) / 2``,
    turn ``(L - R) / 2`` of ``L, R = sat(base +- (kp_num * e) >> kp_shift)``."""
    es = {math.floor(e_lo), math.ceil(e_hi), min(max(0, math.floor(e_lo)), math.ceil(e_hi))}
    fwd, turn = [], []
    for level in levels:
        b = params.base_dps[level]
        for e in es:
            t = (params.kp_num * e) >> params.kp_shift
            left, right = _saturate(b + t, params), _saturate(b - t, params)
            fwd.append((left + right) / 2)
            turn.append((left - right) / 2)
    return min(fwd), max(fwd), min(turn), max(turn)


def _supported(params):
    """None when the envelopes read this design's laws, else why not."""
    if params.motor_law != "p_control":
        return f"the design steers by its LED table (motor_law={params.motor_law!r})"
    if params.lost_motion != "hold" or params.search_side_from != "centroid":
        return "the design's lost/search law is not the default one"
    return None


def _stop_level(params):
    """The lowest proximity level whose law speed is not forward (None: the law never stops)."""
    return next((lvl for lvl in range(1, 8) if params.base_dps[lvl] <= 0), None)


#: ``stop_distance_m``'s answers: a sweep of 3940 distances that depends on the camera and
#: the design only, the same for every run of a campaign's scenario (the geometry's repr,
#: exact for its floats, stands for it).
_STOP_DISTANCES = {}


def stop_distance_m(geom, params, code):
    """``(near, far)``: within ``near`` m (camera to the target's centre, target straight
    ahead) the law surely says stop or reverse; beyond ``far`` it surely drives forward.
    None when the law never stops or the count may never reach its level; ``near`` None when
    the count may reach it but nowhere surely (no band of the colour sure to match)."""
    key = (repr(geom), params, code)
    if key not in _STOP_DISTANCES:
        if len(_STOP_DISTANCES) >= 256:
            _STOP_DISTANCES.clear()
        _STOP_DISTANCES[key] = _stop_distance(geom, params, code)
    return _STOP_DISTANCES[key]


def _stop_distance(geom, params, code):
    level = _stop_level(params)
    if level is None:
        return None
    threshold = params.proximity_thresholds[level - 1]
    near = far = None
    for d in np.arange(0.3, 20.0, 0.005):
        b = count_bounds(float(d), 0.0, code, geom, params)
        if b is None:
            continue
        if b[0] >= threshold:
            near = float(d)
        if b[1] >= threshold:
            far = float(d)
    if far is None:
        return None
    return (None if near is None else round(near, 3)), round(far, 3)


def _camera_view(traj, geom):
    """Per frame: the camera's distance to the target's centre (m) and its bearing (rad)."""
    h = np.asarray(traj["heading"], float)
    cx = np.asarray(traj["x"], float) + geom.mount_forward * np.cos(h)
    cy = np.asarray(traj["y"], float) + geom.mount_forward * np.sin(h)
    dx = np.asarray(traj["target_x"], float) - cx
    dy = np.asarray(traj["target_y"], float) - cy
    bearing = (np.arctan2(dy, dx) - h - geom.yaw + np.pi) % (2 * np.pi) - np.pi
    return np.hypot(dx, dy), bearing


_NAMES = (
    "approach_speed_violation_fraction",
    "reverse_when_far_fraction",
    "turn_law_violation_fraction",
    "search_law_violation_fraction",
    "stop_overshoot_m",
    "stop_distance_m",
    "stop_closest_m",
    "stop_reason",
    "envelope_reason",
    "approach_speed_frames",
    "reverse_when_far_frames",
    "turn_law_frames",
    "search_law_frames",
)


def envelope_metrics(traj, params, geom):
    """The envelope metrics of a run (``geom``: ``envelope_geometry``'s answer): fractions of
    the judged frames outside each band (None when no frame could be judged), the stop
    overshoot (m) with the stop distance and the closest judged distance it is measured
    against (camera to the target's centre, m; each frame's stop distance is the one of the
    colour it follows), ``stop_reason`` (why there is no stop overshoot, else None) and
    ``envelope_reason`` (why nothing could be judged at all, else None). Each law's
    ``..._frames`` (``_frames_judged``) says how many frames it judged and what the first
    one outside the law commanded against what the law allowed."""
    out = dict.fromkeys(_NAMES)
    why = geom if isinstance(geom, str) else _supported(params)
    need = ("found", "motor_left", "motor_right", "target_x", "color_sel", "heading")
    if why is None and any(k not in traj for k in need):
        why = "the trajectory lacks the design's found/motor outputs"
    if why is not None:
        out["envelope_reason"] = why
        return out
    found = np.asarray(traj["found"], float)
    if np.isnan(found).any():  # a design of one's own without the output records NaN
        out["envelope_reason"] = "the design has no found output"
        return out
    found = found.astype(bool)
    ml = np.asarray(traj["motor_left"], float)
    mr = np.asarray(traj["motor_right"], float)
    if np.isnan(ml).any() or np.isnan(mr).any():
        out["envelope_reason"] = "the design has no wheel command outputs"
        return out
    fwd, turn = (ml + mr) / 2, (ml - mr) / 2
    # An obstacle interlock (follow_target_safe's ``obstacle`` output) holding the wheels at 0
    # overrides the law in those frames: they are not judged.
    interlocked = np.asarray(traj.get("design.obstacle", np.zeros(len(found))), float) == 1
    dist, bearing = _camera_view(traj, geom)
    codes = np.asarray(traj["color_sel"], np.int64)
    # On a ramp the camera pitches with the robot: each frame's rows are drawn at its tilt.
    tilts = np.asarray(traj.get("camera_tilt", np.full(len(codes), geom.tilt)), float)
    # Furniture or a person between the camera and part of the target (``target_hidden``)
    # takes pixels off the count and moves the centroid anywhere on the silhouette.
    hidden = np.asarray(traj.get("target_hidden", np.zeros(len(codes))), bool)
    w, centred_px = geom.width, geom.width * CENTRED_PX_FRACTION
    speed, reverse, steer = [], [], []
    # The stop distance of the colour each frame follows (None: that colour never stops).
    stops = {c: stop_distance_m(geom, params, c) for c in {int(c) for c in codes[found]}}
    near = np.array([_or_nan((stops.get(int(c)) or (None,))[0]) for c in codes])
    far = np.array([(stops.get(int(c)) or (math.nan, math.nan))[1] for c in codes])
    own = _own_depth(traj, dist, near)
    came_near, judged_stop = False, []
    for k in np.flatnonzero(found):
        if not math.isfinite(dist[k]):
            continue
        code = int(codes[k])
        frame_geom = geom if tilts[k] == geom.tilt else replace(geom, tilt=float(tilts[k]))
        bounds = count_bounds(float(dist[k]), float(bearing[k]), code, frame_geom, params)
        if bounds is None:
            continue
        if hidden[k]:
            bounds = (0, bounds[1])
        levels = range(
            proximity_level(bounds[0], params.proximity_thresholds),
            proximity_level(bounds[1], params.proximity_thresholds) + 1,
        )
        left, right = silhouette(float(dist[k]), float(bearing[k]), geom)
        column = (left + right) / 2 - 0.5  # the pixel index the centre falls on
        tol = E_TOLERANCE_PX
        if geom.bands_maybe[code] != geom.bands_sure[code] or hidden[k]:
            # Only a lit strip, or the part not hidden, may match, anywhere up to the
            # silhouette's edge.
            tol += (right - left) / 2
        if geom.exposure_s and "w" in traj:  # half the smear of a turn during the exposure
            tol += abs(float(traj["w"][k])) * geom.exposure_s * geom.focal / 2
        e = column - w // 2
        f_lo, f_hi, t_lo, t_hi = law_band(levels, e - tol, e + tol, params)
        if not interlocked[k]:
            where = {"levels": [int(levels[0]), int(levels[-1])], "distance_m": float(dist[k])}
            if abs(column + 0.5 - w / 2) <= centred_px:
                bad = not f_lo <= fwd[k] <= f_hi
                speed.append((k, bad, fwd[k], [f_lo, f_hi], where))
            if f_lo >= 0:
                reverse.append((k, fwd[k] < 0, fwd[k], [f_lo, f_hi], where))
            steer.append((k, not t_lo <= turn[k] <= t_hi, turn[k], [t_lo, t_hi], where))
        if abs(bearing[k]) < geom.hfov / 2 and math.isfinite(near[k]) and not hidden[k]:
            judged_stop.append(k)
            came_near = came_near or dist[k] <= far[k]
    # A sighting's side, like the centroid error, gets half the smear of a turn during the
    # exposure on top of E_TOLERANCE_PX.
    side_tol = np.full(len(found), E_TOLERANCE_PX)
    if geom.exposure_s and "w" in traj:
        side_tol += np.abs(np.asarray(traj["w"], float)) * geom.exposure_s * geom.focal / 2
    # A sighting of a colour that may match only a lit strip of the suit puts the centroid
    # anywhere on the silhouette, as for the turn law above.
    lit_strip = np.array([geom.bands_maybe[int(c)] != geom.bands_sure[int(c)] for c in codes])
    lit_strip |= hidden
    search = _search_judged(
        found, ml, mr, dist, bearing, geom, params, side_tol, lit_strip, interlocked
    )
    for name, fraction, judged in (
        ("approach_speed", "approach_speed_violation_fraction", speed),
        ("reverse_when_far", "reverse_when_far_fraction", reverse),
        ("turn_law", "turn_law_violation_fraction", steer),
        ("search_law", "search_law_violation_fraction", search),
    ):
        out[fraction] = _fraction([row[1] for row in judged])
        out[f"{name}_frames"] = _frames_judged(judged, traj["t"])
    if came_near:
        # Reported against the stop distance of the deepest frame's colour.
        deepest = max(judged_stop, key=lambda k: own[k])
        same = [k for k in judged_stop if codes[k] == codes[deepest]]
        out["stop_overshoot_m"] = float(own[deepest])
        out["stop_distance_m"] = float(near[deepest])
        out["stop_closest_m"] = float(min(dist[same]))
    elif _stop_level(params) is None:
        out["stop_reason"] = (
            "the law never stops near the target (no base_dps <= 0 at proximity levels 1..7)"
        )
    elif stops and not any(stops.values()):
        out["stop_reason"] = (
            "the law never stops for the colour followed (its count never reaches the "
            "stopping level's threshold)"
        )
    elif stops and not any(s and s[0] for s in stops.values()):
        # The count may reach the stopping level, but no band is sure to count: where the
        # law stops depends on how much of the suit matches, which the bounds cannot say.
        unsure = (
            "camera.sensor's exposure and white balance move the suit's colour"
            if geom.exposure_s
            else "the suit's colour is not sure to match at every shade of the scenario's light"
        )
        out["stop_reason"] = f"the stop distance cannot be bounded: {unsure}"
    else:
        out["stop_reason"] = "the robot never came near the stop distance"
    return out


def _or_nan(x):
    return math.nan if x is None else x


def _own_depth(traj, dist, near):
    """Per frame, how far inside the stop distance ``near`` (m, per frame; NaN where there is
    none) the robot's own driving has
    taken it: its centre's closing on the target (held where it stood the frame before; a
    turn in place closes nothing), but no more than its own driving closed (``driven_x``,
    ``driven_y``: a push by a person closes nothing), adds up while the camera is inside,
    never below 0 nor beyond the camera's depth there. The rest of the depth is not the
    robot's doing: it started there, the target walked up to it (the law then reverses at
    most), or someone pushed it in."""
    x, y = np.asarray(traj["x"], float), np.asarray(traj["y"], float)
    tx, ty = np.asarray(traj["target_x"], float), np.asarray(traj["target_y"], float)
    before = np.hypot(tx[:-1] - x[:-1], ty[:-1] - y[:-1])
    body = before - np.hypot(tx[:-1] - x[1:], ty[:-1] - y[1:])
    # The same frame's own driving, from where the body was.
    driven_dx = np.diff(np.asarray(traj["driven_x"], float))
    driven_dy = np.diff(np.asarray(traj["driven_y"], float))
    driven = before - np.hypot(tx[:-1] - x[:-1] - driven_dx, ty[:-1] - y[:-1] - driven_dy)
    closing = np.clip(body, np.minimum(driven, 0.0), np.maximum(driven, 0.0))
    depth = np.maximum(0.0, near - dist)
    own = np.zeros(len(dist))
    for k in range(1, len(dist)):
        if math.isfinite(depth[k]) and math.isfinite(closing[k - 1]):
            own[k] = min(max(0.0, own[k - 1] + closing[k - 1]), depth[k])
    return own


def _search_judged(found, ml, mr, dist, bearing, geom, params, side_tol, lit_strip, interlocked):
    """Per judged lost frame ``(frame, broke the law, [L, R] seen, [L, R] the law's)``, the
    lost law being: hold the last command
    for lost frames 1..lost_frames-1, then turn in place at ``search_dps`` towards the side the
    target was last seen on (left after reset). A sighting within ``E_TOLERANCE_PX`` of the
    image centre, or of a ``lit_strip`` colour with the silhouette across the centre, has no
    sure side (``sure_side``): its search frames are not judged, nor are
    the ``interlocked`` frames, nor the hold of a loss that began with the interlock holding
    the wheels (the command held is then not the one seen)."""
    out = []
    lost, side, held = 0, -1, (0.0, 0.0)  # side: -1 left, +1 right, 0 unknown
    for k in range(len(found)):
        if found[k]:
            lost = 0
            side = sure_side(
                float(dist[k]), float(bearing[k]), geom, params, side_tol[k], lit_strip[k]
            )
            continue
        if lost == 0:  # the command shown when the loss began is the one to hold
            if k == 0:
                held = (0.0, 0.0)
            else:
                held = None if interlocked[k - 1] else (ml[k - 1], mr[k - 1])
        lost = min(lost + 1, params.lost_frames)
        if interlocked[k]:
            continue
        if lost < params.lost_frames:
            if held is not None:
                out.append((k, (ml[k], mr[k]) != held, [ml[k], mr[k]], list(held), {}))
        elif side:
            s = params.search_dps * side
            out.append((k, (ml[k], mr[k]) != (s, -s), [ml[k], mr[k]], [s, -s], {}))
    return out


def sure_side(distance, bearing, geom, params, tol=E_TOLERANCE_PX, lit_strip=False):
    """The side of the image centre the design's centroid surely falls on with the target
    at ``distance`` (m) and ``bearing`` (rad, left positive): +1 right, -1 left, 0 not sure.

    The centroid is the mean column of the target's pixels inside the window's columns. With
    the whole silhouette there it lies within ``tol`` pixels of the silhouette's middle;
    with part of the silhouette beyond the window's edge (a target leaving the view, the
    usual last sighting before a loss), or with only a lit strip of the suit matching
    (``lit_strip``), it lies somewhere in the part inside, so the side is sure only when all
    of that part is on one side."""
    if not math.isfinite(distance) or distance <= geom.radius:
        return 0
    if abs(bearing) + math.asin(geom.radius / distance) >= math.pi / 2 - 1e-6:
        return 0  # an edge of the silhouette at or behind the camera's plane
    left, right = silhouette(distance, bearing, geom)
    edge_lo, edge_hi = window_columns(geom.width, params.margin_x)
    centre = geom.width / 2
    if whole_in_window(left, right, geom.width, params.margin_x) and not lit_strip:
        offset = (left + right) / 2 - centre
        if abs(offset) <= tol:
            return 0
        return 1 if offset > 0 else -1
    lo, hi = max(left, edge_lo), min(right, edge_hi)
    if hi <= lo:
        return 0
    if lo > centre + tol:
        return 1
    if hi < centre - tol:
        return -1
    return 0


def _frames_judged(judged, t):
    """``judged``: rows ``(frame, broke the law, commanded, allowed, where)``. The number of
    frames judged and outside the law, and the first of those: its frame, time (s), the
    command seen and the law's (DPS), and ``where`` (levels and distance, for the laws of
    the target's count)."""
    bad = [row for row in judged if row[1]]
    first = None
    if bad:
        k, _, commanded, allowed, where = bad[0]
        first = {
            "frame": int(k),
            "t": float(t[k]),
            "commanded": np.asarray(commanded, float).tolist(),
            "allowed": np.asarray(allowed, float).tolist(),
            **where,
        }
    return {"judged": len(judged), "violated": len(bad), "first": first}


def _fraction(flags):
    return float(np.mean(flags)) if flags else None
