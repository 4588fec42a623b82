"""The display connector: log every ``FrameRecord`` of a closed-loop run to rerun.

One ``Recorder`` owns one ``rerun.RecordingStream`` (never the global one), so several runs in
one process stay apart. Timelines: ``frame`` (sequence, the frame index) and ``sim_time``
(duration, simulated seconds); rerun's wall-clock ``log_time`` is left out so a recording
depends only on the run.

What is logged per frame (entity paths in ``viz.paths``):

- every ``log_every``-th frame (``frame % log_every == 0``): the camera frame (by default as
  the design receives it, RGB444; ``camera="rgb888"``: the full 8-bit render) and the design's
  filtered frame, PNG (lossless) up to 160x120 and JPEG above (``jpeg_quality``);
- every frame: the LEDs (small images), the scalar series (found, proximity, centroid_x,
  DPS, V, W, target distance), the robot, field of view, people and trails on the map, and
  the frame's events. They are small, and decimating them would hide short events.

An output the design lacks (None in its ``FrameResult``: a foreign design whose port map does
not name it) is absent in the viewer, never drawn as 0: no LEDs or filtered image for it, a gap
in its series.
"""

import math
import weakref

import rerun as rr

from . import paths as P
from .blueprint import default_blueprint
from .cameras import CameraPanels
from .columns import (
    FILE_ONLY,
    MAX_SECONDS,
    ColumnBuffer,
    arrows,
    images,
    jpegs,
    pngs,
    points,
    rgb_images,
    scalars,
    strips,
    time_ns,
)
from .errors import ViewerError
from .frame_calls import FrameCalls, signals_held
from .images import (
    as_received,
    check_camera_format,
    check_jpeg_quality,
    encode_frame,
    encode_rgb444,
)
from .leds import centroid_image, proximity_image
from .lidar import log_scans_3d
from .modes import parse_mode
from .outcome import settle
from .sensors import MAP_LINES, SensorViews, line_strips
from .sinks import open_output
from .world3d import World3D

__all__ = ["Recorder", "open_recorder"]

_WALL_COLOR = (200, 200, 200)
_ROBOT_COLOR = (60, 160, 255)
_FOV_COLOR = (255, 220, 60)
_TARGET_COLOR = (255, 70, 70)
_PERSON_COLOR = (170, 170, 190)
_TRAIL_ROBOT_COLOR = (60, 160, 255)
_TRAIL_TARGET_COLOR = (255, 110, 110)
_TRAIL_OTHER_COLOR = (200, 120, 255)
_SERIES_COLORS = {
    P.DESIGN_TRACKING: [(80, 220, 80), (255, 170, 30)],
    P.MOTORS_DPS: [(80, 170, 255), (255, 120, 80)],
    P.SHADOW_MOTORS_DPS: [(40, 90, 150), (150, 70, 40)],
    P.TWIST_V: [(160, 160, 160), (80, 200, 255)],
    P.TWIST_W: [(160, 160, 160), (80, 200, 255)],
    P.DESIGN_CENTROID_X: [(255, 220, 60)],
    P.TARGET_DISTANCE: [(255, 110, 110)],
}
_COLUMN_BUILDERS = {
    (P.CAMERA_RAW, "raw"): rgb_images,
    (P.CAMERA_RAW, "png"): pngs,
    (P.CAMERA_RAW, "jpeg"): jpegs,
    (P.CAMERA_FILTERED, "raw"): rgb_images,
    (P.CAMERA_FILTERED, "png"): pngs,
    (P.CAMERA_FILTERED, "jpeg"): jpegs,
    P.LEDS_PROXIMITY: images,
    P.LEDS_CENTROID: images,
    P.DESIGN_TRACKING: scalars,
    P.DESIGN_CENTROID_X: scalars,
    P.MOTORS_DPS: scalars,
    P.SHADOW_LEDS_PROXIMITY: images,
    P.SHADOW_LEDS_CENTROID: images,
    P.SHADOW_MOTORS_DPS: scalars,
    P.TWIST_V: scalars,
    P.TWIST_W: scalars,
    P.TARGET_DISTANCE: scalars,
    P.MAP_ROBOT: arrows,
    P.MAP_FOV: strips,
    P.MAP_PEOPLE: points,
    P.TRAIL_ROBOT: strips,
    P.TRAIL_TARGET: strips,
}
_DEFAULT_RAY = 1.0  # length of the field-of-view rays when no world map gave a scale, m


def _close_abandoned(columns, output, stream):
    try:
        columns.flush()
    finally:
        output.close_abandoned(stream)


def _check_log_every(n):
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ViewerError(f"log_every must be an integer >= 1, got {n!r}")
    return n


def _xy(x, y):
    # World (y up) to the viewer's 2D coordinates (y down).
    return (float(x), -float(y))


def _series(value):
    """A design output as a series value: NaN (a gap in the plot) when the design lacks it."""
    return float("nan") if value is None else float(value)


def _event_level(text):
    """Collisions and a tipped robot stand out in the event log (WARN); the rest is INFO."""
    text = text.lower()
    return (
        rr.TextLogLevel.WARN
        if "collision" in text or text.startswith("tipped over")
        else rr.TextLogLevel.INFO
    )


class Recorder:
    """Logs a run's world map and frames to one rerun sink; see ``open_recorder``.

    Attributes
    ----------
    mode : str
        The sink actually in use: ``save``, ``spawn``, ``connect``, ``serve`` or ``off``.
    path : str or None
        The ``.rrd`` file: for ``save`` from the start; for the live modes after ``close()``,
        when a copy was kept.
    notices : list of str
        Every line the user must be told, in order: when opening (where a served run can be
        watched, why a file is used instead of a viewer) and when closing (where the
        recording is). ``pop_notices()`` returns those not taken yet. Nothing is printed.
    delivered : bool or None
        After ``close()`` of ``spawn``/``connect``: whether rerun confirmed every message sent.
    frames_logged, images_logged : int
        ``log_frame`` calls, and how many of them logged the camera images.
    viewer_pid : int or None
        The viewer process ``spawn`` started (it outlives the run), if any.
    live_url, web_url : str or None
        The gRPC URL streamed to or served (``rerun URL`` opens it) and, for ``serve``, the
        web viewer's address.
    """

    def __init__(self, stream, output, *, log_every=1, jpeg_quality=None, camera="rgb444"):
        self._stream = stream
        self._output = output
        self.mode = output.kind if output is not None else "off"
        file = output.file if output is not None else None
        self.path = str(file.path) if file is not None and self.mode == "save" else None
        self.notice = output.reason if output is not None else None
        self.log_every = log_every
        self.jpeg_quality = jpeg_quality
        self.camera = camera
        self.frames_logged = 0
        self.images_logged = 0
        self._open_frame = None  # the frame log_frame is adding rows of
        self.delivered = None
        self.viewer_pid = output.viewer_pid if output is not None else None
        self.live_url = output.live_url if output is not None else None
        self.web_url = output.web_url if output is not None else None
        self.notices = list(output.opening) if output is not None else []
        self._told = 0
        self._closed = False
        self._message = None
        self._ray = _DEFAULT_RAY
        self._blueprint_sent = False
        self._bounds = None  # the map's, kept for a blueprint sent again
        self._world_map = False  # a world to draw on the map: log_world_map tells
        self._shadow_seen = False  # a shadow design's first frame re-lays out the board
        self._world3d = None  # viz.world3d.World3D, made at the first record with a scene
        self._layout_stale = False  # the layout sent lacks a view that is now needed
        self._sensor_series = 0  # sensor series in the layout sent (viz.sensors)
        self._camera_panels = 0  # further cameras in the layout sent (viz.cameras)
        # Whether the design has a filtered image or LEDs (follow_line has neither): the
        # first frame tells.
        self._frame_outputs = True
        self._camera_input = True  # the design takes the camera's frames: the first frame tells
        self._first_frame_seen = False
        self._last_robot = None
        self._last_target = None
        if stream is not None:
            self._guard = output.guard()
            # A file alone is sent in longer columns: a smaller file (viz.columns).
            frames, seconds = FILE_ONLY if self.mode == "save" else (None, MAX_SECONDS)
            self._columns = ColumnBuffer(
                stream, _COLUMN_BUILDERS, self._guard, max_frames=frames, max_seconds=seconds
            )
            self._sensors = SensorViews(stream, self._columns)
            self._cameras = CameraPanels(stream, self._columns)
            # Never closed (dropped, or open at exit): the file still gets its real name.
            self._abandoned = weakref.finalize(
                self, _close_abandoned, self._columns, output, stream
            )
            with self._guard:
                self._log_static_styles()

    def pop_notices(self):
        """The lines for the user not taken yet; the caller prints them, the library never does."""
        new = self.notices[self._told :]
        self._told = len(self.notices)
        return new

    def _check_open(self):
        if self._closed:
            raise RuntimeError("this recorder is closed; open a new one with open_recorder")

    # Setup -------------------------------------------------------------------------------------

    def _log_static_styles(self, shadow=False):
        """Series names and colours, LED image formats: of the primary design's entities, or
        (``shadow``) of a shadow design's, logged when its first frame comes."""
        log = self._stream.log
        shadow_paths = (P.SHADOW_MOTORS_DPS, P.SHADOW_LEDS_PROXIMITY, P.SHADOW_LEDS_CENTROID)
        for path, names in P.SERIES.items():
            if (path in shadow_paths) == shadow:
                log(
                    path,
                    rr.SeriesLines(names=list(names), colors=_SERIES_COLORS[path]),
                    static=True,
                )
        leds = (
            (P.SHADOW_LEDS_PROXIMITY, P.SHADOW_LEDS_CENTROID)
            if shadow
            else (P.LEDS_PROXIMITY, P.LEDS_CENTROID)
        )
        for path, img in (
            (leds[0], proximity_image(0)),
            (leds[1], centroid_image(0)),
        ):
            fmt = rr.components.ImageFormat(
                width=img.shape[1], height=img.shape[0], color_model="RGB", channel_datatype="U8"
            )
            log(path, rr.Image.from_fields(format=fmt), static=True)

    def _send_blueprint(self, bounds=None, shadow=False):
        if bounds is not None:
            self._bounds = bounds
        with self._guard:
            self._stream.send_blueprint(
                default_blueprint(
                    self._bounds,
                    shadow=shadow,
                    world3d=self._world3d is not None,
                    sensors=tuple(self._sensors.series),
                    frame_outputs=self._frame_outputs,
                    camera=self.camera if self._camera_input else None,
                    cameras=tuple(self._cameras.names),
                    wall_height=0.0 if self._world3d is None else self._world3d.wall_height,
                    world_map=self._world_map,
                )
            )
        self._sensor_series = len(self._sensors.series)
        self._camera_panels = len(self._cameras.names)
        self._layout_stale = False
        self._blueprint_sent = True

    def log_world_map(self, world_map):
        """Draw the static geometry (walls, furniture) and frame the map view on its bounds."""
        self._check_open()
        if self._stream is None:
            return
        with self._guard:
            self._log_map_geometry(world_map)
        xmin, ymin, xmax, ymax = world_map.bounds
        self._world_map = True
        self._ray = 0.25 * max(xmax - xmin, ymax - ymin)
        self._send_blueprint(world_map.bounds)

    def _log_map_geometry(self, world_map):
        log = self._stream.log
        log(P.MAP_ROBOT, rr.Arrows2D.from_fields(colors=_ROBOT_COLOR, radii=0.03), static=True)
        log(P.MAP_FOV, rr.LineStrips2D.from_fields(colors=_FOV_COLOR, radii=0.01), static=True)
        for path, color in (
            (P.TRAIL_ROBOT, _TRAIL_ROBOT_COLOR),
            (P.TRAIL_TARGET, _TRAIL_TARGET_COLOR),
        ):
            log(path, rr.LineStrips2D.from_fields(colors=color, radii=0.01), static=True)
        walls = [[_xy(*a), _xy(*b)] for a, b in world_map.walls]
        if walls:
            log(P.MAP_WALLS, rr.LineStrips2D(walls, colors=_WALL_COLOR, radii=0.02), static=True)
        strips_, radii, colors = line_strips(world_map)
        if strips_:  # floor markings (line-following tracks)
            log(MAP_LINES, rr.LineStrips2D(strips_, radii=radii, colors=colors), static=True)
        terrain = [
            [_xy(*p) for p in poly] + [_xy(*poly[0])]
            for poly in getattr(world_map, "terrain", ())
            if poly
        ]
        if terrain:  # floor patches (ramps, wet floor), under the furniture
            log(
                P.MAP_TERRAIN,
                rr.LineStrips2D(
                    terrain, colors=[tuple(c) for c in world_map.terrain_colors], radii=0.01
                ),
                static=True,
            )
        self._log_furniture(world_map, 0, 0.0)

    def _log_furniture(self, world_map, frame, sim_time):
        """The furniture from ``frame`` on: on the timeline, since a piece may leave the room
        during the run (``update_furniture``)."""
        polygons = [
            [_xy(*p) for p in poly] + [_xy(*poly[0])] for poly in world_map.obstacles if poly
        ]
        self._stream.set_time("frame", sequence=frame)
        self._stream.set_time("sim_time", duration=time_ns(sim_time))
        if polygons:
            colors = [tuple(int(c) for c in col) for col in world_map.obstacle_colors]
            self._stream.log(
                P.MAP_FURNITURE, rr.LineStrips2D(polygons, colors=colors or None, radii=0.015)
            )
        else:
            self._stream.log(P.MAP_FURNITURE, rr.Clear(recursive=False))

    def update_furniture(self, world_map, frame, sim_time):
        """The furniture changed (a piece left the room) at ``frame``: draw it anew from then."""
        self._check_open()
        if self._stream is None:
            return
        with self._guard:
            self._log_furniture(world_map, frame, sim_time)

    # Per frame ---------------------------------------------------------------------------------

    def log_frame(self, record):
        """Log one ``FrameRecord`` at its ``frame`` and ``sim_time``."""
        self._check_open()
        if self._stream is None:
            return
        if record.scene is not None and self._world3d is None:
            # The world in 3D (viz.world3d) joins the layout: sent once this frame is logged.
            self._world3d = World3D(self._stream)
            self._layout_stale = True
        if not self._blueprint_sent:
            self._send_blueprint()
        frame = int(record.frame)
        self._open_frame = frame  # until its last row is added (close drops a partial one)
        t = time_ns(record.sim_time)
        res = record.result
        if not self._first_frame_seen:
            self._first_frame_seen = True
            if res.filtered is None and res.proximity is None and res.centroid_leds is None:
                self._frame_outputs = False
                self._layout_stale = True
            if not getattr(record, "camera_input", True):
                self._camera_input = False
                self._layout_stale = True

        def add(path, row):
            self._columns.add(path, frame, t, row)

        if frame % self.log_every == 0:
            q = self.jpeg_quality
            if self.camera == "rgb444":
                kind, data = encode_rgb444(as_received(record.camera_rgb), q)
            else:
                kind, data = encode_frame(record.camera_rgb, q)
            add((P.CAMERA_RAW, kind), data)
            if res.filtered is not None:  # a design without a filtered stream: no image
                kind, data = encode_rgb444(res.filtered, q)
                add((P.CAMERA_FILTERED, kind), data)
        # Calls made straight to the stream wait for the frame's end: a frame cut short by
        # Ctrl-C leaves none of its rows (viz.frame_calls), as the buffered ones are dropped.
        direct = FrameCalls()
        if record.events:
            direct.set_time("frame", sequence=frame)
            direct.set_time("sim_time", duration=t)
            for text in record.events:
                direct.log(P.EVENTS, rr.TextLog(str(text), level=_event_level(str(text))))

        self._add_outputs(res, add, P.LEDS_PROXIMITY, P.LEDS_CENTROID, P.MOTORS_DPS)
        if res.found is not None or res.proximity is not None:
            add(P.DESIGN_TRACKING, (_series(res.found), _series(res.proximity)))
        if res.centroid_x is not None:
            add(P.DESIGN_CENTROID_X, (float(res.centroid_x),))
        if record.shadow_result is not None:
            self._add_shadow(record.shadow_result, add)
        add(P.TWIST_V, (float(record.cmd_v), float(record.robot_v)))
        add(P.TWIST_W, (float(record.cmd_w), float(record.robot_w)))
        if record.target_distance is not None:
            add(P.TARGET_DISTANCE, (float(record.target_distance),))
        if self._world_map:  # real frames (run --source) have no world: a robot at 0, 0
            self._add_map(record, add)
        with self._guard:
            self._sensors.log(record, add)
            self._cameras.log(
                record,
                add,
                images=frame % self.log_every == 0,
                jpeg_quality=self.jpeg_quality,
                reach=self._ray,
                frame=frame,
                t=t,
                camera=self.camera,
                stream=direct,
            )
        if len(self._sensors.series) != self._sensor_series:
            self._layout_stale = True
        if len(self._cameras.names) != self._camera_panels:
            self._layout_stale = True
        if self._world3d is not None and record.scene is not None:
            self._world3d.log_frame(record, frame, t, stream=direct)
            log_scans_3d(direct, record, frame, t)
        if self._layout_stale:
            self._send_blueprint(shadow=self._shadow_seen)
        with signals_held():  # the frame whole, or (Ctrl-C before this) none of it
            if direct:
                with self._guard:
                    direct.replay(self._stream)
            self.frames_logged += 1
            self.images_logged += frame % self.log_every == 0
            self._open_frame = None
        self._columns.end_frame()

    def _add_shadow(self, res, add):
        if not self._shadow_seen:
            self._shadow_seen = True
            with self._guard:
                self._log_static_styles(shadow=True)
            self._send_blueprint(shadow=True)
        self._add_outputs(
            res, add, P.SHADOW_LEDS_PROXIMITY, P.SHADOW_LEDS_CENTROID, P.SHADOW_MOTORS_DPS
        )

    @staticmethod
    def _add_outputs(res, add, proximity_path, centroid_path, motors_path):
        """The LEDs and wheel commands; an output the design lacks (None) is drawn as absent:
        its LEDs not at all, its series with a gap (NaN), never as 0."""
        if res.proximity is not None:
            add(proximity_path, proximity_image(res.proximity))
        if res.centroid_leds is not None:
            add(centroid_path, centroid_image(res.centroid_leds))
        if res.motor_left is not None or res.motor_right is not None:
            add(motors_path, (_series(res.motor_left), _series(res.motor_right)))

    def _add_map(self, record, add):
        x, y = _xy(record.robot_x, record.robot_y)
        h = float(record.robot_heading)
        reach = self._ray
        # Heading (world, counter-clockwise) -> viewer direction (cos h, -sin h).
        c, s = math.cos(h), math.sin(h)
        add(P.MAP_ROBOT, (x, y, 0.4 * reach * c, -0.4 * reach * s))
        # The field of view from the camera on its mount (ahead of the centre, maybe yawed),
        # as the frames and the 3D view see it; from the body without a camera pose.
        pose = record.camera_pose
        (cx, cy), ch = ((x, y), h) if pose is None else (_xy(pose.x, pose.y), float(pose.heading))
        half = 0.5 * float(record.camera_hfov)
        left = (cx + reach * math.cos(ch + half), cy - reach * math.sin(ch + half))
        right = (cx + reach * math.cos(ch - half), cy - reach * math.sin(ch - half))
        add(P.MAP_FOV, (left, (cx, cy), right))

        target = None
        if record.people:
            positions, radii, colors, labels = [], [], [], []
            for person in record.people:
                positions.append(_xy(person.x, person.y))
                radii.append(float(person.radius))
                colors.append(_TARGET_COLOR if person.is_target else _PERSON_COLOR)
                labels.append(str(person.name))
                if person.is_target:
                    target = positions[-1]
            add(P.MAP_PEOPLE, (positions, radii, colors, labels))

        # Trails: one segment per frame; the map view shows all segments up to the cursor.
        pos = (x, y)
        add(P.TRAIL_ROBOT, (self._last_robot or pos, pos))
        self._last_robot = pos
        if target is not None:
            add(P.TRAIL_TARGET, (self._last_target or target, target))
        self._last_target = target

    def log_trail(self, name, x, y):
        """A whole path drawn on the map at once, at ``map/trails/<name>``: the robot's path
        as another design drove it (``run --shadow-continue``)."""
        self._check_open()
        if self._stream is None:
            return
        points = [_xy(a, b) for a, b in zip(x, y, strict=True)]
        with self._guard:
            self._stream.log(
                f"{P.TRAILS}/{name}",
                rr.LineStrips2D([points], colors=_TRAIL_OTHER_COLOR, radii=0.01),
                static=True,
            )

    # End ---------------------------------------------------------------------------------------

    def close(self):
        """Finish the recording; returns the lines the user has not been told yet, joined.

        Every wait is bounded (a viewer that stopped reading costs about 10 s more; the limits
        are in ``viz.live``). A file appears under its final name only now; when this runs
        after Ctrl-C (or anything else raised), what was logged so far is kept all the same.
        Calling ``close`` again returns the same text.
        """
        if self._closed:
            return self._message
        self._closed = True
        if self._stream is not None:
            self._abandoned.detach()
        if self._stream is None:
            self.notices.append("viewer off: nothing was recorded")
        else:
            confirmed, problem = False, "closing was interrupted"
            if self._open_frame is not None:
                self._columns.drop_frame(self._open_frame)
            try:
                self._columns.flush()
                confirmed, problem = self._output.finish(self._stream)
            except BaseException:  # Ctrl-C while closing: still hand over every logged row
                try:
                    self._columns.flush()  # the rows not sent yet are still buffered
                finally:
                    self._output.abort(self._stream)
                raise
            finally:  # even on a second Ctrl-C: the file gets its real name
                self.notices.append(self._settle(confirmed, problem))
        self._message = "\n".join(self.pop_notices())
        return self._message

    def _settle(self, confirmed, problem):
        out = self._output
        line, kept = settle(out, confirmed, problem, self.frames_logged, self.images_logged)
        self.path = str(kept) if kept is not None else None
        if out.kind in ("spawn", "connect"):
            self.delivered = confirmed
        return line

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        # On an error the data logged so far is still saved: it shows what led up to it.
        self.close()
        return False

    def __repr__(self):
        where = self.path or (self._output.description if self._output else "")
        return f"Recorder(mode={self.mode!r}, {where!r}, frames_logged={self.frames_logged})"


def open_recorder(
    mode,
    *,
    default_path,
    app_id="fpga_robotics",
    log_every=1,
    jpeg_quality=None,
    camera="rgb444",
):
    """Open a recorder for ``mode`` (see ``viz.modes``); returns a ``Recorder``.

    Parameters
    ----------
    mode : str or None
        ``save:PATH.rrd``, ``save``, ``spawn``, ``connect``, ``connect:URL``, ``serve``,
        ``serve:ADDRESS``, ``off`` or ``auto``/``None`` (``spawn`` with a display, else
        ``save`` to ``default_path``).
    default_path : str or None
        The ``.rrd`` file for ``save`` without a path, for a live sink that cannot work here,
        and for the copy kept beside a live sink; a new name (``NAME-2.rrd``, ...) is taken
        when it exists. ``None``: no fallback (a live sink that cannot work is an error).
    app_id : str
        rerun application id (the viewer groups recordings and layouts by it).
    log_every : int
        Log the camera images of every ``log_every``-th frame; everything else every frame.
    jpeg_quality : int or None
        ``None`` PNG (lossless) up to 160x120 and JPEG quality 85 above; ``0`` always raw
        (uncompressed, exact); 1..100 always JPEG at that quality.
    camera : str
        ``rgb444`` (default): the camera frame as the design receives it, each channel's top
        four bits (``c >> 4``), shown as ``c << 4`` like the filtered frame; ``rgb888``: the
        full 8-bit render, its low bits (sensor noise the design never sees) included.

    Raises
    ------
    ViewerError
        A malformed mode, ``log_every``, ``jpeg_quality`` or ``camera``; a file that cannot be
        written (checked now, before any frame); a live sink that cannot work with no default
        path.
    """
    parsed = parse_mode(mode, default_path)
    options = {
        "log_every": _check_log_every(log_every),
        "jpeg_quality": check_jpeg_quality(jpeg_quality),
        "camera": check_camera_format(camera),
    }
    if parsed.kind == "off":
        return Recorder(None, None, **options)
    stream, output = open_output(parsed, app_id)
    try:
        return Recorder(stream, output, **options)
    except BaseException:  # e.g. Ctrl-C right now: no recorder to close, so no file either
        try:
            output.abort(stream)
        finally:
            if output.file is not None:
                output.file.discard()
        raise
