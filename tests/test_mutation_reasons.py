"""Why a blind spot shows no robot-level behaviour (fpga_robotics/mutation/reasons.py): the
reason class and its data, computed from the unit judge's verdict; and the data the unit
judge keeps for it (frames with a difference, the largest difference of each output)."""

import dataclasses

import numpy as np

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.mutation.reasons import blind_spot_reason, reason_class
from fpga_robotics.mutation.unit_judge import (
    UnitVerdict,
    golden_results,
    judge_frames,
    judge_mutant,
)

W = 160


def _verdict(frames=104, differing_frames=0, failure=None, max_difference=None, **differing):
    v = UnitVerdict(
        index=1,
        caught=True,
        first_frame=0,
        failure=failure,
        frames=frames,
        frames_differing=differing_frames,
        max_difference=max_difference or {},
    )
    v.differing.update(differing)
    return v


def test_outputs_no_check_or_wheel_uses():
    v = _verdict(differing_frames=70, filtered=70)
    assert reason_class(v, W) == "filtered only"
    assert blind_spot_reason(v, W) == (
        "filtered only: differs in 70 of 104 unit frames, only on the filtered video output, "
        "which no check or wheel uses"
    )
    v = _verdict(differing_frames=3, centroid_leds=3, max_difference={"centroid_leds": 16})
    assert reason_class(v, W) == "LEDs only"
    assert blind_spot_reason(v, W) == "LEDs only: differs in 3 of 104 unit frames (centroid_leds)"


def test_small_steering_errors_by_their_size():
    # Centroid off by 1 px (5 px is the limit at 160 wide), wheels by 3 DPS (limit 20).
    v = _verdict(
        differing_frames=21,
        centroid_x=21,
        motor_left=21,
        motor_right=21,
        max_difference={"centroid_x": 1, "motor_left": 3, "motor_right": 3},
    )
    assert reason_class(v, W) == "small steering error"
    assert blind_spot_reason(v, W) == (
        "small steering error: differs in 21 of 104 unit frames (centroid_x, motor_left, "
        "motor_right); centroid off by up to 1 px; wheels off by up to 3 DPS"
    )
    assert reason_class(dataclasses.replace(v, max_difference={"centroid_x": 5}), W) == (
        "small steering error"
    )
    # 6 px is no longer small at 160 wide, but is at 320 wide (limit 10 px); in 21 of 104
    # frames (more than 5 %) it is no rare state either.
    wide = dataclasses.replace(v, max_difference={"centroid_x": 6, "motor_left": 3})
    assert reason_class(wide, W) == "other" and reason_class(wide, 320) == "small steering error"
    fast = dataclasses.replace(v, max_difference={"centroid_x": 1, "motor_right": 21})
    assert reason_class(fast, W) == "other"


def test_rare_states_and_the_rest():
    # A search command wrong in 4 of 104 frames (at most 5 % of them: 5.2 frames).
    v = _verdict(differing_frames=4, motor_right=4, max_difference={"motor_right": 2048})
    assert reason_class(v, W) == "rare state"
    assert blind_spot_reason(v, W) == (
        "rare state: differs in 4 of 104 unit frames (motor_right); wheels off by up to 2048 DPS"
    )
    v = _verdict(differing_frames=6, motor_right=6, max_difference={"motor_right": 2048})
    assert reason_class(v, W) == "other"
    v = _verdict(
        differing_frames=67,
        found=3,
        proximity=12,
        centroid_x=49,
        motor_left=67,
        max_difference={"found": 1, "proximity": 3, "centroid_x": 80, "motor_left": 450},
    )
    assert blind_spot_reason(v, W) == (
        "other: differs in 67 of 104 unit frames (found, proximity, centroid_x, motor_left); "
        "centroid off by up to 80 px; wheels off by up to 450 DPS; proximity off by up to 3"
    )
    v = _verdict(frames=3, differing_frames=1, failure="no frame_done within 20000 cycles")
    assert blind_spot_reason(v, W) == (
        "frame protocol: no frame_done within 20000 cycles (the closed loop went on)"
    )


class _OffByThree:
    """A design that answers as the model does, except frame 2's centroid (3 px more) and
    frame 5's right wheel (10 DPS less)."""

    def __init__(self, params):
        from fpga_robotics.sim.backends import get_backend

        self.model = get_backend("model", params)
        self.frame = 0

    def set_runtime(self, name, value):
        pass

    def reset(self):
        self.model.reset()
        self.frame = 0

    def process_frame(self, frame, color):
        r = self.model.process_frame(frame, color)
        k, self.frame = self.frame, self.frame + 1
        if k == 2:
            r = dataclasses.replace(r, centroid_x=r.centroid_x + 3)
        if k == 5:
            r = dataclasses.replace(
                r, motor_right=r.motor_right - 10, filtered=np.zeros_like(r.filtered) + 1
            )
        return r


def test_the_unit_judge_keeps_the_frames_and_the_largest_differences():
    params = FollowTargetParams(width=80, height=60)
    frames = judge_frames(params)
    v = judge_mutant(_OffByThree(params), 1, frames, golden_results(params, frames))
    assert v.caught and v.first_frame == 2
    assert v.frames == len(frames) and v.frames_differing == 2
    assert v.max_difference == {"centroid_x": 3, "motor_right": 10}
    assert v.differing["filtered"] == 1 and v.differing["centroid_x"] == 1
    # The filtered image differs too (not a steering error alone); 2 of 104 frames: rare.
    assert reason_class(v, 80) == "rare state"


def _results(rows, robot, reasons=None):
    """mutants.json's content for ``rows`` (``(Mutant, unit verdict)``), the robot verdicts
    ``robot`` (``{index: verdict}``) and, for FollowTarget, the blind spots' ``reasons``
    (``{index: reason}``), as ``mutate`` writes it."""
    from fpga_robotics.mutation.scores import by_module, robot_score, unit_score

    mutants = [m for m, _ in rows]
    unit = {v.index: v.caught for _, v in rows}
    caught = {k: v["caught"] for k, v in robot.items()}
    return {
        "unit": unit_score(unit),
        "robot": robot_score(unit, caught),
        "campaign": "mutation",
        "baseline": {"runs": [["--scenario", "approach"]], "passing": [0]},
        "modules": by_module(mutants, unit, caught),
        "mutants": [
            {
                **m.__dict__,
                "sources": list(m.sources),
                "describe": m.describe(),
                "unit": {"caught": v.caught, "effect": v.effect()},
                "robot": robot.get(m.index),
                **({"blind_spot_reason": reasons.get(m.index)} if reasons is not None else {}),
            }
            for m, v in rows
        ],
    }


def _mutant(i, module, signal):
    from fpga_robotics.sim.mutation import Mutant

    return Mutant(i, "inv", module, "$1", "Y", 0, None, signal, 0, ("hw/x.py:1",), "")


ROBOT = {
    1: {"caught": False, "replay": "python -m fpga_robotics.run --runtime mutsel=1"},
    2: {"caught": False, "replay": None},
    3: {"caught": True, "status": "fail", "failed_checks": ["max_wheel_command_dps"]},
}


def test_the_report_gives_each_blind_spot_its_reason(tmp_path):
    """report.html: mutant 1 (only the filtered image differs) and 2 (a 1 px centroid error)
    are blind spots, each with its reason; mutant 3, caught by a run, has none."""
    from fpga_robotics.mutation.report import write_report

    filtered = _verdict(differing_frames=70, filtered=70)
    small = _verdict(
        differing_frames=21, centroid_x=21, max_difference={"centroid_x": 1, "motor_left": 3}
    )
    wheel = _verdict(differing_frames=90, motor_left=90, max_difference={"motor_left": 4096})
    for k, v in enumerate((filtered, small, wheel), start=1):
        v.index = k
    rows = [
        (_mutant(1, "color_filter", "filtered__payload"), filtered),
        (_mutant(2, "tracker.counter", "px"), small),
        (_mutant(3, "motor", "motor_left"), wheel),
    ]
    reasons = {k: blind_spot_reason(v, W) for k, v in ((1, filtered), (2, small))}
    results = _results(rows, ROBOT, reasons)
    path = write_report(
        str(tmp_path), results, {1: "recordings/mutant1.rrd"}, title="ft", inputs="the unit frames"
    )
    with open(path) as f:
        text = f.read()
    assert "why no run shows it" in text
    assert "filtered only: differs in 70 of 104 unit frames" in text
    assert (
        "small steering error: differs in 21 of 104 unit frames (centroid_x); centroid "
        "off by up to 1 px; wheels off by up to 3 DPS"
    ) in text
    assert "Blind spots: caught by the unit judge, missed by every run (2)" in text
    assert "other: differs in 90" not in text and "max_wheel_command_dps" in text
    assert '<a href="recordings/mutant1.rrd">' in text


class _TwoTraces:
    """A pin backend stand-in whose outputs follow a fixed change list per ``mutsel``."""

    def __init__(self, traces):
        self.traces, self.mutsel = traces, 0

    def reset(self):
        pass

    def poke(self, name, value):
        self.mutsel = value

    def schedule_many(self, name, edges, values):
        pass

    def peek(self, name):
        return self.traces[self.mutsel][name][0][1]

    def record_changes(self, cycles, outputs):
        return {name: self.traces[self.mutsel][name][1:] for name in outputs}


def _pin_verdict(mutant, design, cycles=1000, ports=None):
    from fpga_robotics.mutation.pin_judge import judge_pin_mutant, pin_trace

    backend = _TwoTraces({0: design, 1: mutant})
    reference = pin_trace(backend, 0, [], cycles, list(design))
    return judge_pin_mutant(backend, 1, [], cycles, reference, ports)


def test_a_pin_verdict_counts_the_cycles_its_outputs_differ():
    """By hand: motor differs in cycles 100-149 (by 40, signed: 20 against -20) and
    200-299 (by 5); led in 120-179; any output in 100-179 and 200-299: 180 cycles."""
    from fpga_robotics.sim.pins.base import Port

    design = {
        "motor": [(0, 0), (100, 20), (150, 0), (200, 5), (300, 0)],
        "led": [(0, 0)],
        "still": [(0, 7)],
    }
    mutant = {
        "motor": [(0, 0), (100, 0xFFEC), (150, 0), (300, 0)],  # -20 in 16 bits
        "led": [(0, 0), (120, 1), (180, 0)],
        "still": [(0, 7)],
    }
    ports = {"motor": Port("motor", 16, "out", True)}
    v = _pin_verdict(mutant, design, ports=ports)
    assert v.caught and v.first_cycle == 100
    assert v.extent == {"motor": (150, 40), "led": (60, 1)}
    assert v.cycles_differing == 180
    # Read unsigned, -20 is 65516: 65496 from 20.
    assert _pin_verdict(mutant, design).extent["motor"] == (150, 65496)
    # The pin model gives a signed port's values signed already: -20 stays -20.
    signed = {**mutant, "motor": [(0, 0), (100, -20), (150, 0), (300, 0)]}
    assert _pin_verdict(signed, design, ports=ports).extent["motor"] == (150, 40)


def test_a_pin_blind_spot_s_reason_class():
    """The classes of a design's blind spots: filtered only, recorded only, rare state (at
    most 5% of the cycles), other."""
    from fpga_robotics.mutation.reasons import pin_blind_spot_reason

    design = {"motor": [(0, 0)], "dist": [(0, 0)], "px": [(0, 0)]}
    pixels = _pin_verdict({**design, "px": [(0, 0), (10, 3)]}, design)
    assert pin_blind_spot_reason(pixels, "px", {"dist"}) == (
        "filtered only: differs during 99% of the 1000 random-input cycles (px: 990 cycles, "
        "off by up to 3), from cycle 10; only the filtered video's payload, whose pixels no "
        "check or wheel uses"
    )
    recorded = _pin_verdict({**design, "dist": [(0, 0), (500, 9)]}, design)
    assert pin_blind_spot_reason(recorded, "px", {"dist"}).startswith(
        "recorded only: differs during 50% of the 1000 random-input cycles (dist: 500 cycles"
    )
    rare = _pin_verdict({**design, "motor": [(0, 0), (400, 300), (450, 0)]}, design)
    assert pin_blind_spot_reason(rare, "px", {"dist"}) == (
        "rare state: differs during 5% of the 1000 random-input cycles (motor: 50 cycles, "
        "off by up to 300), from cycle 400"
    )
    often = _pin_verdict({**design, "motor": [(0, 0), (400, 300), (451, 0)]}, design)
    assert pin_blind_spot_reason(often, "px", {"dist"}).startswith("other: differs during 5.1%")
    # A wheel with the recorded output: it moves the robot, so not "recorded only".
    both = _pin_verdict({**design, "motor": [(0, 1)], "dist": [(0, 1)]}, design)
    assert pin_blind_spot_reason(both, "px", {"dist"}).startswith("other: differs during 100%")


def test_a_design_s_report_gives_each_blind_spot_its_reason(tmp_path):
    """A design of one's own: its report lists its blind spots with the pin reasons."""
    from fpga_robotics.mutation.pin_judge import PinVerdict
    from fpga_robotics.mutation.reasons import pin_blind_spot_reason
    from fpga_robotics.mutation.report import write_report

    verdicts = [
        PinVerdict(k, True, 3, {"hit": True}, {"hit": (0, 1)}, 2000, {"hit": (9, 1)}, 9)
        for k in (1, 2, 3)
    ]
    rows = [(_mutant(v.index, "", "hit"), v) for v in verdicts]
    reasons = {k: pin_blind_spot_reason(verdicts[k - 1]) for k in (1, 2)}
    path = write_report(
        str(tmp_path),
        _results(rows, ROBOT, reasons),
        {},
        title="BumpGuard",
        inputs="these inputs",
    )
    with open(path) as f:
        text = f.read()
    assert "Mutation coverage of BumpGuard" in text and "equivalent on these inputs" in text
    assert "Blind spots: caught by the unit judge, missed by every run (2)" in text
    assert text.count("differs from cycle 3: hit 0 -&gt; 1") == 2
    assert "why no run shows it" in text
    assert text.count("rare state: differs during 0.45% of the 2000 random-input cycles") == 2


def test_a_filtered_image_difference_is_counted_in_pixels():
    """Two filtered pixels swapped (one on, one off): the image differs though the count of
    matching pixels does not; the effect says how many pixels differ, not "1819 -> 1819"."""
    params = FollowTargetParams()
    frames = judge_frames(params)[:3]
    golden = golden_results(params, frames)

    class Swapping:
        def set_runtime(self, name, value):
            pass

        def reset(self):
            self.k = 0

        def process_frame(self, frame, color):
            want = golden[self.k]
            self.k += 1
            if self.k < 2:
                return want
            image = want.filtered.copy()
            on, off = np.argwhere(image != 0)[0], np.argwhere(image == 0)[0]
            image[tuple(off)], image[tuple(on)] = image[tuple(on)], 0
            return dataclasses.replace(want, filtered=image)

    v = judge_mutant(Swapping(), 1, frames, golden)
    matching = int((golden[1].filtered != 0).sum())
    assert v.first_frame == 1 and v.first_difference == {"filtered": (matching, matching)}
    assert v.first_filtered_pixels == 2
    assert v.effect() == "differs from frame 1: filtered 2 pixel(s) differ; filtered in 2 frame(s)"
