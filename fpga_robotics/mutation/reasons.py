"""Why a blind spot (a mutant the unit judge catches and no run of the campaign does) shows
no robot-level behaviour: a short reason class computed from what the mutant does to the
outputs on the unit frames (``UnitVerdict``), for the terminal, ``report.html`` and
``mutants.json``.

The classes, in the order they are tried:

- ``filtered only``: only the filtered video output differs; no check and no wheel uses it;
- ``LEDs only``: only the centroid LEDs differ;
- ``small steering error``: only the centroid, the proximity level and the wheel commands
  differ, the centroid by at most ``SMALL_CENTROID_FRACTION`` of the width and each wheel by
  at most ``SMALL_WHEEL_DPS``: the robot still follows within every check's limit;
- ``rare state``: the outputs differ in at most ``RARE_FRACTION`` of the unit frames (a state
  the runs reach seldom or never, e.g. one proximity level or one side's search);
- ``other``: none of these (the documentation says more about each such mutant).

A design of one's own (``mutate --design``) has no golden model and outputs of its own, so
its blind spots' classes read the pin unit judge's data (``PinVerdict``: the outputs that
differ, during how many of the random-input cycles, by how much): ``filtered only`` (only
the filtered stream's payload differs), ``recorded only`` (only outputs its port map lists
as ``[extra_outputs]``: recorded, read by no check, moving nothing), ``rare state`` (the
outputs differ during at most ``RARE_FRACTION`` of the cycles) or
``other``.
"""

__all__ = [
    "RARE_FRACTION",
    "SMALL_CENTROID_FRACTION",
    "SMALL_WHEEL_DPS",
    "blind_spot_reason",
    "pin_blind_spot_reason",
    "reason_class",
]

#: A centroid error this fraction of the image width or less is small (5 px at 160x120:
#: what the LED checks allow near a border).
SMALL_CENTROID_FRACTION = 1 / 32
#: A wheel command off by this many DPS or less is small (0.012 m/s on a TurtleBot2's 35 mm
#: wheels, a twentieth of the design's 400 DPS top base speed).
SMALL_WHEEL_DPS = 20
#: A mutant that changes the outputs in this fraction of the unit frames or fewer acts in a
#: rare state.
RARE_FRACTION = 0.05

_STEERING = {"centroid_x", "proximity", "motor_left", "motor_right"}


def _outputs(verdict):
    return {name for name, n in verdict.differing.items() if n}


def reason_class(verdict, width):
    """The class of a unit-caught mutant's effect (see the module's docstring)."""
    outs = _outputs(verdict)
    if verdict.failure is not None:
        return "frame protocol"
    if outs <= {"filtered"}:
        return "filtered only"
    if outs <= {"centroid_leds"}:
        return "LEDs only"
    big = verdict.max_difference
    if (
        outs <= _STEERING
        and big.get("centroid_x", 0) <= SMALL_CENTROID_FRACTION * width
        and max(big.get("motor_left", 0), big.get("motor_right", 0)) <= SMALL_WHEEL_DPS
    ):
        return "small steering error"
    if verdict.frames and verdict.frames_differing <= RARE_FRACTION * verdict.frames:
        return "rare state"
    return "other"


def blind_spot_reason(verdict, width):
    """One line: the reason class and the data behind it, e.g. ``"small steering error:
    differs in 21 of 104 unit frames (centroid_x, motor_left, motor_right); centroid off by
    up to 1 px; wheels off by up to 3 DPS"``."""
    cls = reason_class(verdict, width)
    if cls == "frame protocol":
        return f"frame protocol: {verdict.failure} (the closed loop went on)"
    if cls == "filtered only":
        return (
            f"filtered only: differs in {verdict.differing['filtered']} of "
            f"{verdict.frames} unit frames, only on the filtered video output, which no "
            f"check or wheel uses"
        )
    outs = [name for name, n in verdict.differing.items() if n]
    text = (
        f"{cls}: differs in {verdict.frames_differing} of {verdict.frames} unit frames "
        f"({', '.join(outs)})"
    )
    big = verdict.max_difference
    if "centroid_x" in big:
        text += f"; centroid off by up to {big['centroid_x']} px"
    wheels = max(big.get("motor_left", 0), big.get("motor_right", 0))
    if wheels:
        text += f"; wheels off by up to {wheels} DPS"
    if "proximity" in big:
        text += f"; proximity off by up to {big['proximity']}"
    return text


def pin_blind_spot_reason(verdict, filtered=None, recorded=()):
    """One line for a blind spot of a design of one's own (``verdict``: its ``PinVerdict``;
    ``filtered``: the name of the design's filtered-stream payload output, if any;
    ``recorded``: its outputs that are only recorded), e.g.
    ``"rare state: differs during 0.18% of the 100000 random-input cycles (motor_left: 180
    cycles, off by up to 40), from cycle 51234"``."""
    extent = {name: verdict.extent.get(name, (0, 0)) for name, d in verdict.differing.items() if d}
    during = verdict.cycles_differing
    if filtered is not None and set(extent) == {filtered}:
        cls = "filtered only"
    elif set(extent) <= set(recorded):
        cls = "recorded only"
    elif during <= RARE_FRACTION * verdict.cycles:
        cls = "rare state"
    else:
        cls = "other"
    share = 100 * during / verdict.cycles if verdict.cycles else 0.0
    share = f"{share:.0f}" if share >= 10 else f"{share:.2g}"  # 37%, 2.5%, 0.03%
    outputs = "; ".join(
        f"{name}: {n} cycles, off by up to {largest}" for name, (n, largest) in extent.items()
    )
    text = (
        f"{cls}: differs during {share}% of the {verdict.cycles} random-input cycles "
        f"({outputs}), from cycle {verdict.first_cycle}"
    )
    if cls == "filtered only":
        text += "; only the filtered video's payload, whose pixels no check or wheel uses"
    elif cls == "recorded only":
        text += "; only outputs that are recorded, which no check reads and nothing acts on"
    return text
