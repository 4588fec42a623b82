"""The connectors in the viewer (real-clock runs): what each sensor measured and what the
design saw at its pins, on the frames' timeline, and where the sensors are on the map.

- ``sensors/<name>/<key>``: one series per measurement (an ultrasound's ``echo_edges`` in
  design clock cycles and ``echo_m`` in metres, a line sensor's bits ...);
- ``design/extra/<output>``: the design's outputs beyond FollowTarget's (``distance_mm``,
  ``obstacle``, ``line_seen``); ``design/shadow_extra/<output>`` a shadow design's
  (``run --shadow REF``);
- ``map/sensors/<name>``: the sensors' points (bright when their state is 1: over a line,
  pressed) and rays (an ultrasound's measured range from the sensor);
- ``map/lines``: the floor markings, drawn once with the map.

Entities appear with the first record that has them; the recorder then adds a Sensors tab.
"""

import rerun as rr

from .columns import points, scalars, strips

__all__ = [
    "DESIGN_EXTRA",
    "MAP_LINES",
    "MAP_SENSORS",
    "SENSORS",
    "SHADOW_EXTRA",
    "SensorViews",
    "line_strips",
]

SENSORS = "sensors"
DESIGN_EXTRA = "design/extra"
SHADOW_EXTRA = "design/shadow_extra"
MAP_SENSORS = "map/sensors"
MAP_LINES = "map/lines"

_ON_COLOR = (255, 255, 255)
_OFF_COLOR = (90, 90, 110)
_RAY_COLOR = (120, 255, 160)
#: Floor markings darker than this (0..255 luminance) are drawn light on the dark map.
_DARK = 80
_LIGHT_TAPE = (230, 230, 230)


def line_strips(world_map):
    """``(strips, radii, colors)`` of the map's floor markings (``WorldMap.lines``)."""
    lines = list(getattr(world_map, "lines", ()) or ())
    colors = []
    for color in getattr(world_map, "line_colors", ()) or ():
        r, g, b = (int(c) for c in color)
        dark = 0.299 * r + 0.587 * g + 0.114 * b < _DARK
        colors.append(_LIGHT_TAPE if dark else (r, g, b))
    radii = [w / 2 for w in getattr(world_map, "line_widths", ()) or ()]
    return [[(float(x), -float(y)) for x, y in line] for line in lines], radii, colors


class SensorViews:
    """Adds the sensor rows of each ``FrameRecord`` to the recorder's column buffer."""

    def __init__(self, stream, columns):
        self._stream = stream
        self._columns = columns
        self.seen = False  # any sensor or extra output logged (the layout needs the tab)
        self.series = []  # entity paths of the series, in first-seen order

    def _series(self, path, name):
        if self._columns.register(path, scalars):
            self._stream.log(path, rr.SeriesLines(names=[name]), static=True)
            self.series.append(path)

    def log(self, record, add):
        for root, extra in (
            (DESIGN_EXTRA, getattr(record, "design_extra", None)),
            (SHADOW_EXTRA, getattr(record, "shadow_extra", None)),
        ):
            for name, value in (extra or {}).items():
                path = f"{root}/{name}"
                self._series(path, name)
                add(path, (float(value),))
                self.seen = True
        for name, reading in (getattr(record, "sensors", None) or {}).items():
            self.seen = True
            for key, value in reading.values.items():
                path = f"{SENSORS}/{name}/{key}"
                self._series(path, key)
                add(path, (float("nan") if value is None else float(value),))
            if reading.points:
                path = f"{MAP_SENSORS}/{name}/points"
                self._columns.register(path, points)
                states = reading.states or (0,) * len(reading.points)
                add(
                    path,
                    (
                        [(float(x), -float(y)) for x, y in reading.points],
                        [0.012] * len(reading.points),
                        [_ON_COLOR if s else _OFF_COLOR for s in states],
                        [""] * len(reading.points),
                    ),
                )
            if reading.rays:
                path = f"{MAP_SENSORS}/{name}/ray"
                if self._columns.register(path, strips):
                    self._stream.log(
                        path,
                        rr.LineStrips2D.from_fields(colors=_RAY_COLOR, radii=0.008),
                        static=True,
                    )
                (x0, y0), (x1, y1) = reading.rays[0]
                add(path, ((float(x0), -float(y0)), (float(x1), -float(y1))))
