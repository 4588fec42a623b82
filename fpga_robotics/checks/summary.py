"""What a closed-loop run measured, the scenario's checks against it, and the verdict.

``metrics(traj, events, ...)`` reduces the per-frame trajectory to numbers;
``evaluate_checks(checks, metrics)`` (``registry.py``) compares them with the scenario's
limits. Each check says what it measured, its limit and whether it passed, failed or could
not judge (n/a, with the reason), so that a verdict explains itself. ``format_summary`` is
the human version printed by the runner.
"""

import numpy as np

from fpga_robotics.checks.check import DESIGN_OUTPUTS
from fpga_robotics.checks.percent import percent
from fpga_robotics.checks.registry import CHECK_OUTPUTS, CHECKS, evaluate_checks, verdict
from fpga_robotics.checks.window import visible_middle, whole_in_window, window_columns

__all__ = [
    "CHECKS",
    "CHECK_OUTPUTS",
    "DESIGN_OUTPUTS",
    "TIMING_FIELDS",
    "compute_metrics",
    "evaluate_checks",
    "format_summary",
    "rounded",
    "verdict",
]

#: Metrics made of design outputs: name -> the outputs they need (None when one is absent).
_METRIC_OUTPUTS = {
    "found_fraction": ("found",),
    "found_after_acquisition_fraction": ("found",),
    "acquired_at_s": ("found",),
    "losses": ("found",),
    "searches": ("found",),
    "searched_losses": ("found",),
    "searched_reacquisitions": ("found",),
    "reacquire_times_s": ("found",),
    "unrecovered_losses_s": ("found",),
    "oscillation_hz": ("found",),
    "off_target_fraction": ("found", "centroid_x"),
    "mean_centroid_error_px": ("found", "centroid_x"),
    "led_wrong_side_fraction": ("found", "centroid_leds"),
    "led_misplaced_fraction": ("found", "centroid_leds"),
    "peak_wheel_command_dps": ("motor_left", "motor_right"),
    "search_travel_m": ("found",),
}

#: The design outputs the wheels connector reads.
_WHEEL_OUTPUTS = ("motor_left", "motor_right")

#: Summary fields that depend on the machine, not on the simulation.
TIMING_FIELDS = (
    "wall_time_s",
    "ms_per_frame",
    "realtime_factor",
    "cpu_ms_per_frame",
    "backend_setup_s",
    "cycles_per_wall_s",
    "paused_s",
)


def _float(x):
    return None if x is None else float(x)


def _time(x):
    """A time (s) at the microsecond the run's events are stamped with, free of the float
    noise of ``k * period`` (1.0000000000000002 s is 1 s, at a limit of 1 s)."""
    return None if x is None else round(float(x), 6)


#: Decimals the summary shows a metric with (``rounded``): 4, or these.
SHOWN_DECIMALS = {
    "mean_centroid_error_px": 2,
    "heading_overshoot_deg": 2,
    "mean_aim_error_deg": 2,
    "max_abs_bearing_deg": 2,
    "obstacle_removed_at_s": 6,
}


def rounded(metrics):
    """The metrics as the summary shows them: every float, also in lists and tables, to 4
    decimals or its ``SHOWN_DECIMALS``. The checks judge the metrics before this: a target in
    view in 1 frame of 20004 meets a limit of 0.001%, though its fraction shows as 0.0."""
    return {name: _rounded(value, name) for name, value in metrics.items()}


def _rounded(value, name):
    if isinstance(value, dict):
        return {k: _rounded(v, k) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v, name) for v in value]
    if isinstance(value, float):
        return round(value, SHOWN_DECIMALS.get(name, 4))
    return value


#: The design's centroid points away from the target when it is further than this fraction of
#: the image width from the target's column.
OFF_TARGET_FRACTION = 0.125


def compute_metrics(
    traj,
    events,
    collisions,
    frame_period,
    *,
    at_fault_collisions=0,
    width=None,
    absent=(),
    margin_x=None,
    collision_summary=None,
    camera_mount=None,
    lit_strip=None,
):
    """Reduce a run to numbers.

    Parameters
    ----------
    traj : dict of numpy arrays, one entry per camera frame
        ``t``, ``x``, ``y``, ``found``, ``target_distance`` (NaN without target),
        ``target_in_view``; for the centroid metrics ``target_column``, ``centroid_x`` and
        ``target_left``, ``target_right`` (the target's silhouette; without them the centroid
        is compared with the target's column whatever the window cuts off).
    events : list of (frame, time, text)
    collisions : dict kind → count
    frame_period : float
    at_fault_collisions : int
        Collisions with a person the robot drove into (``World.at_fault_collisions``).
    width : int, optional
        The image width, pixels: the centroid and LED metrics need it (without it they are
        None).
    absent : collection of str
        ``DESIGN_OUTPUTS`` the design does not produce (their trajectory entries are NaN): the
        metrics made of them are None, and ``absent_outputs`` lists them.
    margin_x : int, optional
        The columns the design's tracking window leaves on each side (the LEDs sit above its
        eighths; the centroid metrics compare the design's centroid with the part of the
        target inside it); default ``width // 10``, the design's default.
    collision_summary : dict, optional
        ``World.collision_summary()``: per kind, episodes, contact time and largest impulse.
    camera_mount : fpga_robotics.loop.connectors.base.Mount, optional
        Where the camera sits on the robot and its yaw off the heading (the heading
        overshoot is measured from the camera's axis); default the robot's centre and heading.
    lit_strip : numpy bool array, optional
        Per frame, whether the target's suit may match the colour filter only where it is
        lit (``envelopes.lit_strip_frames``): the centroid checks there measure from the
        part of the silhouette inside the window, not from its middle; so do they in the
        frames in which the trajectory's ``target_hidden`` says something hides part of it.
    """
    if "target_hidden" in traj:
        # Part of the target hidden behind furniture or a person: the centroid of what is
        # seen lies anywhere on the silhouette, as for a lit strip.
        hidden = np.asarray(traj["target_hidden"], bool)
        lit_strip = hidden if lit_strip is None else np.asarray(lit_strip, bool) | hidden
    absent = [name for name in DESIGN_OUTPUTS if name in set(absent)]
    if absent:
        present = {k: v for k, v in traj.items() if k not in absent}
        if "found" in absent:  # the metrics below read it; theirs are replaced by None
            present["found"] = np.zeros(len(traj["t"]), bool)
        m = compute_metrics(
            present,
            events,
            collisions,
            frame_period,
            at_fault_collisions=at_fault_collisions,
            width=width,
            margin_x=margin_x,
            collision_summary=collision_summary,
            camera_mount=camera_mount,
            lit_strip=lit_strip,
        )
        for name, needs in _METRIC_OUTPUTS.items():
            if any(o in absent for o in needs):
                m[name] = None
        m["absent_outputs"] = absent
        return m
    t = traj["t"]
    n = len(t)
    dist = traj["target_distance"]
    valid = ~np.isnan(dist)
    found = traj["found"]
    first = int(np.argmax(found)) if found.any() else None
    acquired_at = float(t[first]) if first is not None else None
    found_after = float(found[first:].mean()) if first is not None else 0.0
    path = float(np.hypot(np.diff(traj["x"]), np.diff(traj["y"])).sum()) if n > 1 else 0.0

    # Loss episodes: from a "target lost" to the next "target found".
    episodes = []  # (lost_time, found_time or None, searched)
    open_ep = None
    for _frame, time, text in events:
        if text == "target lost":
            open_ep = [time, None, False]
            episodes.append(open_ep)
        elif text == "search started" and open_ep is not None:
            open_ep[2] = True
        elif text == "target found" and open_ep is not None:
            open_ep[1] = time
            open_ep = None
    end_time = float(t[-1]) + frame_period if n else 0.0
    reacq = [_time(f - lost) for lost, f, _ in episodes if f is not None]
    unrecovered = [_time(end_time - lost) for lost, f, _ in episodes if f is None]
    tipped = [(time, text) for _f, time, text in events if text.startswith("tipped over")]
    return {
        "min_distance_m": float(dist[valid].min()) if valid.any() else None,
        "mean_distance_m": float(dist[valid].mean()) if valid.any() else None,
        "target_in_view_fraction": float(traj["target_in_view"].mean()) if n else 0.0,
        "found_fraction": float(found.mean()) if n else 0.0,
        "found_after_acquisition_fraction": found_after,
        "acquired_at_s": _time(acquired_at),
        "collisions": dict(collisions),
        "robot_at_fault_collisions": int(at_fault_collisions),
        "collision_summary": dict(collision_summary or {}),
        "losses": len(episodes),
        "searches": sum(1 for _, _, text in events if text == "search started"),
        "searched_losses": sum(1 for ep in episodes if ep[2]),
        "searched_reacquisitions": sum(1 for ep in episodes if ep[2] and ep[1] is not None),
        "reacquire_times_s": reacq,
        "unrecovered_losses_s": unrecovered,
        "path_length_m": path,
        "tipped_over_at_s": _time(tipped[0][0]) if tipped else None,
        "tip_overs": len(tipped),
        "max_wheel_command_step_dps": _max_command_step(traj),
        "oscillation_hz": _oscillation(traj, n * frame_period),
        **_off_target(traj, width, margin_x, lit_strip),
        "led_wrong_side_fraction": _led_wrong_side(traj, width, margin_x, lit_strip),
        "led_misplaced_fraction": _led_misplaced(traj, width, margin_x, lit_strip),
        "peak_wheel_command_dps": _peak_command(traj),
        "search_travel_m": _search_travel(traj, events),
        "heading_overshoot_deg": _heading_overshoot(traj, camera_mount),
        "mean_aim_error_deg": _mean_aim_error(traj, camera_mount),
        "absent_outputs": [],
    }


def _heading_overshoot(traj, mount=None):
    """How far the robot turns past the target, degrees: the largest bearing error on the far
    side once the error has changed sign, over frames with the target's centre in view and the
    frames out of view in which the robot goes on turning away from the target (a turn that
    carries the target out of the image on the far side is the largest overshoot, not none);
    any other frame out of view starts afresh. The bearing error is the turn in place that
    would put the target on the camera's axis (``_aim_error``; the camera at ``mount``, a
    ``connectors.base.Mount``, or at the robot's centre along its heading without one), so a
    camera yawed on its mount is on the target when the robot's body is not. Meaningful with a
    standing target (a step response, e.g. ``approach`` with ``robot.heading_deg=20``); a
    walking target crossing the robot's axis counts too. None without the fields, or when the
    target's centre was never in view (no heading response to judge)."""
    need = ("x", "y", "heading", "target_x", "target_y", "target_column")
    if any(k not in traj for k in need) or len(traj["x"]) == 0:
        return None
    in_view = ~np.isnan(np.asarray(traj["target_column"], dtype=float))
    if not in_view.any():
        return None
    b = np.degrees(_aim_error(traj, mount))
    # The robot's own turn since the last frame, left positive: it turns away from the target
    # when that turn is against the error's sign (the error grows by it).
    turn = np.diff(np.unwrap(np.asarray(traj["heading"], dtype=float)), prepend=np.nan)
    best, last, crossed = 0.0, 0.0, False
    for bk, seen, tk in zip(b, in_view, turn):
        if not seen and not (crossed and tk * bk < 0):
            last, crossed = 0.0, False
            continue
        sign = np.sign(bk)
        if sign == 0:
            continue
        crossed = crossed or (last != 0 and sign != last)
        if crossed:
            best = max(best, abs(float(bk)))
        last = sign
    return best


def _mean_aim_error(traj, mount=None):
    """The mean, over the frames with a target, of how far the camera points off it, degrees
    (``_aim_error`` unsigned, in or out of view: a robot that lets the target drift to the
    image's edge or out of it, or turns to something else, aims badly whatever it reports).
    None without the fields or a target."""
    need = ("x", "y", "heading", "target_x", "target_y")
    if any(k not in traj for k in need) or len(traj["x"]) == 0:
        return None
    err = np.abs(np.degrees(_aim_error(traj, mount)))
    valid = ~np.isnan(err)
    return float(err[valid].mean()) if valid.any() else None


def _aim_error(traj, mount):
    """Per frame, the turn in place (rad, left positive) that puts the target's centre on the
    camera's axis. The camera sits at ``m = (forward, left)`` of the robot's centre, looking
    ``yaw`` off its heading; it is on the target when the target, ``r`` from the centre, lies
    at ``m + s u(yaw)`` in the robot's frame, ``s`` the root of ``|m + s u(yaw)| = r``: at
    the angle ``a`` of that point from the heading. The error is the target's bearing from the
    centre less ``a`` (``a`` is 0 for a camera on the robot's axis looking ahead)."""
    dx, dy = traj["target_x"] - traj["x"], traj["target_y"] - traj["y"]
    bearing = np.arctan2(dy, dx) - traj["heading"]
    if mount is not None:
        fwd, left, yaw = mount.forward, mount.left, mount.yaw
        along = fwd * np.cos(yaw) + left * np.sin(yaw)  # m . u(yaw)
        s = -along + np.sqrt(np.maximum(0.0, along**2 - fwd**2 - left**2 + dx**2 + dy**2))
        bearing = bearing - np.arctan2(left + s * np.sin(yaw), fwd + s * np.cos(yaw))
    return (bearing + np.pi) % (2 * np.pi) - np.pi


def _off_target(traj, width, margin_x=None, lit_strip=None):
    """How far the design's centroid is from where it should see the target, over the frames
    in which it reports found with the target's centre in view: the target's image column
    (``target_column``) with its silhouette (``target_left`` .. ``target_right``) wholly
    inside the tracking window's columns, else the middle of the part inside (the tracker
    counts only the pixels there; ``visible_middle``; a frame with no part inside is left
    out). In the ``lit_strip`` frames only a lit strip of the suit may match, its centroid
    anywhere on the part inside: the error there is from the nearest point of that part
    (another object's pixels beside the target still pull the centroid off it). The
    fraction of those frames with an error above ``OFF_TARGET_FRACTION * width``, the frames
    found with no part of the target in view counted too, as away (whatever the design found
    there is not the target); and the mean error (pixels) over the first. None without such
    frames or fields."""
    none = {"off_target_fraction": None, "mean_centroid_error_px": None}
    if width is None or "target_column" not in traj or "centroid_x" not in traj:
        return none
    elsewhere = int(np.count_nonzero(traj["found"] & ~np.asarray(traj["target_in_view"], bool)))
    column = np.asarray(traj["target_column"], dtype=float)
    expected = column
    if "target_left" in traj and "target_right" in traj:
        left = np.asarray(traj["target_left"], dtype=float)
        right = np.asarray(traj["target_right"], dtype=float)
        expected = np.where(
            whole_in_window(left, right, width, margin_x),
            column,
            visible_middle(left, right, width, margin_x),
        )
    centroid = np.asarray(traj["centroid_x"], dtype=float)
    ok = traj["found"] & ~np.isnan(column) & ~np.isnan(expected)
    if not ok.any():
        return {**none, "off_target_fraction": 1.0} if elsewhere else none
    err = np.abs(centroid - expected)
    if lit_strip is not None and "target_left" in traj and "target_right" in traj:
        lo, hi = window_columns(width, margin_x)
        nearest = np.clip(centroid, np.maximum(left, lo), np.minimum(right, hi))
        err = np.where(lit_strip, np.abs(centroid - nearest), err)
    away = np.count_nonzero(err[ok] > OFF_TARGET_FRACTION * width) + elsewhere
    return {
        "off_target_fraction": float(away / (np.count_nonzero(ok) + elsewhere)),
        "mean_centroid_error_px": float(err[ok].mean()),
    }


def _centroid_span(traj, width, margin_x, lit_strip):
    """Per frame, ``(lo, hi)``: the columns the design's centroid of the target may lie
    between: its image column, or in a ``lit_strip`` frame (only a lit strip of the suit may
    match) anywhere on the part of its silhouette inside the tracking window."""
    column = np.asarray(traj["target_column"], dtype=float)
    if lit_strip is None or "target_left" not in traj or "target_right" not in traj:
        return column, column
    lo, hi = window_columns(width, margin_x)
    left = np.maximum(np.asarray(traj["target_left"], dtype=float), lo)
    right = np.minimum(np.asarray(traj["target_right"], dtype=float), hi)
    strip = np.asarray(lit_strip, bool) & (right > left)
    return np.where(strip, left, column), np.where(strip, right, column)


#: The target is on one side when its image column is at least this fraction of the image
#: width from the centre (``led_wrong_side_fraction``).
LED_SIDE_FRACTION = 0.125


def _led_wrong_side(traj, width, margin_x=None, lit_strip=None):
    """How often the centroid LEDs point the wrong way, over the frames found with the
    target's centre in view: at least ``LED_SIDE_FRACTION`` of the width to one side, an LED of
    the other half is lit (bits 0-3 are the left half, 4-7 the right); within half that of the
    centre, one of the two outermost LEDs of a side is lit (bits 0, 1, 6, 7: they light only
    when half the target's pixels are in the outer quarter of the window). In a
    ``lit_strip`` frame the whole part of the silhouette in the window must lie that far to a
    side or that near the centre (``_centroid_span``). None without such frames or fields."""
    if width is None or "target_column" not in traj or "centroid_leds" not in traj:
        return None
    column = np.asarray(traj["target_column"], dtype=float)
    lo, hi = _centroid_span(traj, width, margin_x, lit_strip)
    offset = column - width / 2
    seen = traj["found"] & ~np.isnan(column)
    near = np.minimum(np.abs(lo - width / 2), np.abs(hi - width / 2))
    far = np.maximum(np.abs(lo - width / 2), np.abs(hi - width / 2))
    one_side = np.sign(lo - width / 2) == np.sign(hi - width / 2)
    side = seen & one_side & (near >= LED_SIDE_FRACTION * width)
    centre = seen & (far <= LED_SIDE_FRACTION * width / 2)
    judged = side | centre
    if not judged.any():
        return None
    leds = np.asarray(traj["centroid_leds"], dtype=np.int64)
    other_half = np.where(offset < 0, leds & 0xF0, leds & 0x0F) != 0
    outer = (leds & 0b1100_0011) != 0
    wrong = (side & other_half) | (centre & outer)
    return float(wrong[judged].mean())


#: Near a border between two of the window's eighths, or near the image centre, the LED
#: above the target is ambiguous within this fraction of the image width
#: (``led_misplaced_fraction``): a body a few pixels across straddles the border.
LED_BORDER_FRACTION = 1 / 32
#: The middle pair of LEDs (the design's "centred" code).
LED_CENTRED = 0b0001_1000


def _led_misplaced(traj, width, margin_x=None, lit_strip=None):
    """How often the lit LEDs are not the one above the target, over the frames found with
    the target's centre inside the tracking window's columns (``margin_x`` from each side;
    default ``width // 10``): LED k sits above the window's k-th eighth (from the left); the
    right code is that LED alone, or, with the column within ``LED_BORDER_FRACTION`` of the
    width from a border between eighths, the LED on either side of it, or, that close to the
    image centre, the middle pair too. In a ``lit_strip`` frame the centroid may lie anywhere
    on the part of the silhouette in the window (``_centroid_span``): the LED above any
    column of it is right. Any other code (no LED, two LEDs, the wrong one) is misplaced.
    None without such frames or fields."""
    if width is None or "target_column" not in traj or "centroid_leds" not in traj:
        return None
    margin = width // 10 if margin_x is None else margin_x
    bin_width = (width - 2 * margin) / 8
    if bin_width <= 0:
        return None
    column = np.asarray(traj["target_column"], dtype=float)
    judged = traj["found"] & ~np.isnan(column)
    judged &= (column >= margin) & (column < width - margin)
    if not judged.any():
        return None
    lo, hi = (a[judged] for a in _centroid_span(traj, width, margin, lit_strip))
    leds = np.asarray(traj["centroid_leds"], dtype=np.int64)[judged]
    tol = LED_BORDER_FRACTION * width
    first = np.clip(((lo - tol - margin) // bin_width).astype(np.int64), 0, 7)
    last = np.clip(((hi + tol - margin) // bin_width).astype(np.int64), 0, 7)
    single = (leds > 0) & ((leds & (leds - 1)) == 0)
    lit = np.log2(np.maximum(leds, 1)).astype(np.int64)  # the one LED lit, if single
    ok = single & (first <= lit) & (lit <= last)
    ok |= (lo - tol <= width / 2) & (width / 2 <= hi + tol) & (leds == LED_CENTRED)
    return float((~ok).mean())


def _peak_command(traj):
    """The largest wheel command either way, DPS (of the wheels whose command the design
    produces; None with neither)."""
    wheels = [k for k in ("motor_left", "motor_right") if k in traj]
    if not wheels or len(traj[wheels[0]]) == 0:
        return None
    return int(max(np.abs(np.asarray(traj[k], dtype=float)).max() for k in wheels))


def _search_travel(traj, events):
    """The longest distance the robot's centre travelled by its own driving during one
    search: from a "search started" event's frame to the next "target found" (or the last
    frame), metres; each frame's step no longer than its own driving's (``driven_x``,
    ``driven_y``), so a person pushing it adds nothing. None without a search."""
    last = len(traj["x"]) - 1
    starts, episodes = None, []
    for frame, _time, text in events:
        if text == "search started" and starts is None:
            starts = frame
        elif text == "target found" and starts is not None:
            episodes.append((starts, frame))
            starts = None
    if starts is not None:
        episodes.append((starts, last))
    if not episodes:
        return None

    def steps(xs, ys):
        return np.hypot(np.diff(np.asarray(xs, float)), np.diff(np.asarray(ys, float)))

    own = np.minimum(steps(traj["x"], traj["y"]), steps(traj["driven_x"], traj["driven_y"]))
    return _float(max(float(own[a : min(b, last)].sum()) for a, b in episodes))


def _max_command_step(traj):
    """The largest change of a wheel's command from one frame to the next, DPS (of the wheels
    whose command the design produces; None with neither)."""
    wheels = [k for k in ("motor_left", "motor_right") if k in traj]
    if not wheels or len(traj[wheels[0]]) < 2:
        return None
    steps = [np.abs(np.diff(np.asarray(traj[k], dtype=float))).max() for k in wheels]
    return int(max(steps))


def _oscillation(traj, seconds):
    """Sign changes of the commanded turn rate W per second while the design reports the
    target found: a steering that swings left-right-left about the target. Frames with W = 0
    (straight ahead) keep the last sign, so left-straight-right counts once; a frame without
    the target starts the count afresh (a search turns one way). Every found frame counts,
    wherever the centroid is: a swing wide enough to carry the target off-centre is the worst
    oscillation, not none (a tracker's W points to the target's side off-centre, so it flips
    only as the target crosses the centre). Per second of found time; None if the target was
    never found, or without ``cmd_w``."""
    if "cmd_w" not in traj or seconds <= 0:
        return None
    found = np.asarray(traj["found"], bool)
    if not found.any():
        return None
    flips, last = 0, 0.0
    for wk, fk in zip(np.sign(np.asarray(traj["cmd_w"], dtype=float)), found):
        if not fk:
            last = 0.0
        elif wk != 0:
            flips += bool(last * wk < 0)
            last = wk
    # Sign changes over the found frames' time: to 1e-6 Hz, free of the float noise of the
    # frame period (3 in 3 s is 1 Hz, at a limit of 1 Hz).
    return round(flips / (seconds * found.mean()), 6)


def format_summary(s):
    """The human summary printed at the end of a run (several lines)."""
    rtf = s["realtime_factor"]
    lines = [
        f"scenario {s['scenario']}  backend {s['backend']}  {s['resolution']}  seed {s['seed']}",
        (
            f"  {s['frames']} frames, {s['sim_time_s']:.1f} s simulated in {s['wall_time_s']:.2f} s"
            + (f", paused {s['paused_s']:.1f} s besides" if s.get("paused_s") else "")
            + f" ({s['ms_per_frame']:.2f} ms/frame, "
            f"{f'{rtf:.1f}x' if rtf is not None else 'n/a'} real time)"
        ),
    ]
    if s.get("timing") is not None:
        rate = s.get("cycles_per_wall_s")
        rate = f", {rate / 1e6:.1f} M/s of wall time" if rate else ""
        clock = (
            f"real clock at {s['clock_hz'] / 1e6:g} MHz"
            if s["timing"] == "real_clock"
            else "compressed (clocked while pixels flow)"
        )
        lines.append(f"  timing: {clock}; {s['sim_cycles']:,} design cycles{rate}")
    if s.get("ended_early"):
        lines.append(f"  run ended early: {s['ended_early']}")
    # An output recorded under its own name (a camera-less design's `found`) is no absentee.
    absent = [n for n in s.get("absent_outputs") or () if n not in (s.get("extra_outputs") or {})]
    tracker = [n for n in absent if n not in _WHEEL_OUTPUTS]
    if tracker:
        lines.append(
            "  tracker outputs absent (no such port, or no camera frame to latch them): "
            + ", ".join(tracker)
        )
    wheels = [n for n in absent if n in _WHEEL_OUTPUTS]
    if wheels:
        lines.append(f"  wheel outputs absent (no wheels bound: 0 DPS): {', '.join(wheels)}")
    acq = s["acquired_at_s"]
    found = (
        percent(s["found_fraction"])
        if s["found_fraction"] is not None
        else "n/a (no tracker `found` output)"
    )
    searches = s["searches"] if s["searches"] is not None else "n/a"
    # Without a target person every distance is missing (the trajectory holds NaN).
    if s["min_distance_m"] is None:
        lines.append(
            "  target: none in the scenario"
            + (
                f" (the design reported found in {found} of frames, {searches} search(es))"
                if s["found_fraction"] is not None
                else ", and no tracker `found` output"
            )
        )
        lines.append(f"  distance: n/a (no target person); path {s['path_length_m']:.1f} m")
    else:
        lines.append(
            "  target: "
            + (
                f"first found at {acq:.2f} s"
                if acq is not None
                else "never found"
                if s["found_fraction"] is not None
                else "acquisition n/a"
            )
            + f", in view {percent(s['target_in_view_fraction'])}, found {found}"
            + f", {searches} search(es)"
        )
        lines.append(
            f"  distance: min {s['min_distance_m']:.2f} m, mean {s['mean_distance_m']:.2f} m; "
            f"path {s['path_length_m']:.1f} m"
        )
    coll = ", ".join(f"{k} {v}" for k, v in s["collisions"].items()) or "none"
    lines.append(f"  collisions: {coll}")
    if s.get("silent_sensors"):
        lines.append(
            "  warning: no measurement at all from sensor(s) "
            + ", ".join(s["silent_sensors"])
            + " (the checks that need them are n/a; checks.min_measured_frames "
            "fails such a run)"
        )
    for c in s["checks"]:
        mark = {True: "ok", False: "FAIL", None: "n/a"}[c["passed"]]
        lines.append(f"  [{mark}] {c['name']}: {c['text']}")
    if s["verdict"] == "n/a":
        lines.append("verdict: N/A (no check could judge this run)")
    else:
        lines.append(f"verdict: {s['verdict'].upper()}")
    return "\n".join(lines)
