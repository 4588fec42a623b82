"""Further cameras in the viewer (``[[robot.sensors]]`` cameras, ``FrameRecord.cameras``):
each camera's latest image at ``cameras/<name>/image`` (one panel each beside the body
camera's), its pinhole at ``cameras/<name>`` placed in the world (the 3D view shows the image
on its frustum) and its field of view on the map at ``map/cameras/<name>``, all turned with
the servo it is on.

Entities appear with the first record that has them; the recorder then lays out a panel
for each.
"""

import math

import rerun as rr

from .columns import jpegs, pngs, rgb_images, strips
from .images import as_received, encode_frame, encode_rgb444
from .world3d import camera_rotation

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

    def log(
        self, record, add, *, images, jpeg_quality, reach, frame, t, camera="rgb444", stream=None
    ):
        """``images``: this frame logs camera images (``log_every``); ``reach``: the map's
        field-of-view length, m; ``frame``, ``t``: the record's frame and time (ns);
        ``camera``: how images are recorded, as the body camera's (``rgb444``: as a design
        receives them, ``rgb888``: the render); ``stream``: where the rows not ``add``ed go
        (default the recorder's; ``viz.frame_calls``)."""
        s = self._stream if stream is None else stream
        for name, view in (getattr(record, "cameras", None) or {}).items():
            h, w = view.rgb.shape[:2]
            if name not in self.names:
                self.names.append(name)
                fov = f"{MAP_CAMERAS}/{name}"
                self._columns.register(fov, strips)
                s.log(fov, rr.LineStrips2D.from_fields(colors=_FOV_COLOR, radii=0.008), static=True)
                s.log(
                    f"{CAMERAS}/{name}",
                    rr.Pinhole(
                        focal_length=(w / 2) / math.tan(view.hfov / 2),
                        width=w,
                        height=h,
                        camera_xyz=rr.ViewCoordinates.RDF,
                        image_plane_distance=0.4,
                    ),
                    static=True,
                )
            p = view.pose
            s.set_time("frame", sequence=frame)
            s.set_time("sim_time", duration=t)
            s.log(
                f"{CAMERAS}/{name}",
                rr.Transform3D(
                    translation=(p.x, p.y, p.height), mat3x3=camera_rotation(p.heading, p.tilt)
                ),
            )
            if images:
                if camera == "rgb444":
                    kind, data = encode_rgb444(as_received(view.rgb), jpeg_quality)
                else:
                    kind, data = encode_frame(view.rgb, jpeg_quality)
                key = (f"{CAMERAS}/{name}/image", kind)
                self._columns.register(key, _BUILDERS[kind])
                add(key, data)
            half = 0.5 * float(view.hfov)
            x, y = float(p.x), -float(p.y)  # the map's y is flipped (viz.paths)
            left = (x + reach * math.cos(p.heading + half), y - reach * math.sin(p.heading + half))
            right = (x + reach * math.cos(p.heading - half), y - reach * math.sin(p.heading - half))
            add(f"{MAP_CAMERAS}/{name}", (left, (x, y), right))
