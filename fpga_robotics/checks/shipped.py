"""The checks the project ships, each declared once: the metric it reads, its comparison, the
design outputs it needs, when it cannot judge (its precondition) and what it says."""

from fpga_robotics.checks.check import Check, measured
from fpga_robotics.checks.percent import limit_percent, percent
from fpga_robotics.checks.sensor_metrics import RESUME_CLOSING_M
from fpga_robotics.sim.world.config import MAX_TIME

__all__ = ["SHIPPED_CHECKS"]

_DAY = MAX_TIME  # s
_COUNT = (0, 10**6, "")
_FRACTION = (0, 1, "")
_NO_TARGET = "no target person: no distance to compare"


def _decimals(v, limit, least_digits):
    """How many decimals show ``v`` against ``limit``: ``least_digits``, or more where fewer
    would show it equal to the limit, or on its other side, when it is not (the checks judge
    unrounded values: a distance of 0.59996 m against 0.6 m reads 0.59996, not 0.6000)."""
    for digits in range(least_digits, 16):
        shown = round(v, digits)
        if v == limit or (shown != limit and (shown > limit) == (v > limit)):
            return digits
    return 16


def _num(v, limit, least_digits):
    """``v`` with ``_decimals`` decimals."""
    return f"{v:.{_decimals(v, limit, least_digits)}f}"


def _metres(v, limit):
    """A distance to at most 4 decimals (1.0, 3.0058), more only as ``_decimals`` needs."""
    return round(v, _decimals(v, limit, 4))


def _never_found(m):
    """Why the target was never found, for a failed check's message. Where the camera
    points is the design's doing (it turns the robot), so a target never in view is a
    failure to find it, not a run the check cannot judge."""
    if m.get("mean_distance_m") is None:
        return "the target was never found (the scenario has no target person)"
    if m.get("target_in_view_fraction") == 0:
        return "the target was never found (never in the camera's view)"
    return "the target was never found"


def _mean_distance(v, limit, m):
    """At most the limit: a pass. Above it in a run too short for a robot at its top speed
    from its start to get the mean under it (``checks.reach``): nothing to judge (None)."""
    if v is None:
        return False
    if v <= limit:
        return True
    floor = m.get("mean_distance_floor_m")
    return None if floor is not None and floor > limit else False


def _mean_distance_text(v, limit, m):
    if v is None:
        return f"{_NO_TARGET} (limit <= {limit} m)"
    if _mean_distance(v, limit, m) is None:
        return (
            f"mean distance {_metres(v, limit)} m, but no robot could have kept it under "
            f"{limit} m in this run (at its top speed from its start, at best "
            f"{_metres(m['mean_distance_floor_m'], limit)} m): too short to judge"
        )
    return f"mean distance {_metres(v, limit)} m (limit <= {limit} m)"


def _collisions(kind, meaning):
    return Check(
        f"max_{kind}_collisions",
        lambda m: int(m["collisions"].get(kind, 0)),
        "max",
        meaning,
        lambda v, limit, m: f"{v} collision(s) with {kind} (limit {limit})",
        kind=int,
        limits=_COUNT,
    )


def _tipped(v, limit, m):
    return (
        "the robot never tipped over"
        if v == 0
        else f"the robot tipped over at {m['tipped_over_at_s']:.2f} s (limit {limit})"
    )


def _reacquire_time(m):
    times = m["reacquire_times_s"]
    return max(times) if times else None


def _late(m, limit):
    return [u for u in m["unrecovered_losses_s"] if u > limit]


def _reacquired(v, limit, m):
    """No loss took longer than the limit to end, none still open at the end is older than
    it, and a searched loss ended with the target found: a pass. A loss longer than the limit
    fails whether or not the design searched (one that never searches must not escape). With
    no loss searched, or the only searched loss still open, younger than the limit, when the
    run ended, there is nothing to judge (None): the run was cut short, not the design."""
    if any(x > limit for x in m["reacquire_times_s"]) or _late(m, limit):
        return False
    return True if m["searched_reacquisitions"] >= 1 else None


def _reacquired_text(v, limit, m):
    late = _late(m, limit)
    if late:
        return (
            f"target lost and not found again for {_num(max(late), limit, 2)} s (limit {limit} s)"
        )
    if _reacquired(v, limit, m) is None:
        if m["searched_losses"] == 0:
            return "the target was never lost long enough for the design to search"
        return (
            f"the run ended {_num(m['unrecovered_losses_s'][-1], limit, 2)} s after the target "
            f"was lost, the design still searching, within the {limit} s limit: no "
            "re-acquisition to judge"
        )
    return (
        f"{len(m['reacquire_times_s'])} re-acquisition(s), slowest {_num(v, limit, 2)} s "
        f"after the loss (limit {limit} s)"
    )


def _found_fraction(v, limit, m):
    return m["acquired_at_s"] is not None and v >= limit


def _resumed(v, limit, m):
    """Resumed within the limit: a pass; never, in a run that went on for the limit after the
    removal: a fail. A run that ended sooner leaves nothing to judge (None): the run was cut
    short, not the design."""
    if v is not None:
        return v <= limit
    return False if m["run_after_removal_s"] >= limit else None


def _resumed_text(v, limit, m):
    t_r = m["obstacle_removed_at_s"]
    if _resumed(v, limit, m) is None:
        return (
            f"the run ended {_num(m['run_after_removal_s'], limit, 2)} s after the obstacle "
            f"left at {t_r:.2f} s, before the {limit} s limit: no resumption to judge"
        )
    if v is None:
        return (
            f"the robot never drove {RESUME_CLOSING_M} m towards the target after the "
            f"obstacle left at {t_r:.2f} s (limit {limit} s)"
        )
    return (
        f"drove {RESUME_CLOSING_M} m towards the target {v:.2f} s after the obstacle left "
        f"(limit {limit} s)"
    )


def _measured_text(v, limit, m):
    silent = m.get("silent_sensors") or []
    if silent:
        return (
            f"no measurement at all from {', '.join(silent)} "
            f"(limit >= {limit} frame(s) with a measurement)"
        )
    return f"every sensor measured in at least {v} frame(s) (limit >= {limit})"


def _judged_text(v, limit, judged, noun):
    """``n of N <noun> (p%)``, then the first frame outside the law: its time and frame, the
    command seen against the law's (``judged``: an ``envelopes`` ``..._frames`` metric; the
    percentage alone without it)."""
    if not judged:
        return f"{percent(v, limit, 1)} of the {noun}"
    text = f"{judged['violated']} of {judged['judged']} {noun} ({percent(v, limit, 1)})"
    first = judged["first"]
    if first is None:
        return text
    seen, law = first["commanded"], first["allowed"]
    if isinstance(seen, list):  # the lost/search law: both wheels
        what = f"wheels {seen[0]:g}, {seen[1]:g} DPS, law {law[0]:g}, {law[1]:g}"
    else:
        lo, hi = first["levels"]
        what = (
            f"{seen:g} DPS, law {law[0]:g}..{law[1]:g} (levels {lo}..{hi} at "
            f"{first['distance_m']:.2f} m)"
        )
    return f"{text}, first at {first['t']:.2f} s (frame {first['frame']}): {what}"


def _envelope(metric, no_frames):
    """A precondition: the envelopes read this design's laws and the run judged a frame."""

    def precondition(m):
        if m.get("envelope_reason"):
            return f"no envelope: {m['envelope_reason']}"
        return no_frames if m.get(metric) is None else None

    return precondition


_WHEELS = ("found", "motor_left", "motor_right")
_BAND = (
    "(bands from the design's parameters and the camera's geometry: fpga_robotics.checks.envelopes)"
)

_NO_LINE = "not measured: the run has no floor line or no line sensors"

SHIPPED_CHECKS = (
    Check(
        "acquired_within_s",
        "acquired_at_s",
        "max",
        "the design reports the target found within this time",
        lambda v, limit, m: (
            f"{_never_found(m)} (limit {limit} s)"
            if v is None
            else f"target first found at {_num(v, limit, 2)} s (limit {limit} s)"
        ),
        limits=(0, _DAY, "s"),
        outputs=("found",),
    ),
    Check(
        "mean_distance_max_m",
        "mean_distance_m",
        "max",
        (
            "mean robot-to-target distance (centres) at most this; n/a when the run is too short "
            "for any robot to get the mean under it (mean_distance_floor_m)"
        ),
        _mean_distance_text,
        limits=(0, 1000, "m"),
        passes=_mean_distance,
    ),
    Check(
        "min_distance_min_m",
        "min_distance_m",
        "min",
        "closest robot-to-target distance (centres) at least this",
        lambda v, limit, m: (
            f"min distance {_metres(v, limit)} m (limit >= {limit} m)"
            if v is not None
            else f"{_NO_TARGET} (limit >= {limit} m)"
        ),
        limits=(0, 1000, "m"),
    ),
    _collisions("person", "at most this many collisions with a person"),
    Check(
        "max_robot_at_fault_collisions",
        "robot_at_fault_collisions",
        "max",
        (
            "at most this many times the robot drove into a person (at the first touch it closed "
            "the gap faster than the person and than sim.world.AT_FAULT_SPEED)"
        ),
        lambda v, limit, m: f"the robot drove into a person {v} time(s) (limit {limit})",
        kind=int,
        limits=_COUNT,
    ),
    Check(
        "max_tip_overs",
        "tip_overs",
        "max",
        "the robot tipped over at most this often (0: never; sim.world tip-over model)",
        _tipped,
        kind=int,
        limits=(0, 1, ""),
    ),
    Check(
        "max_oscillation_hz",
        "oscillation_hz",
        "max",
        (
            "the commanded turn rate W changes sign at most this often per second while the "
            "design reports the target found"
        ),
        lambda v, limit, m: (
            f"W changes sign {_num(v, limit, 2)} times per second with the target found "
            f"(limit {limit})"
        ),
        limits=(0, 1000, "Hz"),
        outputs=("found",),
        precondition=measured("oscillation_hz", "the target was never found"),
    ),
    Check(
        "max_off_target_fraction",
        "off_target_fraction",
        "max",
        (
            "the design's centroid is more than an eighth of the image width from the target's "
            "image column (with the target partly beyond the tracking window's edge, from the "
            "middle of its part inside) in at most this fraction of the frames in which it "
            "reports found with the target's centre in view or with none of the target in "
            "view, these all away (a non-target object taken for the target)"
        ),
        lambda v, limit, m: (
            f"centroid away from the target, or the target out of view, in {percent(v, limit)} "
            f"of the frames found (limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=("found", "centroid_x"),
        precondition=measured(
            "off_target_fraction",
            "the design never reported the target found with its centre in view, nor with "
            "it out of view",
        ),
    ),
    Check(
        "mean_centroid_error_max_px",
        "mean_centroid_error_px",
        "max",
        (
            "mean distance of the design's centroid from the target's image column (with the "
            "target partly beyond the tracking window's edge, from the middle of its part "
            "inside; frames found with the target's centre in view) at most this; with the "
            "target straight ahead, the centroid's distance from the image centre; with a "
            "suit whose colour matches in some light but not in all (only a lit strip may "
            "match), the distance from the part of its silhouette inside the window"
        ),
        lambda v, limit, m: (
            f"centroid {_num(v, limit, 2)} px from the target's image column on average "
            f"(limit <= {limit} px)"
        ),
        limits=(0, 10000, "px"),
        outputs=("found", "centroid_x"),
        precondition=measured(
            "mean_centroid_error_px", "the design never reported the target found with it in view"
        ),
    ),
    Check(
        "max_led_wrong_side_fraction",
        "led_wrong_side_fraction",
        "max",
        (
            "the design's centroid LEDs point the wrong way (an LED of the other half lit with "
            "the target an eighth of the width or more to one side, an outermost LED lit with "
            "it within a sixteenth of the centre) in at most this fraction of the frames found "
            "with the target in view (led_wrong_side_fraction)"
        ),
        lambda v, limit, m: (
            f"centroid LEDs point the wrong way in {percent(v, limit)} of the frames "
            f"judged (limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=("found", "centroid_leds"),
        precondition=measured(
            "led_wrong_side_fraction", "the target was never found to one side or at the centre"
        ),
    ),
    Check(
        "max_led_misplaced_fraction",
        "led_misplaced_fraction",
        "max",
        (
            "the lit centroid LEDs are not the one above the target (the LED of the window's "
            "eighth that holds the target's image column; near a border between eighths either "
            "neighbour, near the image centre also the middle pair) in at most this fraction of "
            "the frames found with the target's centre inside the window "
            "(led_misplaced_fraction)"
        ),
        lambda v, limit, m: (
            f"the lit LEDs are not the one above the target in {percent(v, limit, 1)} of "
            f"the frames judged (limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=("found", "centroid_leds"),
        precondition=measured(
            "led_misplaced_fraction", "the target was never found inside the window"
        ),
    ),
    Check(
        "max_wheel_command_dps",
        "peak_wheel_command_dps",
        "max",
        (
            "the design never commands a wheel faster than this, either way "
            "(peak_wheel_command_dps): the speed the motors are rated for"
        ),
        lambda v, limit, m: f"largest wheel command {v} DPS (limit <= {limit:g} DPS)",
        limits=(0, 32768, "DPS"),
        outputs=("motor_left", "motor_right"),
        precondition=measured("peak_wheel_command_dps", "no wheel command"),
    ),
    Check(
        "max_search_travel_m",
        "search_travel_m",
        "max",
        (
            "while the design searches (from a search started to the target found again) the "
            "robot's own driving moves its centre at most this far: it turns in place "
            "(search_travel_m; a push by a person is not its driving)"
        ),
        lambda v, limit, m: (
            f"the robot drove {_num(v, limit, 2)} m during a search (limit <= {limit} m)"
        ),
        limits=(0, 1000, "m"),
        outputs=("found",),
        precondition=measured("search_travel_m", "the design never searched"),
    ),
    Check(
        "max_heading_overshoot_deg",
        "heading_overshoot_deg",
        "max",
        (
            "the robot turns at most this far past the heading that puts the target on the "
            "camera's axis (heading_overshoot_deg)"
        ),
        lambda v, limit, m: (
            f"turned {_num(v, limit, 1)} deg past the target (limit <= {limit} deg)"
        ),
        limits=(0, 180, "deg"),
        precondition=measured("heading_overshoot_deg", "the target's centre was never in view"),
    ),
    Check(
        "max_mean_aim_error_deg",
        "mean_aim_error_deg",
        "max",
        (
            "on average over the frames with a target, the camera points at most this far off "
            "it, in view or not (mean_aim_error_deg): the robot turns to keep the target "
            "centred"
        ),
        lambda v, limit, m: (
            f"the camera pointed {_num(v, limit, 1)} deg off the target on average "
            f"(limit <= {limit} deg)"
        ),
        limits=(0, 180, "deg"),
        precondition=measured("mean_aim_error_deg", "no target person: no aim to judge"),
    ),
    _collisions("wall", "at most this many collisions with a wall"),
    _collisions("furniture", "at most this many collisions with furniture"),
    Check(
        "target_in_view_min_fraction",
        "target_in_view_fraction",
        "min",
        "the target is in the camera's view this often",
        lambda v, limit, m: (
            f"target in view {percent(v, limit)} of frames (limit >= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
    ),
    Check(
        "found_min_fraction",
        "found_after_acquisition_fraction",
        "min",
        "after first acquisition, the design reports found this often",
        lambda v, limit, m: (
            f"{_never_found(m)} (limit >= {limit_percent(limit)} of the frames after it is)"
            if m["acquired_at_s"] is None
            else f"found in {percent(v, limit)} of frames after acquisition "
            f"(limit >= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=("found",),
        passes=_found_fraction,
    ),
    Check(
        "reacquired_within_s",
        _reacquire_time,
        "max",
        (
            "the design lost the target and searched at least once, and every loss ended with "
            "the target found again within this time"
        ),
        _reacquired_text,
        limits=(0, _DAY, "s"),
        outputs=("found",),
        precondition=lambda m: (
            None
            if m["reacquire_times_s"] or m["unrecovered_losses_s"]
            else "the target was never found, so never lost"
            if m["acquired_at_s"] is None
            else "the target was never lost"
        ),
        passes=_reacquired,
    ),
    # The sensor designs' checks (fpga_robotics.checks.sensor_metrics).
    Check(
        "max_lateral_error_m",
        "lateral_error_max_m",
        "max",
        (
            "the line sensors' centre stays within this distance of the nearest floor line's "
            "centreline"
        ),
        lambda v, limit, m: (
            f"line sensors at most {v:.3f} m from the line (mean "
            f"{m['lateral_error_mean_m']:.3f} m; limit {limit} m)"
        ),
        limits=(0, 100, "m"),
        precondition=measured("lateral_error_max_m", _NO_LINE),
    ),
    Check(
        "min_laps",
        "laps",
        "min",
        "at least this many whole laps of the closed floor line",
        lambda v, limit, m: f"{v} whole lap(s) of the track (limit >= {limit})",
        kind=int,
        limits=_COUNT,
        precondition=measured("laps", _NO_LINE),
    ),
    Check(
        "max_off_line_s",
        "off_line_s",
        "max",
        "at most this long in all with no line sensor over a floor line",
        lambda v, limit, m: f"{v:.2f} s with no line sensor over the line (limit {limit} s)",
        limits=(0, _DAY, "s"),
        precondition=measured("off_line_s", _NO_LINE),
    ),
    Check(
        "resumes_within_s",
        "resumed_after_s",
        "max",
        (
            f"after the last piece of furniture is removed, the robot drives "
            f"{RESUME_CLOSING_M} m towards the target within this time (its own motion: a "
            f"person walking up to it does not count)"
        ),
        _resumed_text,
        limits=(0, _DAY, "s"),
        precondition=measured(
            "obstacle_removed_at_s",
            "no furniture was removed during the run (room.furniture.present_until)",
        ),
        passes=_resumed,
    ),
    Check(
        "min_measured_frames",
        "measured_frames_min",
        "min",
        (
            "every measuring sensor of the robot ([[robot.sensors]]) gives a measurement in at "
            "least this many frames (1: the sensor is not silent)"
        ),
        _measured_text,
        kind=int,
        limits=(0, 10**7, ""),
        precondition=measured(
            "measured_frames_min", "the robot has no sensor that measures ([[robot.sensors]])"
        ),
    ),
    # Behaviour envelopes (fpga_robotics.checks.envelopes).
    Check(
        "max_approach_speed_violation_fraction",
        "approach_speed_violation_fraction",
        "max",
        (
            "with the target found and centred, the commanded forward speed (L + R) / 2 is "
            "outside the law's speed for the target's distance (base_dps of the proximity "
            f"levels its pixel count can reach there) in at most this fraction of the frames {_BAND}"
        ),
        lambda v, limit, m: (
            "forward speed outside the approach law in "
            f"{_judged_text(v, limit, m.get('approach_speed_frames'), 'centred frames')} "
            f"(limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=_WHEELS,
        precondition=_envelope(
            "approach_speed_violation_fraction",
            "the target was never found centred and wholly in the window",
        ),
    ),
    Check(
        "max_reverse_when_far_fraction",
        "reverse_when_far_fraction",
        "max",
        (
            "the robot is commanded backwards while the target is farther than the distance at "
            "which the law reverses, in at most this fraction of the frames found there "
            f"{_BAND}"
        ),
        lambda v, limit, m: (
            "reversing with the target beyond the reversing distance in "
            f"{_judged_text(v, limit, m.get('reverse_when_far_frames'), 'frames found there')} "
            f"(limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=_WHEELS,
        precondition=_envelope(
            "reverse_when_far_fraction", "the target was never found beyond the reversing distance"
        ),
    ),
    Check(
        "max_stop_overshoot_m",
        "stop_overshoot_m",
        "max",
        (
            "the robot drives at most this far inside the distance within which the law surely "
            "says stop or reverse (the stop distance, camera to the target's centre): its own "
            "driving, not a start inside it nor the target walking up to it "
            f"{_BAND}"
        ),
        lambda v, limit, m: (
            f"drove {_num(v, limit, 3)} m inside the stop distance (stop distance "
            f"{m['stop_distance_m']:.3f} m, closest {m['stop_closest_m']:.3f} m, camera to the "
            f"target's centre; limit <= {limit} m)"
        ),
        limits=(0, 100, "m"),
        outputs=_WHEELS,
        precondition=lambda m: _envelope("stop_overshoot_m", m.get("stop_reason"))(m),
    ),
    Check(
        "max_turn_law_violation_fraction",
        "turn_law_violation_fraction",
        "max",
        (
            "with the target found wholly in the window, the commanded turn (L - R) / 2 is "
            "outside kp * (the target's column - the image centre), saturating at max_dps, "
            f"in at most this fraction of the frames {_BAND}"
        ),
        lambda v, limit, m: (
            "turn outside the steering law in "
            f"{_judged_text(v, limit, m.get('turn_law_frames'), 'frames judged')} "
            f"(limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=_WHEELS,
        precondition=_envelope(
            "turn_law_violation_fraction", "the target was never found wholly in the window"
        ),
    ),
    Check(
        "max_search_law_violation_fraction",
        "search_law_violation_fraction",
        "max",
        (
            "with the target lost, the design holds its last command for lost_frames - 1 "
            "frames, then turns in place at search_dps towards the side the target was last "
            f"seen on, in all but at most this fraction of the lost frames {_BAND}"
        ),
        lambda v, limit, m: (
            "lost/search command off the law in "
            f"{_judged_text(v, limit, m.get('search_law_frames'), 'lost frames judged')} "
            f"(limit <= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        outputs=_WHEELS,
        precondition=_envelope("search_law_violation_fraction", "the target was never lost"),
    ),
    Check(
        "camera_target_in_view_min_fraction",
        "camera_target_in_view_fraction",
        "min",
        (
            "every further camera with a target ([[robot.sensors]] camera, target = ...) has "
            "its target in view this often (the least of them)"
        ),
        lambda v, limit, m: (
            f"a camera's target in view {percent(v, limit)} of frames (limit >= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        precondition=measured("camera_target_in_view_fraction", "no further camera has a target"),
    ),
    Check(
        "camera_target_centred_min_fraction",
        "camera_target_centred_fraction",
        "min",
        (
            "every further camera with a target has it within its centred_deg of the axis "
            "this often (the least of them): a pan camera keeps its target centred"
        ),
        lambda v, limit, m: (
            f"a camera's target centred in {percent(v, limit)} of frames (limit >= {limit_percent(limit)})"
        ),
        limits=_FRACTION,
        precondition=measured("camera_target_centred_fraction", "no further camera has a target"),
    ),
)
