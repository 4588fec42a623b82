"""Entity paths of a recording (the names a user sees in the viewer and a reader looks up).

The map is drawn in the viewer's 2D coordinates: x = world x, y = -world y (rerun's 2D y axis
points down), so the top-down view is not mirrored.
"""

CAMERA_RAW = "camera/raw"
CAMERA_FILTERED = "camera/filtered"
LEDS_PROXIMITY = "leds/proximity"
LEDS_CENTROID = "leds/centroid"
DESIGN_CENTROID_X = "design/centroid_x"
DESIGN_TRACKING = "design/tracking"  # [found, proximity]
MOTORS_DPS = "motors/dps"  # [left, right]
TWIST_V = "twist/v"  # [commanded, measured]
TWIST_W = "twist/w"  # [commanded, measured]
TARGET_DISTANCE = "target/distance"
EVENTS = "events"

# A shadow design's outputs (``run --shadow``), beside the primary design's.
SHADOW_LEDS_PROXIMITY = "shadow/leds/proximity"
SHADOW_LEDS_CENTROID = "shadow/leds/centroid"
SHADOW_MOTORS_DPS = "motors/shadow_dps"  # [left, right]; under "motors" to share the plot
MOTORS = "motors"

MAP = "map"
MAP_WALLS = "map/walls"
MAP_FURNITURE = "map/furniture"
MAP_TERRAIN = "map/terrain"
MAP_ROBOT = "map/robot"
MAP_FOV = "map/fov"
MAP_PEOPLE = "map/people"
TRAIL_ROBOT = "map/trails/robot"
TRAIL_TARGET = "map/trails/target"
TRAILS = "map/trails"  # + "/<name>": a whole path drawn at once (Recorder.log_trail)

#: Series names of the multi-valued scalar entities, in logged order.
SERIES = {
    DESIGN_TRACKING: ("found", "proximity"),
    MOTORS_DPS: ("left", "right"),
    SHADOW_MOTORS_DPS: ("shadow left", "shadow right"),
    TWIST_V: ("commanded", "measured"),
    TWIST_W: ("commanded", "measured"),
    DESIGN_CENTROID_X: ("centroid_x",),
    TARGET_DISTANCE: ("distance",),
}
