"""Seeded buggy variants of the sensor designs, each meant to fail one named closed-loop check.

A variant is a change of one parameter object (plain Python, no Amaranth import): the
gateware and the Python models both read the changed field, so the model predicts the
variant's wrong output exactly (the unit tests show it on hand-built inputs).
``variant_params(name, base)`` applies a variant to the parameters it changes.
"""

from collections.abc import Callable
from dataclasses import dataclass

from .errors import ParamError
from .lidar_params import CorridorParams
from .sensor_params import FollowLineParams, InterlockParams, UltrasoundParams
from .turret_params import TurretParams

__all__ = ["VARIANTS", "Variant", "variant_params"]


@dataclass(frozen=True)
class Variant:
    name: str
    #: The top the variant belongs to ("follow_line", "follow_target_safe").
    design: str
    #: The parameter class it changes.
    params_type: type
    #: ``changes(base) -> {field: value}``.
    changes: Callable
    #: One line: the bug.
    bug: str
    #: One line: the closed-loop check it should fail, and why.
    fails: str


VARIANTS = {
    v.name: v
    for v in (
        Variant(
            name="line_inverted_polarity",
            design="follow_line",
            params_type=FollowLineParams,
            changes=lambda p: {"active_high": False},
            bug="reads the KY-033 output with the wrong polarity (line = low): every sensor over "
            "the bright floor counts as on the line",
            fails="line_track: time off the line (and laps completed): the robot steers away from "
            "the line as soon as a sensor crosses it",
        ),
        Variant(
            name="us_echo_inverted",
            design="follow_target_safe",
            params_type=UltrasoundParams,
            changes=lambda p: {"echo_active_high": False},
            bug="ECHO read with the wrong polarity: the driver times the gap after the echo "
            "instead of the echo, which outlasts the longest range, so every measurement is "
            "no_echo",
            fails="obstacle_between: no contact with the box (max_furniture_collisions): the "
            "interlock never sees the box and the robot drives into it",
        ),
        Variant(
            name="us_echo_counter_narrow",
            design="follow_target_safe",
            params_type=UltrasoundParams,
            changes=lambda p: {"echo_bits": p.full_echo_bits - 1},
            bug="echo counter one bit too narrow: echoes of 2**(bits-1) cycles or more wrap (at "
            "50 MHz surfaces 3.60-4.00 m away read 0-404 mm) and the 38 ms time-out pulse "
            "reads 2920 mm instead of no echo",
            fails="obstacle_between: following resumes when the box is gone: with the box gone, a "
            "wall 3.60-3.89 m ahead reads below stop_mm (300 mm) and holds the wheels at 0",
        ),
        Variant(
            name="interlock_latches",
            design="follow_target_safe",
            params_type=InterlockParams,
            changes=lambda p: {"release_on_far": False},
            bug="the interlock's release is 'no echo AND far' instead of 'no echo OR far': once "
            "stopped, only an empty view (no echo at all) releases the wheels",
            fails="obstacle_between: following resumes when the box is gone: the person (or any "
            "surface within 4 m) keeps answering, so the robot never moves again",
        ),
        Variant(
            name="lidar_bearing_mirrored",
            design="corridor_follow",
            params_type=CorridorParams,
            changes=lambda p: {"clockwise": False},
            bug="reads the RPLIDAR's bearings counter-clockwise (they are clockwise): a wall on "
            "the right looks like one on the left",
            fails="corridor: no contact with the walls (max_wall_collisions): the robot steers "
            "towards the nearer wall instead of away from it",
        ),
        Variant(
            name="turret_pan_inverted",
            design="turret_tracker",
            params_type=TurretParams,
            changes=lambda p: {"inverted": True},
            bug="the pan law's sign is flipped: a target right of the image centre turns the "
            "camera left, away from it",
            fails="turret: the pan camera's target centred (camera_target_centred_min_fraction): "
            "the camera turns away until the target leaves its view or the servo its range",
        ),
    )
}


def variant_params(name, base=None):
    """``base`` (default: the class's defaults) with variant ``name`` applied; an unknown
    name is a ``ValueError`` listing the known ones."""
    if name not in VARIANTS:
        raise ParamError(f"unknown variant {name!r}; known variants: {', '.join(VARIANTS)}")
    variant = VARIANTS[name]
    base = variant.params_type() if base is None else base
    if not isinstance(base, variant.params_type):
        raise TypeError(
            f"variant {name} changes a {variant.params_type.__name__}, not {type(base).__name__}"
        )
    return base.replace(**variant.changes(base))
