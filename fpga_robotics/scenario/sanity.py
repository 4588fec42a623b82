"""A loaded scenario's warnings: legal values that make a run meaningless.

The world's placements (``sim.world.sanity``) and the checks that no run can meet (or that
every run meets) by construction, decided from the file alone. ``run`` and ``sweep`` print
them before they start; with ``--strict`` they are usage errors.
"""

import math

from fpga_robotics.sim.world.config import start_name
from fpga_robotics.sim.world.sanity import world_warnings

__all__ = ["report_warnings", "scenario_warnings"]

#: Checks on the robot-to-target distance or view: without a target person they fail.
_TARGET_CHECKS = ("mean_distance_max_m", "min_distance_min_m", "target_in_view_min_fraction")

#: Bodies pressed together overlap by at most pymunk's collision slop (1 mm): a distance
#: limit this far inside the touching distance is decided by construction, m.
_OVERLAP = 0.01


def _check_warnings(world, checks):
    target = next((p for p in world.people if p.target), None)
    out = []
    for key in _TARGET_CHECKS:
        if (
            key in checks
            and target is None
            and not (key == "target_in_view_min_fraction" and checks[key] == 0)
        ):
            out.append(
                f"checks.{key} = {checks[key]:g} needs a target person "
                f"(people[].target = true); the scenario has none: it always fails"
            )
    if target is None:
        return out
    robot_r = world.robot.spec.body_radius
    touch = robot_r + target.radius  # centres never come closer: the bodies are solid
    room = world.room
    farthest = math.hypot(room.width - touch, room.depth - touch)
    limit = checks.get("mean_distance_max_m")
    if limit is not None and limit < touch - _OVERLAP:
        out.append(
            f"checks.mean_distance_max_m = {limit:g} m is below {touch:.3f} m, the "
            f"robot's and the target's centres when they touch: it always fails"
        )
    limit = checks.get("min_distance_min_m")
    if limit is not None and limit < touch - _OVERLAP:
        out.append(
            f"checks.min_distance_min_m = {limit:g} m is below {touch:.3f} m, the "
            f"robot's and the target's centres when they touch: it always passes "
            f"(use max_person_collisions for contact)"
        )
    elif limit is not None and limit > farthest:
        out.append(
            f"checks.min_distance_min_m = {limit:g} m is beyond {farthest:.2f} m, the "
            f"farthest the centres can be apart in the room: it always fails"
        )
    elif limit is not None and limit > (
        start_gap := math.dist(world.robot.start, target.waypoints[0])
    ):
        # Frame 0's distance is fixed by the file: the target stands at its first waypoint.
        out.append(
            f"checks.min_distance_min_m = {limit:g} m is beyond {start_gap:.2f} m, the "
            f"target's first waypoint from {start_name(world.robot.default_start)}: it always "
            "fails"
        )
    return out


def scenario_warnings(world, checks):
    """One line per problem of a scenario: ``world`` a parsed ``WorldConfig``, ``checks``
    its ``[checks]`` table."""
    return world_warnings(world) + _check_warnings(world, checks)


def report_warnings(scenario, strict, stream, error):
    """Print the scenario's warnings on ``stream`` (``warning: ...``); with ``strict`` raise
    ``error`` (an exception class) with the first one instead."""
    warnings = scenario.warnings
    if strict and warnings:
        more = f" (and {len(warnings) - 1} more)" if len(warnings) > 1 else ""
        raise error(f"scenario {scenario.name!r}: {warnings[0]}{more} (--strict)")
    for line in warnings:
        print(f"warning: scenario {scenario.name!r}: {line}", file=stream)
