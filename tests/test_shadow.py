"""Shadow runs: a second design on the same frames, in lockstep, never driving the robot."""

import dataclasses

import numpy as np
import pytest

from fpga_robotics.loop.shadow import COMPARED_OUTPUTS, shadow_overrides
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend


def test_shadow_spec_becomes_design_overrides():
    assert shadow_overrides("published") == ['design.preset="published"']
    assert shadow_overrides("diff_min=5; design.kp_num=2") == [
        "design.diff_min=5",
        "design.kp_num=2",
    ]
    assert shadow_overrides("published;max_dps=400") == [
        'design.preset="published"',
        "design.max_dps=400",
    ]
    with pytest.raises(ValueError, match="preset name"):
        shadow_overrides(" ; ")
    # A key or preset named twice: the later one would win while the label shows both.
    for spec, what in [
        ("diff_min=15;diff_min=6", "diff_min"),
        ("diff_min=15;design.diff_min=6", "diff_min"),
        ("published;published", "a preset"),
    ]:
        with pytest.raises(ValueError, match=f"^{what} is given twice: give it once$"):
            shadow_overrides(spec)


def test_the_design_shadowed_by_itself_never_differs():
    s = load_scenario("lost_target", ["sim.duration=8"])
    with ModelBackend(s.params) as shadow:
        r = run_scenario(s, backend="model", shadow=shadow, shadow_label="same")
    sh = r.summary["shadow"]
    assert sh["frames"] == r.summary["frames"]
    assert sh["first_divergence"] is None
    assert sh["differing_frames"] == dict.fromkeys(COMPARED_OUTPUTS, 0)


def test_a_shadow_of_another_resolution_is_refused_before_the_run():
    # It was a FrameError at frame 0 telling the caller to resize frames they never see.
    s = load_scenario("divider", ["sim.duration=1"])
    frames = []
    wrong = dataclasses.replace(s.params, width=320, height=240)
    with ModelBackend(wrong) as shadow, pytest.raises(ValueError) as info:
        run_scenario(s, backend="model", shadow=shadow, on_frame=frames.append)
    assert str(info.value) == (
        "the shadow backend is 320x240, the scenario's camera 160x120: build the shadow for "
        "the scenario's resolution"
    )
    assert frames == []


def test_shadow_does_not_drive_the_robot():
    s = load_scenario("lost_target", ["sim.duration=8"])
    alone = run_scenario(s, backend="model")
    other = s.with_overrides(["design.lost_frames=5", "design.search_dps=-300"]).params
    with ModelBackend(other) as shadow:
        shadowed = run_scenario(s, backend="model", shadow=shadow)
    for name in ("x", "y", "heading", "motor_left", "motor_right"):
        assert np.array_equal(alone.trajectory[name], shadowed.trajectory[name]), name


def test_first_divergence_is_where_the_shorter_lost_count_starts_searching():
    # Primary searches after 15 lost frames, the shadow after 5: the designs see the same
    # frames, so they part exactly at the 5th consecutive frame without the target (found
    # there and before agree; the motors differ: search versus hold).
    s = load_scenario("lost_target", ["sim.duration=12"])
    other = s.with_overrides(["design.lost_frames=5"]).params
    with ModelBackend(other) as shadow:
        r = run_scenario(s, backend="model", shadow=shadow, shadow_label="lost_frames=5")
    found = r.trajectory["found"]
    seen = False
    misses = 0
    expected = None
    for k, f in enumerate(found):
        seen |= bool(f)
        misses = 0 if f else misses + 1
        if seen and misses == 5:
            expected = k
            break
    assert expected is not None, "the scenario never loses the target"
    first = r.summary["shadow"]["first_divergence"]
    assert first["frame"] == expected
    assert set(first["outputs"]) <= {"motor_left", "motor_right"}
    assert first["outputs"]["motor_left"]["primary"] == r.trajectory["motor_left"][expected]
    events = [e for k, _t, e in r.events if k == expected]
    assert any(e.startswith("shadow design lost_frames=5 diverges") for e in events)
    assert r.summary["shadow"]["differing_frames"]["found"] == 0


def test_a_filtered_image_that_parts_says_how_many_pixels_differ():
    """Two filtered pixels swapped: the images differ but their counts of matching pixels do
    not, so the first divergence says how many pixels differ, not "1819 vs 1819"."""
    import dataclasses

    from fpga_robotics.loop.shadow import ShadowComparison, divergence_event, format_shadow
    from fpga_robotics.mutation.unit_judge import golden_results, judge_frames

    params = load_scenario("approach").params
    frame = judge_frames(params)[0]
    (primary,) = golden_results(params, [frame])
    image = primary.filtered.copy()
    on, off = tuple(np.argwhere(image != 0)[0]), tuple(np.argwhere(image == 0)[0])
    image[off], image[on] = image[on], 0
    shadow = dataclasses.replace(primary, filtered=image)
    comparison = ShadowComparison("swap")
    assert comparison.compare(0, 0.0, primary, shadow) == ["filtered"]
    first = comparison.summary()["first_divergence"]["outputs"]["filtered"]
    assert first["primary"] == first["shadow"] and first["pixels_differing"] == 2
    assert "filtered 2 pixel(s) differ" in format_shadow(comparison.summary())[0]
    assert divergence_event("swap", ["filtered"], primary, shadow) == (
        "shadow design swap diverges: filtered 2 pixel(s) differ"
    )
