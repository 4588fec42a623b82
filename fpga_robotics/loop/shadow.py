"""Shadow runs: a second design sees exactly the frames the first one sees, in lockstep, without
driving the robot; where their outputs part is reported frame by frame.

This is how a refactored design is checked against the reference in closed loop: the robot
moves as the primary design decides, so both designs get the same inputs, and the first frame
at which they decide differently is the place to look.
"""

from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "COMPARED_OUTPUTS",
    "ShadowComparison",
    "differing_outputs",
    "divergence_event",
    "format_shadow",
    "is_shadow_event",
    "output_value",
    "shadow_overrides",
]

#: The outputs compared frame by frame (the filtered image is compared as a pixel count).
COMPARED_OUTPUTS = (
    "found",
    "proximity",
    "centroid_x",
    "centroid_leds",
    "motor_left",
    "motor_right",
    "filtered",
)


def shadow_overrides(spec):
    """``--shadow SPEC`` as scenario overrides of the ``[design]`` section.

    ``SPEC`` is a preset name (``published``), ``KEY=VALUE`` items separated by ``;``
    (``diff_min=5;kp_num=2``; ``design.`` may be written or left out), or both
    (``published;max_dps=400``: the preset first, the items on top). A key (or a preset)
    given twice is a ``ValueError``: the last would win unseen.
    """
    items = [part.strip() for part in str(spec).split(";") if part.strip()]
    if not items:
        raise ValueError(
            "--shadow needs a preset name or KEY=VALUE items, e.g. "
            "--shadow published or --shadow 'diff_min=5;kp_num=2'"
        )
    out = {}
    for item in items:
        key, value = item.split("=", 1) if "=" in item else ("preset", f'"{item}"')
        key = key.strip().removeprefix("design.")
        if key in out:
            what = "a preset" if key == "preset" else key
            raise ValueError(f"{what} is given twice: give it once")
        out[key] = f"design.{key}={value.strip()}"
    return list(out.values())


def output_value(result, name):
    """Output ``name`` of a ``FrameResult`` as a plain value for a report (the filtered image
    as its count of matching pixels)."""
    if name == "filtered":
        return int((result.filtered != 0).sum())  # matching pixels; compared as images
    value = getattr(result, name)
    return bool(value) if name == "found" else int(value)


def differing_outputs(a, b):
    """The ``COMPARED_OUTPUTS`` in which two ``FrameResult``s differ; an output either of them
    lacks (None) is not compared."""
    differ = []
    for name in COMPARED_OUTPUTS:
        x, y = getattr(a, name), getattr(b, name)
        if x is None or y is None:
            continue
        if not (np.array_equal(x, y) if name == "filtered" else x == y):
            differ.append(name)
    return differ


@dataclass
class ShadowComparison:
    """Collects where a shadow design's outputs differ from the primary design's."""

    label: str
    differing_frames: dict = field(default_factory=lambda: dict.fromkeys(COMPARED_OUTPUTS, 0))
    first_divergence: dict | None = None
    frames: int = 0

    def compare(self, frame, time_s, primary, shadow):
        """Compare one frame's results; return the names of the outputs that differ."""
        self.frames += 1
        differ = differing_outputs(primary, shadow)
        for name in differ:
            self.differing_frames[name] += 1
        if differ and self.first_divergence is None:
            self.first_divergence = {
                "frame": frame,
                "time_s": round(time_s, 6),
                "outputs": {n: _first_values(primary, shadow, n) for n in differ},
            }
        return differ

    def summary(self):
        """JSON-ready: what was compared, the first divergence and the counts."""
        return {
            "design": self.label,
            "frames": self.frames,
            "first_divergence": self.first_divergence,
            "differing_frames": dict(self.differing_frames),
        }


def _first_values(primary, shadow, name):
    """The two designs' values of output ``name`` where they first part; for the filtered
    image also how many pixels differ (its counts of matching pixels may be equal)."""
    values = {"primary": output_value(primary, name), "shadow": output_value(shadow, name)}
    if name == "filtered":
        values["pixels_differing"] = int((primary.filtered != shadow.filtered).sum())
    return values


def _difference(name, values):
    if "pixels_differing" in values:
        return f"filtered {values['pixels_differing']} pixel(s) differ"
    return f"{name} {values['primary']} vs {values['shadow']}"


def divergence_event(label, differ, primary, shadow):
    """The event text for the first frame where the designs part."""
    parts = ", ".join(_difference(n, _first_values(primary, shadow, n)) for n in differ)
    return f"shadow design {label} diverges: {parts}"


def is_shadow_event(text):
    """Whether an event is a shadow design's (``divergence_event``, pin_shadow's alike)."""
    return text.startswith("shadow design ")


def format_shadow(summary):
    """Lines for the human summary; a design of one's own is named with the parameters it
    ran with (``params``: a changed default the scenario sets does not show)."""
    first = summary["first_divergence"]
    label = summary["design"]
    if "params" in summary:
        given = ", ".join(f"{n}={v!r}" for n, v in summary["params"].items())
        label += f" with {given or 'its defaults'}"
    if first is None:
        return [f"  shadow {label}: identical outputs on all {summary['frames']} frames"]
    counts = ", ".join(f"{n} {c}" for n, c in summary["differing_frames"].items() if c)
    what = ", ".join(_difference(n, v) for n, v in first["outputs"].items())
    return [
        (
            f"  shadow {label}: first differs at frame {first['frame']} "
            f"({first['time_s']:.2f} s): {what}"
        ),
        f"  shadow frames that differ: {counts} (of {summary['frames']})",
    ]
