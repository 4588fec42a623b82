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


def test_a_design_s_report_has_no_reason_column(tmp_path):
    """A design of one's own has no reason classes (they read FollowTarget's outputs): its
    report lists the same blind spots without the column."""
    from fpga_robotics.mutation.pin_judge import PinVerdict
    from fpga_robotics.mutation.report import write_report

    verdicts = [PinVerdict(k, True, 3, {"hit": True}, {"hit": (0, 1)}, 2000) for k in (1, 2, 3)]
    rows = [(_mutant(v.index, "", "hit"), v) for v in verdicts]
    path = write_report(
        str(tmp_path), _results(rows, ROBOT), {}, title="BumpGuard", inputs="these inputs"
    )
    with open(path) as f:
        text = f.read()
    assert "Mutation coverage of BumpGuard" in text and "equivalent on these inputs" in text
    assert "Blind spots: caught by the unit judge, missed by every run (2)" in text
    assert text.count("differs from cycle 3: hit 0 -&gt; 1") == 2
    assert "why no run shows it" not in text
