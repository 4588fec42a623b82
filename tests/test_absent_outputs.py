"""Outputs a design lacks are absent, never 0: a foreign design whose port map names no
``found`` (or no centroid, LEDs, filtered stream) runs in closed loop, and the trajectory, the
metrics, the checks, the human summary, the viewer and a shadow comparison all say "absent"
instead of reporting zeros (docs/foreign.md)."""

import dataclasses
import json
import math

import numpy as np
import pytest

from fpga_robotics.checks.summary import (
    DESIGN_OUTPUTS,
    compute_metrics,
    evaluate_checks,
    format_summary,
    verdict,
)
from fpga_robotics.loop.shadow import ShadowComparison
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import get_backend
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import read_rrd

RES = "80x60"
CHECKS = (
    "acquired_within_s",
    "found_min_fraction",
    "max_off_target_fraction",
    "max_oscillation_hz",
    "mean_distance_max_m",
    "max_person_collisions",
)


class WithoutOutputs:
    """The model backend with some outputs removed, as a foreign design lacking those ports
    delivers them (None in its FrameResult)."""

    def __init__(self, params, lacking):
        self._inner = get_backend("model", params)
        self.lacking = lacking
        self.name = "model-without-" + "-".join(lacking)

    def process_frame(self, frame, color_sel="red"):
        r = self._inner.process_frame(frame, color_sel)
        return dataclasses.replace(r, **dict.fromkeys(self.lacking))

    def __getattr__(self, name):
        return getattr(self._inner, name)


def scenario():
    return load_scenario("follow_person", [f'camera.resolution="{RES}"', "sim.duration=3"])


@pytest.fixture(scope="module")
def runs():
    s = scenario()
    full = run_scenario(s, seed=3, backend=get_backend("model", s.params))
    lacking = ("found", "centroid_x", "centroid_leds", "filtered")
    part = run_scenario(s, seed=3, backend=WithoutOutputs(s.params, lacking))
    return full, part


def test_the_robot_moves_the_same_and_the_lacking_outputs_are_nan(runs):
    full, part = runs
    # The wheel commands are the same design's: the same run, frame for frame.
    for key in ("x", "y", "heading", "motor_left", "motor_right", "proximity"):
        np.testing.assert_array_equal(part.trajectory[key], full.trajectory[key], err_msg=key)
    assert full.trajectory["found"].any()  # the comparison means something
    for key in ("found", "centroid_x", "centroid_leds"):
        assert np.isnan(part.trajectory[key]).all(), key
    assert part.summary["absent_outputs"] == ["found", "centroid_x", "centroid_leds"]
    assert full.summary["absent_outputs"] == []


def test_metrics_of_absent_outputs_are_none_and_the_rest_unchanged(runs):
    full, part = runs
    for key in (
        "found_fraction",
        "acquired_at_s",
        "searches",
        "losses",
        "off_target_fraction",
        "mean_centroid_error_px",
        "oscillation_hz",
    ):
        assert part.summary[key] is None, key
    assert full.summary["found_fraction"] > 0.5
    for key in (
        "min_distance_m",
        "mean_distance_m",
        "path_length_m",
        "collisions",
        "target_in_view_fraction",
        "max_wheel_command_step_dps",
    ):
        assert part.summary[key] == full.summary[key], key
    # No found/lost events come from a design without `found`.
    assert not any(t in ("target found", "target lost") for _, _, t in part.events)
    assert any(t == "target found" for _, _, t in full.events)


def test_checks_that_need_an_absent_output_are_na_and_left_out_of_the_verdict(runs):
    _, part = runs
    m = {k: part.summary[k] for k in part.summary}
    limits = {
        "acquired_within_s": 1.0,
        "found_min_fraction": 0.9,
        "max_off_target_fraction": 0.1,
        "min_distance_min_m": 100.0,
    }
    checks = evaluate_checks(limits, m)
    by = {c["name"]: c for c in checks}
    for name in ("acquired_within_s", "found_min_fraction", "max_off_target_fraction"):
        assert by[name]["passed"] is None and by[name]["text"].startswith(
            "not measured: the design has no"
        )
    assert "`found`" in by["acquired_within_s"]["text"]
    # The measurable check still decides: keeping 100 m from the person is impossible.
    assert by["min_distance_min_m"]["passed"] is False
    assert verdict(checks) == "fail"
    # Without it every check set is n/a: no check could judge, which is no pass.
    assert verdict([c for c in checks if c["name"] != "min_distance_min_m"]) == "n/a"
    assert (
        verdict([c for c in checks if c["name"] in ("min_distance_min_m", "acquired_within_s")])
        == "fail"
    )
    text = format_summary({**part.summary, "checks": checks})
    assert "[n/a] acquired_within_s" in text and "found n/a" in text
    assert (
        "tracker outputs absent (no such port, or no camera frame to latch them): found, centroid_x"
        in text
    )


def test_the_summary_names_absent_wheels_as_wheels_and_no_recorded_output_absent(runs):
    # A camera-less design with a `found` output of its own and no wheels: its `found` is
    # recorded (no frame latches it for the checks), the wheels are absent.
    _, part = runs
    absent = ["found", "proximity", "centroid_x", "centroid_leds", "motor_left", "motor_right"]
    extra = {"found": {"last": 1, "min": 0, "max": 1}}
    text = format_summary({**part.summary, "absent_outputs": absent, "extra_outputs": extra})
    lines = text.splitlines()
    assert (
        "  tracker outputs absent (no such port, or no camera frame to latch them): "
        "proximity, centroid_x, centroid_leds"
    ) in lines
    assert "  wheel outputs absent (no wheels bound: 0 DPS): motor_left, motor_right" in lines
    assert "outputs absent" not in format_summary({**part.summary, "absent_outputs": []})


def test_compute_metrics_by_hand():
    # Three frames: found in the last two; with `found` absent the found metrics are None.
    traj = {
        "t": np.array([0.0, 0.1, 0.2]),
        "x": np.zeros(3),
        "y": np.array([0.0, 0.3, 0.7]),
        "heading": np.zeros(3),
        "target_distance": np.array([2.0, 1.5, 1.0]),
        "target_in_view": np.array([True, True, False]),
        "found": np.array([False, True, True]),
        "motor_left": np.array([0, 40, 10]),
        "motor_right": np.array([0, -20, 10]),
    }
    m = compute_metrics(traj, [], {}, 0.1)
    assert m["acquired_at_s"] == 0.1 and m["found_fraction"] == 2 / 3
    assert m["max_wheel_command_step_dps"] == 40  # |0 - 40|
    nan = {**traj, "found": np.full(3, np.nan), "motor_left": np.full(3, np.nan)}
    m = compute_metrics(nan, [], {}, 0.1, absent={"found", "motor_left"})
    assert m["acquired_at_s"] is None and m["found_fraction"] is None
    assert m["absent_outputs"] == ["found", "motor_left"]
    assert m["max_wheel_command_step_dps"] == 30  # the right wheel only: |-20 - 10|
    assert m["path_length_m"] == 0.7 and m["mean_distance_m"] == 1.5
    assert list(DESIGN_OUTPUTS).index("found") < list(DESIGN_OUTPUTS).index("motor_left")


def test_the_viewer_draws_absent_outputs_as_absent(tmp_path):
    s = load_scenario("follow_person", [f'camera.resolution="{RES}"', "sim.duration=0.5"])
    path = tmp_path / "absent.rrd"
    rec = open_recorder(f"save:{path}", default_path=None)
    lacking = ("found", "centroid_x", "centroid_leds", "filtered")
    result = run_scenario(s, seed=1, backend=WithoutOutputs(s.params, lacking), recorder=rec)
    rec.close()
    ents = read_rrd(str(path)).entities
    n = result.summary["frames"]
    assert len(ents[P.MOTORS_DPS]) == n and len(ents[P.LEDS_PROXIMITY]) == n
    assert P.LEDS_CENTROID not in ents and P.DESIGN_CENTROID_X not in ents
    assert P.CAMERA_FILTERED not in ents and len(ents[P.CAMERA_RAW]) == n
    rows = ents[P.DESIGN_TRACKING].values
    scalars = next(v for k, v in rows.items() if "calar" in k)
    found, proximity = zip(*scalars)
    assert all(math.isnan(f) for f in found)  # a gap, not a line at 0
    assert list(proximity) == [float(p) for p in result.trajectory["proximity"]]


def test_a_shadow_comparison_skips_outputs_one_design_lacks():
    s = scenario()
    model = get_backend("model", s.params)
    frame = np.zeros((60, 80, 3), np.uint8)
    frame[20:40, 30:50] = (230, 20, 20)
    a = model.process_frame(frame)
    b = dataclasses.replace(a, found=None, centroid_x=None, proximity=a.proximity + 1)
    cmp = ShadowComparison("part")
    assert cmp.compare(0, 0.0, a, b) == ["proximity"]
    assert cmp.differing_frames["found"] == 0
    json.dumps(cmp.summary())


@pytest.mark.slow
def test_a_foreign_design_without_found_runs_from_the_command_line(tmp_path, capsys):
    """The user's path: `run --design verilog:... --ports` with a map that names no `found`,
    no centroid and no filtered stream; the JSON summary says absent, the text says n/a."""
    pytest.importorskip("fpga_robotics.sim.backends.foreign")
    from fpga_robotics.cli import run
    from fpga_robotics.hw.verilog import generate_verilog
    from fpga_robotics.sim.backends import BackendError
    from fpga_robotics.sim.backends import toolchain as tc
    from fpga_robotics.sim.backends.port_map import follow_target_port_map

    try:
        tc.find_compiler(), tc.find_make(), tc.verilator_root()
    except BackendError as exc:  # pragma: no cover - depends on the machine
        pytest.skip(f"no Verilator toolchain: {exc}")
    s = load_scenario("follow_person", [f'camera.resolution="{RES}"'])
    (tmp_path / "ft.v").write_text(generate_verilog(s.params))
    keep = [
        line
        for line in follow_target_port_map(s.params).splitlines()
        if not line.startswith(("found", "centroid", "filtered"))
    ]
    (tmp_path / "ft.toml").write_text("\n".join(keep) + "\n")
    code = run.main(
        [
            "--scenario",
            "follow_person",
            "--resolution",
            RES,
            "--duration",
            "1",
            "--design",
            f"verilog:{tmp_path / 'ft.v'}",
            "--ports",
            str(tmp_path / "ft.toml"),
            "--rerun",
            "off",
            "--summary",
            str(tmp_path / "s.json"),
        ]
    )
    out = capsys.readouterr().out
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["backend"] == "cxxrtl-foreign"  # auto: Yosys reads it
    assert summary["absent_outputs"] == ["found", "centroid_x", "centroid_leds"]
    assert summary["found_fraction"] is None and summary["acquired_at_s"] is None
    assert "[n/a] acquired_within_s" in out
    assert code == (0 if summary["verdict"] == "pass" else 1)
