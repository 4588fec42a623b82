"""Fork at divergence for a robot with a servo and a further camera (the shipped `turret`:
a pan camera on a servo, its channel commanding the servo): a variant's forked run equals
its own full run whether its servo commands or its wheels part from the reference's, from
the first frame, late or never, also when the pan camera's captures fall between body
frames and after the last one."""

import dataclasses

import numpy as np
import pytest
from run_equality import assert_same_run

from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.loop.fork import ReferenceRun
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.models.turret import TurretChannel
from fpga_robotics.sweep.fork_groups import world_key

#: The capture from which ``ServoPlus`` commands the servo 7 units further.
LATE_CAPTURE = 40


class _AlteredChannel(TurretChannel):
    """The turret channel with its outputs changed (``change``) from capture ``start`` on."""

    start = 0

    def __init__(self, tables):
        super().__init__(tables)
        self.j = 0

    def process(self, frame, color_sel):
        out = super().process(frame, color_sel)
        if self.j >= self.start:
            out = self.change(out)
        self.j += 1
        return out


class NeverFound(_AlteredChannel):
    """Reports the target never found: an output no servo or wheel takes."""

    @staticmethod
    def change(out):
        return {**out, "turret_found": 0}


class ServoPlus(_AlteredChannel):
    start = LATE_CAPTURE

    @staticmethod
    def change(out):
        return {**out, "servo_angle": out["servo_angle"] + 7}


class WheelFrom:
    """The model design with the left wheel 90 DPS faster from frame ``start`` on."""

    name = "wheel_from"

    def __init__(self, params, start):
        self.inner, self.params, self.start = ModelBackend(params), params, start
        self.k = 0

    def reset(self):
        self.inner.reset()
        self.k = 0

    def process_frame(self, rgb, color_sel):
        r = self.inner.process_frame(rgb, color_sel)
        if self.k >= self.start:
            r = dataclasses.replace(r, motor_left=r.motor_left + 90)
        self.k += 1
        return r

    def close(self):
        self.inner.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@pytest.fixture(scope="module", autouse=True)
def altered_tops():
    """TurretTracker with the altered channels, as ``design.top`` values."""
    base = TOPS["turret_tracker"]
    names = []
    for cls in (NeverFound, ServoPlus):
        name = f"turret_{cls.__name__.lower()}"
        TOPS[name] = dataclasses.replace(
            base, name=name, frame_channels={"turret_pixels": (__name__, cls.__name__)}
        )
        names.append(name)
    # The servo bound to no output: the pan camera never turns.
    TOPS["turret_unbound"] = dataclasses.replace(base, name="turret_unbound", bindings={})
    names.append("turret_unbound")
    yield
    for name in names:
        del TOPS[name]


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("turret", ["sim.duration=6"])


@pytest.fixture(scope="module")
def reference(scenario):
    with ModelBackend(scenario.params) as design:
        yield ReferenceRun(scenario, design=design, checkpoint_every=7)


def fork_and_full(reference, scenario, overrides=(), design=None):
    """The variant's forked run, where it parted, and its full run (asserted equal)."""
    variant = scenario.with_overrides(list(overrides)) if overrides else scenario
    design = ModelBackend(variant.params) if design is None else design
    with design:
        forked = reference.run_variant(design, variant)
        diverged = reference.last_divergence
        full = run_scenario(variant, backend=design)
    assert_same_run(forked, full)
    return forked, diverged


def capture_frame(scenario, spec_name, j):
    """The body frame during which camera ``spec_name``'s capture ``j`` is taken: the
    number of body frames captured at an earlier physics step (frames.count after them)."""
    dt = scenario.sim.physics_dt
    cam = next(s for s in scenario.connectors if s.name == spec_name)
    step = round(j * cam.params.frame_period / dt)
    n = round(scenario.sim.duration / dt)
    body = [round(k * scenario.camera.frame_period / dt) for k in range(10**4)]
    return sum(1 for s in body if s < step and s < n)


def test_campaigns_group_robots_with_a_rig_by_world_in_both_timings():
    turret = load_scenario("turret", ["sim.duration=0.2"])

    class Args:
        shadow = None
        runtime = None

    assert world_key(Args(), turret, None) is not None
    real_clock = load_scenario("turret", ["sim.duration=0.2", "sim.timing=real_clock"])
    assert world_key(Args(), real_clock, None) is not None


def test_the_reference_is_the_plain_run(scenario, reference):
    assert_same_run(reference.result, run_scenario(scenario, backend="model"))
    # One pan capture a frame (both cameras at 15 fps), each recorded with its outputs.
    captures = reference._loop.captures
    assert [c.frame for c in captures] == list(range(reference.frames))
    command = reference.result.trajectory["turret.servo_angle"]
    assert [c.outputs["servo_angle"] for c in captures] == list(command)


def test_a_variant_that_never_drives_differently(scenario, reference):
    forked, diverged = fork_and_full(reference, scenario, ["design.top=turret_neverfound"])
    assert diverged is None
    ref = reference.result.trajectory
    assert ref["turret.turret_found"].sum() > 0 == forked.trajectory["turret.turret_found"].sum()
    for column in ("x", "heading", "pan.command", "pan.angle_deg"):
        assert np.array_equal(forked.trajectory[column], ref[column]), column


def test_a_servo_bug_differs_from_the_first_frame(scenario, reference):
    # The shipped bug: the pan law's sign flipped turns the camera away at once.
    forked, diverged = fork_and_full(reference, scenario, ["design.variant=turret_pan_inverted"])
    assert diverged == 0
    assert "camera_target_centred_min_fraction" in failed(forked)
    assert failed(reference.result) == []


def failed(result):
    return [c["name"] for c in result.summary["checks"] if not c["passed"]]


def test_a_servo_command_that_differs_late(scenario, reference):
    assert LATE_CAPTURE % 7 != 0  # restored from the checkpoint before it
    forked, diverged = fork_and_full(reference, scenario, ["design.top=turret_servoplus"])
    assert diverged == capture_frame(scenario, "turret", LATE_CAPTURE) == LATE_CAPTURE
    ref = reference.result.trajectory
    late = LATE_CAPTURE
    assert forked.trajectory["turret.servo_angle"][late] == ref["turret.servo_angle"][late] + 7
    assert np.array_equal(forked.trajectory["pan.command"][:late], ref["pan.command"][:late])
    assert not np.array_equal(forked.trajectory["pan.angle_deg"], ref["pan.angle_deg"])


def test_a_search_parameter_shows_late(scenario, reference):
    # A slower search sweep: the designs part only once the pan camera has lost its target.
    forked, diverged = fork_and_full(reference, scenario, ["design.turret.search_step=3"])
    assert 30 < diverged < reference.frames
    assert not np.array_equal(
        forked.trajectory["pan.command"], reference.result.trajectory["pan.command"]
    )


def test_wheels_that_differ_late_with_a_rig(scenario, reference):
    forked, diverged = fork_and_full(
        reference, scenario, design=WheelFrom(scenario.params, start=50)
    )
    assert diverged == 50
    ref = reference.result.trajectory
    assert forked.trajectory["motor_left"][50] == ref["motor_left"][50] + 90
    assert not np.array_equal(forked.trajectory["heading"], ref["heading"])


def test_pan_captures_between_body_frames():
    # Body camera at 10 fps, pan camera at 15: some frames hold two pan captures, and the
    # last pan capture comes after the last body frame.
    s = load_scenario("turret", ["sim.duration=6", "camera.fps=10"])
    with ModelBackend(s.params) as design:
        reference = ReferenceRun(s, design=design, checkpoint_every=4)
    frames = [c.frame for c in reference._loop.captures]
    expected = [capture_frame(s, "turret", j) for j in range(len(frames))]
    assert frames == expected
    assert expected[-1] == reference.frames  # after the last body frame
    assert 2 in np.bincount(expected)
    assert_same_run(reference.result, run_scenario(s, backend="model"))
    _, diverged = fork_and_full(reference, s, ["design.top=turret_neverfound"])
    assert diverged is None
    _, diverged = fork_and_full(reference, s, ["design.top=turret_servoplus"])
    assert diverged == expected[LATE_CAPTURE] == 27  # 40 / 15 s: in the frame at 2.7 s


def test_a_variant_that_binds_the_servo_otherwise_runs_in_full(scenario, reference):
    forked, diverged = fork_and_full(reference, scenario, ["design.top=turret_unbound"])
    assert diverged == 0
    assert np.all(forked.trajectory["pan.angle_deg"] == 0)


def test_the_turret_campaign_forked_gives_the_full_runs_rows(tmp_path):
    from fpga_robotics.checks.summary import TIMING_FIELDS
    from fpga_robotics.sweep import load_campaign, run_campaign
    from fpga_robotics.sweep.campaign import read_campaign_file
    from fpga_robotics.sweep.fork_groups import fork_groups
    from fpga_robotics.sweep.plan import make_plan

    data = read_campaign_file("turret")
    data = dict(data[0] if isinstance(data, tuple) else data)
    data.update(seeds=[0, 1], duration=4.0)
    campaign = load_campaign(data)
    plan = make_plan(campaign)
    # Per seed: as shipped and its bug, one world.
    assert sorted(len(g) for g in fork_groups(plan.runs, plan.worlds)) == [2, 2]
    forked = run_campaign(campaign, tmp_path / "forked", workers=1, record="none")
    full = run_campaign(campaign, tmp_path / "full", workers=1, record="none", fork=False)
    times = {"wall_s", "cpu_s", "run_s", *TIMING_FIELDS}

    def by_id(rows):
        return {r["run_id"]: {k: v for k, v in r.items() if k not in times} for r in rows}

    a, b = by_id(forked), by_id(full)
    assert len(a) == 4 and a == b
    assert sorted(r["status"] for r in a.values()) == ["fail", "fail", "pass", "pass"]


@pytest.mark.slow  # the design simulated in Python, twice over, for every frame
def test_the_pan_channel_on_the_design_itself():
    # On pysim the pan camera's channel runs on TurretTracker itself
    # (fpga_robotics.loop.pin_channel), which cannot be copied into a checkpoint: the
    # reference's channel is left out of them and the variant brings its own.
    s = load_scenario("turret", ["sim.duration=0.4"])
    with make_backend("pysim", s.params) as design:
        reference = ReferenceRun(s, design=design, checkpoint_every=2)
    assert reference.result.summary["cameras"]["turret"]["channel"] == "pysim"
    variant = s.with_overrides(["design.turret.kp_num=9"])
    with make_backend("pysim", variant.params) as design:
        forked = reference.run_variant(design, variant)
        full = run_scenario(variant, backend=design)
    assert_same_run(forked, full)
    assert reference.last_divergence is not None
