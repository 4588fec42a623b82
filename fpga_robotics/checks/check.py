"""What a check is: a pass criterion a scenario may set in its ``[checks]`` table, declared once
(``Check``), and its outcome on a run's metrics (``judge``): pass, fail, or n/a with the reason
it could not judge.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["COMPARISONS", "DESIGN_OUTPUTS", "STATUSES", "Check", "judge", "measured"]

#: The design's per-frame scalar outputs. A design may lack some (a foreign Verilog design whose
#: port map names no such port: its ``FrameResult`` holds None); those are *absent*, never 0:
#: NaN in the trajectory, listed in ``absent_outputs``, the metrics made of them None, the
#: checks that need them n/a (left out of the verdict), nothing drawn for them in the viewer.
DESIGN_OUTPUTS = ("found", "proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right")

#: ``max``: the metric must be at most the limit; ``min``: at least the limit.
COMPARISONS = ("max", "min")
#: A check's outcome.
STATUSES = ("pass", "fail", "n/a")


@dataclass(frozen=True)
class Check:
    """One pass criterion.

    name : the key in a scenario's ``[checks]`` table.
    metric : the key of the run's metrics it reads, or a function of the metrics.
    compare : ``"max"`` (metric <= limit) or ``"min"`` (metric >= limit); a missing (None)
        metric fails.
    meaning : what passing means, one sentence (the docs' table and error messages).
    message : ``message(value, limit, metrics)``, the result's text once judged.
    kind, limits : the type of the limit (``int`` or ``float``) and ``(lowest, highest, unit)``
        a scenario may set.
    outputs : the design outputs it is measured from; a design lacking one makes it n/a.
    sensors : the kinds of robot sensor (``[[robot.sensors]]`` ``kind``) whose measurements
        it reads; a run in which no sensor of a kind measured anything makes it n/a.
    precondition : ``precondition(metrics)`` -> None when the run can be judged, else the
        reason it cannot (the check is n/a, e.g. "the design never searched").
    passes : ``passes(value, limit, metrics)`` for a criterion that is more than one comparison
        (None: ``compare`` decides); it returns True, False, or None when the run leaves
        nothing to judge against this limit (the check is n/a, its message the reason).
    """

    name: str
    metric: Any
    compare: str
    meaning: str
    message: Callable
    kind: type = float
    limits: tuple = (0, math.inf, "")
    outputs: tuple = ()
    sensors: tuple = ()
    precondition: Callable | None = None
    passes: Callable | None = None

    def __post_init__(self):
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise ValueError(f"a check's name must be an identifier, got {self.name!r}")
        if self.compare not in COMPARISONS:
            raise ValueError(
                f"check {self.name}: compare must be one of {COMPARISONS}, got {self.compare!r}"
            )
        if self.kind not in (int, float):
            raise ValueError(f"check {self.name}: kind must be int or float, got {self.kind!r}")
        unknown = [o for o in self.outputs if o not in DESIGN_OUTPUTS]
        if unknown:
            raise ValueError(
                f"check {self.name}: unknown design output(s) {unknown}; "
                f"known: {', '.join(DESIGN_OUTPUTS)}"
            )
        lo, hi, unit = self.limits
        if not lo <= hi or not isinstance(unit, str):
            raise ValueError(f"check {self.name}: limits must be (lowest, highest, unit)")

    def value(self, metrics):
        """The metric this check reads (None when the run did not measure it)."""
        return self.metric(metrics) if callable(self.metric) else metrics.get(self.metric)


def measured(metric, reason):
    """A precondition: the run measured ``metric`` (not None), else ``reason``."""

    def precondition(m):
        return reason if m.get(metric) is None else None

    return precondition


def _result(check, status, value, limit, text, reason=None):
    passed = {"pass": True, "fail": False, "n/a": None}[status]
    return {
        "name": check.name,
        "status": status,
        "passed": passed,
        "value": value,
        "limit": limit,
        "text": text,
        "reason": reason,
    }


def _silent(kinds, m):
    """Why the sensors of ``kinds`` cannot be judged (none, or none measured), else None."""
    sensor_kinds = m.get("sensor_kinds") or {}
    counts = m.get("measured_frames") or {}
    for kind in kinds:
        names = [n for n, k in sensor_kinds.items() if k == kind]
        if not names:
            return f"the robot has no {kind} sensor"
        if not any(counts.get(n, 0) for n in names):
            return f"no {kind} measurement arrived"
    return None


def judge(check, limit, m):
    """The outcome of ``check`` with ``limit`` on the metrics ``m``: a result dict with
    ``status`` ("pass", "fail" or "n/a"), ``passed`` (True, False or None), ``value``,
    ``limit``, ``text`` and ``reason`` (why it is n/a; None otherwise)."""
    absent = m.get("absent_outputs") or ()
    missing = [o for o in check.outputs if o in absent]
    if missing:
        names = " or ".join(f"`{o}`" for o in missing)
        reason = f"not measured: the design has no {names} output"
        return _result(check, "n/a", None, limit, reason, reason)
    reason = _silent(check.sensors, m)
    if reason is None and check.precondition is not None:
        reason = check.precondition(m)
    if reason is not None:
        return _result(check, "n/a", None, limit, reason, reason)
    v = check.value(m)
    if check.passes is not None:
        ok = check.passes(v, limit, m)
    elif v is None:
        ok = False
    else:
        ok = v <= limit if check.compare == "max" else v >= limit
    text = check.message(v, limit, m)
    if ok is None:
        return _result(check, "n/a", None, limit, text, text)
    return _result(check, "pass" if ok else "fail", v, limit, text)
