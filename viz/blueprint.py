"""The default viewer layout, built from code.

Left, what the board sees and decides (like the paper's GUI): the camera frame and the design's
filtered frame side by side, the proximity and centroid LEDs under them, then the wheels' DPS
and the robot's V and W. Right, the world: the top-down map, and under it the tracker's
outputs and the event log.
"""

import rerun.blueprint as rrb

from . import paths as P
from .cameras import CAMERAS
from .world3d import world3d_view

__all__ = ["default_blueprint"]

_TIMELINE = "sim_time"


def _trail_range():
    # A trail is logged as one segment per frame; show every segment up to the time cursor.
    return rrb.VisibleTimeRanges(
        [
            rrb.VisibleTimeRange(
                timeline,
                start=rrb.TimeRangeBoundary.infinite(),
                end=rrb.TimeRangeBoundary.cursor_relative(),
            )
            for timeline in ("frame", "sim_time")
        ]
    )


_CAMERA_NAMES = {
    "rgb444": "Camera (RGB444, as the design receives it)",
    "rgb888": "Camera (RGB888)",
    None: "Camera (filming the run; not a design input)",
}


def default_blueprint(
    bounds=None,
    shadow=False,
    world3d=False,
    sensors=(),
    frame_outputs=True,
    camera="rgb444",
    cameras=(),
    wall_height=0.0,
    world_map=True,
):
    """The layout sent to the viewer; ``bounds`` ``(xmin, ymin, xmax, ymax)`` frame the map;
    ``camera`` (``rgb444`` or ``rgb888``, how the camera frame is recorded, or None: the
    design takes no camera, which only films the run) names its view;
    ``shadow`` adds a second LED row and the shadow design's wheel speeds; ``world3d`` puts
    the world in 3D (``viz.world3d``) beside the map, its eye over walls ``wall_height``
    high; ``sensors`` (series entity paths, ``viz.sensors``) come first among the plots
    under the map, one tab each; ``cameras`` (further cameras' names, ``viz.cameras``) get a
    panel each beside the camera's; without ``world_map`` (real frames: no world) the map is
    left out."""
    further = [
        rrb.Spatial2DView(origin=f"{CAMERAS}/{name}/image", name=f"Camera {name}")
        for name in cameras
    ]
    map_kwargs = {}
    if bounds is not None:
        xmin, ymin, xmax, ymax = (float(v) for v in bounds)
        pad = 0.05 * max(xmax - xmin, ymax - ymin)
        # The map is drawn with y flipped (the viewer's 2D y axis points down).
        map_kwargs["visual_bounds"] = rrb.VisualBounds2D(
            x_range=[xmin - pad, xmax + pad], y_range=[-ymax - pad, -ymin + pad]
        )
    plots = rrb.Horizontal(
        rrb.TimeSeriesView(
            origin=P.MOTORS if shadow else P.MOTORS_DPS,
            name="Wheel DPS (left, right" + (", shadow" if shadow else "") + ")",
        ),
        rrb.TimeSeriesView(origin=P.TWIST_V, name="V m/s (commanded, measured)"),
        rrb.TimeSeriesView(origin=P.TWIST_W, name="W rad/s (commanded, measured)"),
    )
    if not frame_outputs:
        board = rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial2DView(origin=P.CAMERA_RAW, name=_CAMERA_NAMES[camera]), *further
            )
            if further
            else rrb.Spatial2DView(origin=P.CAMERA_RAW, name=_CAMERA_NAMES[camera]),
            plots,
            row_shares=[4, 3],
            name="Board",
        )
        return _blueprint(board, bounds, map_kwargs, world3d, sensors, wall_height, world_map)
    board = rrb.Vertical(
        rrb.Horizontal(
            rrb.Spatial2DView(origin=P.CAMERA_RAW, name=_CAMERA_NAMES[camera]),
            rrb.Spatial2DView(origin=P.CAMERA_FILTERED, name="Filtered (design output)"),
            *further,
        ),
        rrb.Horizontal(
            rrb.Spatial2DView(origin=P.LEDS_PROXIMITY, name="Proximity LEDs"),
            rrb.Spatial2DView(origin=P.LEDS_CENTROID, name="Centroid LEDs"),
            column_shares=[7, 8],
        ),
        *(
            [
                rrb.Horizontal(
                    rrb.Spatial2DView(
                        origin=P.SHADOW_LEDS_PROXIMITY, name="Shadow design: proximity"
                    ),
                    rrb.Spatial2DView(
                        origin=P.SHADOW_LEDS_CENTROID, name="Shadow design: centroid"
                    ),
                    column_shares=[7, 8],
                )
            ]
            if shadow
            else []
        ),
        plots,
        row_shares=[4, 1, 1, 3] if shadow else [4, 1, 3],
        name="Board",
    )
    return _blueprint(board, bounds, map_kwargs, world3d, sensors, wall_height, world_map)


def _blueprint(board, bounds, map_kwargs, world3d, sensors, wall_height, world_map):
    """The whole layout: ``board`` on the left, the world on the right."""
    outputs = rrb.Horizontal(
        rrb.Tabs(
            *(rrb.TimeSeriesView(origin=path, name=path.split("/", 1)[1]) for path in sensors),
            rrb.TimeSeriesView(origin=P.DESIGN_TRACKING, name="found, proximity"),
            rrb.TimeSeriesView(origin=P.DESIGN_CENTROID_X, name="centroid_x"),
            rrb.TimeSeriesView(origin=P.TARGET_DISTANCE, name="target distance m"),
        ),
        rrb.TextLogView(origin=P.EVENTS, name="Events"),
        name="Outputs",
    )
    if not world_map:  # real frames (run --source): no world to draw
        return _with_panels(rrb.Horizontal(board, outputs, column_shares=[1, 1]))
    top_down = rrb.Spatial2DView(
        origin=P.MAP,
        name="World (top-down)",
        overrides={P.TRAIL_ROBOT: _trail_range(), P.TRAIL_TARGET: _trail_range()},
        **map_kwargs,
    )
    world = rrb.Vertical(
        rrb.Horizontal(top_down, world3d_view(bounds, wall_height)) if world3d else top_down,
        outputs,
        row_shares=[3, 1],
        name="World",
    )
    return _with_panels(rrb.Horizontal(board, world, column_shares=[1, 1]))


def _with_panels(root):
    return rrb.Blueprint(
        root,
        # The views get the room: the blueprint tree and selection panels start collapsed.
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(timeline=_TIMELINE, state="expanded"),
    )
