"""Further cameras in the viewer (``[[robot.sensors]]`` cameras, ``FrameRecord.cameras``):
each camera's latest image at ``cameras/<name>`` (one panel each beside the body camera's)
and its field of view on the map at ``map/cameras/<name>``, turned with the servo it is on.

Entities appear with the first record that has them; the recorder then lays out a panel
for each.
"""

import math

import rerun as rr

from .columns import jpegs, pngs, rgb_images, strips
from .images import encode_frame

__all__ = ["CAMERAS", "MAP_CAMERAS", "CameraPanels"]

CAMERAS = "cameras"
MAP_CAMERAS = "map/cameras"
_FOV_COLOR = (120, 200, 255)
_BUILDERS = {"raw": rgb_images, "png": pngs, "jpeg": jpegs}


class CameraPanels:
    """Adds each record's further cameras to the recorder's column buffer."""

    def __init__(self, stream, columns):
        self._stream = stream
        self._columns = columns
        self.names = []  # cameras seen, in first-seen order (the layout's panels)

    def log(self, record, add, *, images, jpeg_quality, reach):
        """``images``: this frame logs camera images (``log_every``); ``reach``: the map's
        field-of-view length, m."""
        for name, view in (getattr(record, "cameras", None) or {}).items():
            if name not in self.names:
                self.names.append(name)
                fov = f"{MAP_CAMERAS}/{name}"
                self._columns.register(fov, strips)
                self._stream.log(
                    fov, rr.LineStrips2D.from_fields(colors=_FOV_COLOR, radii=0.008), static=True
                )
            if images:
                kind, data = encode_frame(view.rgb, jpeg_quality)
                key = (f"{CAMERAS}/{name}", kind)
                self._columns.register(key, _BUILDERS[kind])
                add(key, data)
            p, half = view.pose, 0.5 * float(view.hfov)
            x, y = float(p.x), -float(p.y)  # the map's y is flipped (viz.paths)
            left = (x + reach * math.cos(p.heading + half), y - reach * math.sin(p.heading + half))
            right = (x + reach * math.cos(p.heading - half), y - reach * math.sin(p.heading - half))
            add(f"{MAP_CAMERAS}/{name}", (left, (x, y), right))
