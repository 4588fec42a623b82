"""Live control of a closed-loop run: colour select, the target person driven by hand, pause,
single step, pacing speed.

Inputs come from any thread (the Foxglove server's client-publish callbacks, the terminal
reader) through ``LiveControls.submit``; the closed loop asks ``inputs_for(frame, t)`` once
per frame, just after the camera capture, and applies what it gets with ``apply_inputs``:
a colour acts on that very frame, a target velocity from that instant on. Every applied input
is logged with its frame (``log``, the summary's ``inputs``), and ``ReplayControls`` hands the
same inputs to the same frames again, so a run with live input replays exactly
(``--replay-inputs``). Pause, step and speed change only the wall clock, never the results.
"""

import json
import math
import threading
import time

from fpga_robotics.hw.errors import UsageError

from ..hw.pixel import COLOR_SELECT, color_select_value
from ..sim.world.world import MAX_TARGET_SPEED

__all__ = [
    "INPUT_KINDS",
    "TELEOP_SPEED",
    "LiveControls",
    "ReplayControls",
    "apply_inputs",
    "check_input",
    "load_inputs",
    "replay_mismatch",
]

#: Speed of the target person driven by the terminal's arrows and the layout's teleop pad, m/s.
TELEOP_SPEED = 0.5

#: What an input can be: kind -> what its value is.
INPUT_KINDS = {
    "color": "a colour select name (" + ", ".join(COLOR_SELECT) + ")",
    "target_velocity": f"[vx, vy] m/s in the world frame (at most {MAX_TARGET_SPEED:g} m/s), "
    "or null to hand the target back to its script",
    "pause": "null",
    "resume": "null",
    "step": "null",
    "speed": "a pacing factor > 0 (1 = real time)",
}

#: The inputs that change what the run computes (the rest only pace the wall clock).
_EFFECTIVE = ("color", "target_velocity")


def check_input(kind, value):
    """The input ``(kind, value)`` normalised; ``ValueError`` saying what is wrong."""
    if kind not in INPUT_KINDS:
        raise ValueError(f"unknown input kind {kind!r}; one of {', '.join(INPUT_KINDS)}")
    if kind == "color":
        if not isinstance(value, str):
            value = _color_name(value)
        color_select_value(value)  # raises for an unknown name
        return kind, value.lower()
    if kind == "target_velocity":
        if value is None:
            return kind, None
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise ValueError(f"target_velocity must be [vx, vy] or null, got {value!r}")
        vx, vy = (float(v) for v in value)
        if not math.hypot(vx, vy) <= MAX_TARGET_SPEED:  # NaN fails too
            raise ValueError(
                f"target_velocity must be at most {MAX_TARGET_SPEED:g} m/s fast, got {value!r}"
            )
        return kind, [vx, vy]
    if kind == "speed":
        speed = float(value)
        if not (speed > 0 and math.isfinite(speed)):
            raise ValueError(f"speed must be > 0, got {value!r}")
        return kind, speed
    return kind, None


def _color_name(code):
    if isinstance(code, bool) or not isinstance(code, int):
        raise TypeError(f"colour must be a name or a code 0..7, got {code!r}")
    for name, value in COLOR_SELECT.items():
        if value == code:
            return name
    raise ValueError(f"colour code must be 0..7, got {code!r}")


def apply_inputs(loop, inputs):
    """Apply inputs to a ``ClosedLoop``; returns the events they make (one per input)."""
    events = []
    for kind, value in inputs:
        if kind == "color":
            loop.set_color(value)
            events.append(f"control: colour select {value}")
        elif kind == "target_velocity":
            if loop.world.target_position() is None:  # a scenario without a target
                events.append("control: no target person to drive")
                continue
            loop.world.set_target_velocity(value)
            events.append(
                "control: target back on its script"
                if value is None
                else f"control: target velocity ({value[0]:+.2f}, {value[1]:+.2f}) m/s"
            )
        elif kind == "speed":
            events.append(f"control: speed x{value:g}")
        else:
            events.append(f"control: {kind}")
    return events


class LiveControls:
    """Inputs from other threads, applied at frame boundaries; paces the run to the clock.

    Parameters
    ----------
    speed : float or None
        Simulated seconds per wall second (1 = real time); None runs as fast as it can.
    paused : bool
        Start paused (a ``step`` or ``resume`` input lets it go on).
    """

    def __init__(self, speed=1.0, paused=False):
        self.speed = speed
        self.log = []  # [{"frame", "t", "kind", "value"}, ...] in the order applied
        self._cond = threading.Condition()
        self._queue = []
        self._paused = paused
        self._steps = 0
        self._closed = False
        self._anchor = None  # (wall, sim) the pacing counts from
        #: Wall time the run was held paused, s: the user's, not the machine's speed.
        self.paused_s = 0.0

    @property
    def paused(self):
        return self._paused

    def submit(self, kind, value=None):
        """Queue an input (any thread); ``ValueError`` for a malformed one."""
        kind, value = check_input(kind, value)
        with self._cond:
            self._queue.append((kind, value))
            if kind == "pause":
                self._paused = True
            elif kind == "resume":
                self._paused = False
            elif kind == "step":
                self._steps += 1
            self._cond.notify_all()

    def close(self):
        """Let a paused run go on to its end (the user quit)."""
        with self._cond:
            self._closed = True
            self._paused = False
            self._cond.notify_all()

    def inputs_for(self, frame, t):
        """The inputs that act at ``frame`` (simulated time ``t``): waits while paused (one
        frame per ``step``) and paces to ``speed``."""
        with self._cond:
            waited = False
            held_from = time.perf_counter()
            while self._paused and not self._closed:
                if self._steps > 0:
                    self._steps -= 1
                    break
                waited = True
                self._cond.wait(0.1)
            if waited:
                self.paused_s += time.perf_counter() - held_from
            # What came while paused acts on the frame that goes on (a colour, then a step).
            inputs, self._queue = self._queue, []
        for kind, value in inputs:
            if kind == "speed":
                self.speed = value
        if waited or any(k in ("speed", "resume", "step") for k, _ in inputs):
            self._anchor = None  # pacing starts afresh after a pause or a new speed
        self._pace(t)
        for kind, value in inputs:
            self.log.append({"frame": frame, "t": round(t, 6), "kind": kind, "value": value})
        return inputs

    def _pace(self, t):
        if self.speed is None or self._paused:
            return
        now = time.perf_counter()
        if self._anchor is None:
            self._anchor = (now, t)
            return
        ahead = (t - self._anchor[1]) / self.speed - (now - self._anchor[0])
        if ahead > 0:
            time.sleep(ahead)


class ReplayControls:
    """The inputs of an earlier run, each at the frame it acted on; never waits."""

    def __init__(self, inputs):
        self.log = []
        self.paused_s = 0.0  # a replay never waits
        self.last_frame = None  # the last frame the run reached
        self._by_frame = {}
        for item in inputs:
            self._by_frame.setdefault(item["frame"], []).append((item["kind"], item["value"]))

    def inputs_for(self, frame, t):
        self.last_frame = frame
        inputs = self._by_frame.get(frame, [])
        for kind, value in inputs:
            self.log.append({"frame": frame, "t": round(t, 6), "kind": kind, "value": value})
        return inputs

    def unreached(self):
        """How many inputs are at frames after the last one the run reached."""
        last = -1 if self.last_frame is None else self.last_frame
        return sum(len(inputs) for frame, inputs in self._by_frame.items() if frame > last)

    def close(self):
        pass


#: What a summary says of its run that decides where its inputs act.
_STEERED_RUN = ("scenario", "seed", "overrides")


def replay_mismatch(path, steered, scenario, seed, overrides):
    """The warning for replaying the inputs of the run ``steered`` (the summary's
    ``_STEERED_RUN`` items, or None for a bare list) onto another run, or None."""
    if steered is None:
        return None
    this = {"scenario": scenario, "seed": seed, "overrides": list(overrides)}
    if all(steered.get(key) == this[key] for key in _STEERED_RUN):
        return None

    def run(items):
        sets = "".join(f", --set {o}" for o in items.get("overrides") or ())
        return f"{items.get('scenario')} (seed {items.get('seed')}{sets})"

    return (
        f"warning: --replay-inputs {str(path)!r} was steered on {run(steered)}; this run is "
        f"{run(this)}, so its inputs act on another run"
    )


def load_inputs(path):
    """``(inputs, steered)``: the inputs recorded in ``path``, a run's summary JSON (its
    ``inputs``) or a JSON list of ``{"frame", "kind", "value"}``, and for a summary the run
    they steered (its ``scenario``, ``seed`` and ``overrides``; None for a list);
    ``UsageError`` naming what is wrong."""
    what = f"--replay-inputs {str(path)!r}"
    try:
        with open(path) as f:
            data = json.load(f)
    except FileNotFoundError:
        raise UsageError(
            f"{what}: no such file (give the --summary JSON of a run with live input)"
        ) from None
    except (OSError, ValueError) as exc:
        raise UsageError(f"{what}: not readable JSON ({exc})") from None
    steered = None
    if isinstance(data, dict):
        steered = {key: data[key] for key in _STEERED_RUN if key in data} or None
        if "inputs" not in data:
            raise UsageError(
                f"{what}: the summary has no 'inputs' (it was not a run with "
                f"--live or --interactive)"
            )
        data = data["inputs"]
    if not isinstance(data, list):
        raise UsageError(f"{what}: expected a list of inputs")
    out = []
    for i, item in enumerate(data):
        try:
            if not isinstance(item, dict):
                raise TypeError("not an object")
            frame = item.get("frame")
            if isinstance(frame, bool) or not isinstance(frame, int) or frame < 0:
                raise ValueError(f"frame must be an integer >= 0, got {frame!r}")
            kind, value = check_input(item.get("kind"), item.get("value"))
        except (ValueError, TypeError) as exc:
            raise UsageError(f"{what}: input {i}: {exc}") from None
        out.append({"frame": frame, "kind": kind, "value": value})
    return out, steered
