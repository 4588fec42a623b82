"""Designs of one's own by reference (docs/your_design.md): ``[design] top = "FILE.py:Name"``,
``run --design REF``, ``[design.params]``; ports bound by name, every output no connector
reads recorded under its own name (trajectory, summary, viewer); bad references one line.

The designs live in tests/data/user_designs/, outside the package, as a user's would.
"""

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from amaranth.hdl import Fragment

from fpga_robotics import cli
from fpga_robotics.designs.reference import DesignError, resolve_design
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sim.camera.frames import to_rgb444

DESIGNS = Path(__file__).parent / "data" / "user_designs"
WALL_STOP = DESIGNS / "wall_stop.toml"
NEAR_RED = DESIGNS / "near_red.toml"
#: The wall of wall_stop.toml (x = room width) and the ultrasound's mount ahead of the centre.
WALL_X, SENSOR_FORWARD = 2.5, 0.1


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


@pytest.fixture(scope="module")
def wall_stop_run(tmp_path_factory):
    """wall_stop.toml by reference, recorded to a .rrd."""
    from fpga_robotics.viz import open_recorder

    path = tmp_path_factory.mktemp("rrd") / "wall.rrd"
    recorder = open_recorder(f"save:{path}", default_path=None)
    try:
        result = run_scenario(load_scenario(str(WALL_STOP)), backend="cxxrtl", recorder=recorder)
    finally:
        recorder.close()
    return result, path


def test_a_design_reference_resolves_its_ports_bindings_and_extra_outputs():
    spec = resolve_design(f"{DESIGNS}/wall_stop.py:WallStop", {"speed": 100})
    assert spec.kind == "amaranth" and spec.params == {"speed": 100}
    assert spec.ports == {
        "trig": ("out", 1),
        "echo": ("in", 1),
        "motor_left": ("out", 16),
        "motor_right": ("out", 16),
        "distance_mm": ("out", 16),
        "stopped": ("out", 1),
    }
    # By name: trig/echo are the ultrasound's pins, motor_left/right the wheels'.
    assert spec.bindings == {
        "ultrasound": {"trig": "trig", "echo": "echo"},
        "wheels": {"motor_left": "motor_left", "motor_right": "motor_right"},
    }
    assert spec.extra_outputs == ("distance_mm", "stopped")
    component = spec.build()
    assert component.speed == 100
    Fragment.get(component, None)  # used: Amaranth warns of a component never elaborated
    # The built-in follow_target_safe declares its ultrasound pins on its class.
    safe = resolve_design("follow_target_safe")
    assert safe.bindings["ultrasound"] == {"trig": "us_trig", "echo": "us_echo"}
    assert safe.extra_outputs == ("distance_mm", "obstacle")
    assert resolve_design("follow_target").extra_outputs == ()


def test_a_pin_sensor_design_stops_at_the_wall_and_records_its_outputs(wall_stop_run):
    result, _ = wall_stop_run
    traj, summary = result.trajectory, result.summary
    assert summary["verdict"] == "pass" and summary["timing"] == "real_clock"
    # Stopped by its own rule: the true distance from the sensor to the wall is below
    # stop_mm (250) by at most the braking from 300 DPS (17 mm at the GoPiGo3's 1500 DPS/s)
    # plus a measurement period of travel (20 ms at 0.17 m/s) and the echo's rounding.
    gap_mm = 1000 * (WALL_X - (traj["x"][-1] + SENSOR_FORWARD))
    assert 250 - 17 - 4 - 3 <= gap_mm < 250
    assert traj["motor_left"][0] == 300 and traj["motor_left"][-1] == 0
    # Every output no connector reads: a trajectory column under its own name ...
    distance, stopped = traj["design.distance_mm"], traj["design.stopped"]
    assert abs(distance[-1] - gap_mm) <= 3  # the design's own measurement of that gap
    assert stopped[0] == 0 and stopped[-1] == 1
    assert ((stopped == 1) == (traj["motor_left"] == 0)).all()
    # ... a summary field ...
    assert summary["extra_outputs"]["stopped"] == {"last": 1, "min": 0, "max": 1}
    assert summary["extra_outputs"]["distance_mm"]["last"] == int(distance[-1])
    assert summary["extra_outputs"]["distance_mm"]["min"] == int(np.nanmin(distance))


def test_the_extra_outputs_are_viewer_series(wall_stop_run):
    from fpga_robotics.viz.readback import read_rrd

    result, path = wall_stop_run
    entities = read_rrd(str(path)).entities
    for name in ("distance_mm", "stopped"):
        rows = entities[f"design/extra/{name}"]
        scalars = next(v for k, v in rows.values.items() if "calar" in k)
        assert [s[0] for s in scalars] == list(result.trajectory[f"design.{name}"])


def test_a_camera_design_with_an_output_named_near(tmp_path):
    frames = []
    scenario = load_scenario(str(NEAR_RED))
    result = run_scenario(
        scenario, backend="cxxrtl", on_frame=lambda r: frames.append(r.camera_rgb)
    )
    traj = result.trajectory
    assert result.summary["verdict"] == "pass"
    # red_count in row k is frame k-1's (latched at the first pixel of frame k), counted
    # here from the camera's own frames: strongly red RGB444 pixels.
    w, h = scenario.camera.width, scenario.camera.height
    packed = [to_rgb444(f, w, h) for f in frames]
    counts = [int(((p >> 8 >= 8) & ((p >> 4) & 15 < 5) & (p & 15 < 5)).sum()) for p in packed]
    assert list(traj["design.red_count"][1:]) == counts[:-1]
    near = traj["design.near"]
    assert list(near[1:]) == [float(c > 300) for c in counts[:-1]]
    assert near[0] == 0 and near[-1] == 1  # drove up to the person, then stopped
    assert ((traj["motor_left"] == 0) == (near == 1)).all()
    assert set(result.summary["extra_outputs"]) == {"near", "red_count"}


# A camera-only design of one's own: compressed timing ------------------------------------

RED_FRAMES = DESIGNS / "red_frames.toml"


def _red_frames_run(scenario, **kwargs):
    """The run on CXXRTL and its frames' strongly red RGB444 pixels, counted as
    red_frames.py counts them."""
    frames = []
    result = run_scenario(
        scenario, backend="cxxrtl", on_frame=lambda r: frames.append(r.camera_rgb), **kwargs
    )
    packed = [to_rgb444(f, scenario.camera.width, scenario.camera.height) for f in frames]
    counts = [((p >> 8 >= 8) & ((p >> 4) & 15 < 5) & (p & 15 < 5)).sum() for p in packed]
    return result, np.array(counts)


def test_a_camera_only_design_gives_the_same_outputs_in_both_timings():
    """red_frames.py binds only the camera and the wheels and raises frame_done: "auto" runs
    it frame by frame. Before a robot that stands (speed 0: both timings see the same frames
    of a person walking past), every frame's outputs are real-clock timing's, and the
    frames' own red pixels: red_sum, added up over several edges after frame_done, too."""
    items = [
        "sim.duration=3",
        "design.params.speed=0",
        "design.params.min_pixels=110",
        "people.0.waypoints=[[3.5, 0.6], [2.5, 2.4]]",
    ]
    runs = {}
    for timing in ("auto", "real_clock"):
        scenario = load_scenario(str(RED_FRAMES), [*items, f'sim.timing="{timing}"'])
        runs[scenario.sim.timing] = _red_frames_run(scenario)
    (fast, counts), (slow, slow_counts) = runs["compressed"], runs["real_clock"]
    assert fast.summary["timing"] == "compressed" and slow.summary["timing"] == "real_clock"
    np.testing.assert_array_equal(counts, slow_counts)  # the same frames
    assert len(set(counts)) > 3 and (counts < 110).any() and (counts >= 110).any()
    history = np.array([counts[max(0, k - 3) : k + 1].sum() for k in range(len(counts))])
    expected = {
        "found": counts >= 110,
        "design.red_count": counts,
        "design.red_sum": history,
        "motor_left": np.zeros(len(counts)),
    }
    for column, values in expected.items():
        np.testing.assert_array_equal(fast.trajectory[column], values, err_msg=column)
        np.testing.assert_array_equal(slow.trajectory[column], values, err_msg=column)
    assert fast.summary["extra_outputs"] == slow.summary["extra_outputs"]
    assert fast.summary["sim_cycles"] < slow.summary["sim_cycles"] / 5


def test_a_camera_only_design_drives_in_compressed_timing_and_records_its_outputs(tmp_path):
    from fpga_robotics.viz import open_recorder
    from fpga_robotics.viz.readback import read_rrd

    scenario = load_scenario(str(RED_FRAMES))
    assert scenario.sim.timing == "compressed"
    recorder = open_recorder(f"save:{tmp_path / 'red.rrd'}", default_path=None)
    try:
        result, counts = _red_frames_run(scenario, recorder=recorder)
    finally:
        recorder.close()
    traj = result.trajectory
    # Frame k's own count drives frame k's command: 400 DPS while found and not near.
    np.testing.assert_array_equal(traj["design.red_count"], counts)
    np.testing.assert_array_equal(traj["motor_left"], np.where(counts <= 300, 400, 0))
    assert traj["motor_left"][0] == 400 and traj["motor_left"][-1] == 0
    assert traj["x"][-1] > traj["x"][0] + 0.5  # drove up to the person, then stopped
    assert result.summary["verdict"] == "pass"
    assert result.summary["extra_outputs"]["red_count"]["max"] == counts.max()
    entities = read_rrd(str(tmp_path / "red.rrd")).entities
    rows = entities["design/extra/red_sum"]
    scalars = next(v for k, v in rows.values.items() if "calar" in k)
    assert [s[0] for s in scalars] == list(traj["design.red_sum"])


def test_a_robot_spinning_in_place_fails_lost_target_though_it_finds_the_person_again():
    # Spinner turns in place whatever it sees: it re-finds the standing person every turn
    # (reacquired_within_s alone passed it) but faces them a fraction of the time: about
    # (hfov + the person's width) / 360 degrees of each turn, under 30%.
    top = f"design.top={json.dumps(str(DESIGNS / 'spinner.py') + ':Spinner')}"
    result = run_scenario(load_scenario("lost_target", [top]), backend="cxxrtl")
    s, traj = result.summary, result.trajectory
    by = {c["name"]: c for c in s["checks"]}
    assert np.ptp(traj["x"]) < 0.01 and np.ptp(traj["y"]) < 0.01  # it never drove
    assert abs(np.ptp(np.unwrap(traj["heading"]))) > 4 * np.pi  # it turned and turned
    assert by["reacquired_within_s"]["status"] == "pass"
    assert by["target_in_view_min_fraction"]["status"] == "fail"
    assert by["target_in_view_min_fraction"]["value"] < 0.3
    assert by["found_min_fraction"]["status"] == "fail"
    assert s["verdict"] == "fail"


def test_a_steering_that_swings_the_person_off_centre_fails_the_oscillation_check():
    # Swing turns 400 DPS left for 20 frames, then right: the robot swings tens of degrees
    # about the person, who leaves the image centre at each swing. Counting only the centred
    # frames saw almost none of it (0.3 sign changes a second): every found frame counts.
    top = f"design.top={json.dumps(str(DESIGNS / 'swing.py') + ':Swing')}"
    items = [top, "sim.duration=10", "checks.max_oscillation_hz=1.0"]
    result = run_scenario(load_scenario("follow_person", items), backend="cxxrtl")
    traj, s = result.trajectory, result.summary
    heading = np.degrees(np.unwrap(traj["heading"]))
    assert np.ptp(heading[30:90]) > 20  # a swing, not a jitter
    # W's sign changes within each stretch of found frames, per second found, counted here
    # from the trajectory.
    found = traj["found"].astype(bool)
    flips, cuts = 0, np.flatnonzero(np.diff(found)) + 1
    for w, seen in zip(np.split(np.sign(traj["cmd_w"]), cuts), np.split(found, cuts)):
        signs = w[w != 0] if seen[0] else w[:0]
        flips += np.count_nonzero(signs[1:] != signs[:-1])
    assert s["oscillation_hz"] == pytest.approx(flips / (10.0 * found.mean()), abs=1e-4)
    assert s["oscillation_hz"] > 1.0
    (c,) = [c for c in s["checks"] if c["name"] == "max_oscillation_hz"]
    assert c["status"] == "fail", c["text"]
    assert c["text"].startswith(f"W changes sign {s['oscillation_hz']:.2f} times per second")


def test_a_ready_backend_of_another_design_is_refused_before_the_run():
    """A ready FollowTarget backend for a design of one's own ran FollowTarget under the
    scenario's name; a design's ready backend runs only a scenario of that design."""
    from fpga_robotics.loop.pin_frames import open_pin_frames
    from fpga_robotics.sim.backends import get_backend

    own = load_scenario(str(RED_FRAMES), ["sim.duration=0.3"])
    builtin = load_scenario("follow_person", ["sim.duration=0.3", 'camera.resolution="40x30"'])
    with get_backend("model", own.params) as follow_target:
        with pytest.raises(ValueError, match=r"runs FollowTarget; scenario 'red_frames' runs "):
            run_scenario(own, backend=follow_target)
        line = load_scenario("line_track", ["sim.duration=0.3"])
        with pytest.raises(TypeError, match='"real_clock": its design runs on a pin backend'):
            run_scenario(line, backend=follow_target)
    with pytest.raises(TypeError, match="a backend name .* or a ready backend, got 42"):
        run_scenario(own, backend=42)
    with open_pin_frames("cxxrtl", own) as design:
        with pytest.raises(ValueError, match="scenario 'follow_person' runs FollowTarget"):
            run_scenario(builtin, backend=design)
        faster = own.with_overrides(["design.params.speed=200"])
        with pytest.raises(ValueError, match="with other design.params than scenario"):
            run_scenario(faster, backend=design)
        assert run_scenario(own, backend=design).trajectory["motor_left"][0] == 400


def test_a_verilog_design_by_name_runs_itself_in_compressed_timing():
    """A backend name for a camera-only Verilog design in compressed timing opened
    FollowTarget: red_count has none of its tracker outputs and drives by its own rule."""
    data = Path(__file__).parent / "data" / "red_count"
    items = [
        f'design.top="verilog:{data / "red_count.v"}"',
        f'design.ports="{data / "red_count_ports.toml"}"',
        "sim.duration=0.3",
    ]
    scenario = load_scenario("follow_person", items)
    assert scenario.sim.timing == "compressed"
    result = run_scenario(scenario, backend="cxxrtl")
    assert result.summary["absent_outputs"] == ["found", "proximity", "centroid_x", "centroid_leds"]


def test_an_unchanged_copy_of_follow_target_runs_as_the_built_in_does():
    """follow_target_copy.py, FollowTarget as a design of one's own, runs frame by frame on
    its pin backend: every column of the built-in's compressed run, bit for bit."""
    items = ["sim.duration=4", 'camera.resolution="80x60"']
    copy = [
        f'design.top="{DESIGNS / "follow_target_copy.py"}:follow_target_copy"',
        "design.params.width=80",
        "design.params.height=60",
    ]
    builtin = run_scenario(load_scenario("follow_person", items), backend="cxxrtl")
    scenario = load_scenario("follow_person", [*items, *copy])
    assert scenario.sim.timing == "compressed"
    own = run_scenario(scenario, backend="cxxrtl")
    assert set(own.trajectory) == set(builtin.trajectory)
    for column, values in builtin.trajectory.items():
        np.testing.assert_array_equal(own.trajectory[column], values, err_msg=column)
    assert builtin.trajectory["found"].all()
    assert len(set(builtin.trajectory["motor_left"])) > 1  # it steers
    assert own.summary["verdict"] == builtin.summary["verdict"] == "pass"


def test_compressed_timing_names_what_keeps_a_design_on_the_real_clock(tmp_path, capsys):
    for scenario, reason in (
        (WALL_STOP, "(it binds the ultrasound connector)"),
        (NEAR_RED, "(it has no 1-bit frame_done output to say when a frame's results are out)"),
    ):
        assert load_scenario(str(scenario)).sim.timing == "real_clock"
        with pytest.raises(ScenarioError) as info:
            load_scenario(str(scenario), ['sim.timing="compressed"'])
        assert reason in str(info.value) and 'needs sim.timing = "real_clock"' in str(info.value)
    # A second design runs beside it on pins: "auto" is real-clock timing then.
    from fpga_robotics.cli.run import build_parser, load_run_scenario

    argv = ["--scenario", str(RED_FRAMES), "--shadow", f"{DESIGNS}/red_frames.py:RedFrames"]
    assert load_run_scenario(build_parser().parse_args(argv)).sim.timing == "real_clock"
    # A frame whose frame_done never rises (the design counts 31 rows of 30) is one line.
    argv = ["run", "--scenario", str(RED_FRAMES), "--set", "design.params.height=31"]
    code, out, err = _cli([*argv, "--duration", "0.2", "--rerun", "off", "--quiet"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1, err
    assert "frame 0: frame_done did not rise within 20,000 edges" in err
    # The size streamed, for a design that counts its own rows and columns.
    assert "after the frame's last pixel (a 40x30 frame, camera.resolution)" in err
    # Named as the scenario names the design: no --design was given.
    assert err.startswith("fpga-robotics run: error: design.top: RedFrames: frame 0: "), err
    # One that rises before the frame's last pixel (after line 28 of 30, as a design raising
    # it on the stream's last flag, which ends every line, does) is one line too.
    argv = ["run", "--scenario", str(RED_FRAMES), "--set", "design.params.height=29"]
    code, out, err = _cli([*argv, "--duration", "0.3", "--rerun", "off", "--quiet"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1, err
    assert "frame 0: frame_done rose at edge 1,160, before the frame's last pixel" in err


def test_a_frame_done_that_never_rises_is_one_line_in_real_clock_timing_too(capsys):
    """As in compressed timing: else the run passed with found and the centroid never read,
    its checks "not measured", and adding --shadow (auto: real-clock) made a failing run
    pass."""
    # The design counts 31 rows of 30: frame_done never rises. 200 kHz / 10 fps.
    argv = ["run", "--scenario", str(RED_FRAMES), "--duration", "0.3", "--rerun", "off"]
    argv += ["--quiet", '--set=sim.timing="real_clock"']
    code, out, err = _cli([*argv, "--set", "design.params.height=31"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1, err
    assert "frame 0: frame_done did not rise within 20,000 edges" in err
    assert "(a 40x30 frame, camera.resolution); the per-frame outputs are read when it" in err
    # A shadow of it beside it, which makes auto real-clock timing, does not hide it.
    shadow = ["--shadow", f"{DESIGNS}/red_frames.py:RedFrames"]
    code, out, err = _cli([*argv[:-1], "--set", "design.params.height=31", *shadow], capsys)
    assert code == 2 and "frame 0: frame_done did not rise within 20,000 edges" in err, err
    # One that rises runs as before.
    code, out, err = _cli(argv, capsys)
    assert code == 0, err


def test_a_design_file_imports_the_modules_beside_it(tmp_path, monkeypatch, capsys):
    """Wherever the command runs: two versions of a design, each with a helper.py of its
    own, each get theirs."""
    top = (
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import In, Out\n"
        "from helper import SPEED\n\n\n"
        "class Top(wiring.Component):\n"
        "    pressed: In(1)\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += [self.motor_left.eq(SPEED), self.motor_right.eq(SPEED)]\n"
        "        return m\n"
    )
    for version, speed in (("v1", 100), ("v2", 200)):
        (tmp_path / version).mkdir()
        (tmp_path / version / "top.py").write_text(top)
        (tmp_path / version / "helper.py").write_text(f"SPEED = {speed}\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    path = list(sys.path)
    for version, speed in (("v1", 100), ("v2", 200)):
        component = resolve_design(f"../{version}/top.py:Top", base=elsewhere).build()
        Fragment.get(component, None)  # used: Amaranth warns of a component never elaborated
        assert sys.modules[type(component).__module__].SPEED == speed, version
    assert sys.path == path and "helper" not in sys.modules
    # An edit of the helper alone, the design file unchanged, is seen in the same process.
    (tmp_path / "v1" / "helper.py").write_text("SPEED = 1250\n")
    component = resolve_design("../v1/top.py:Top", base=elsewhere).build()
    Fragment.get(component, None)
    assert sys.modules[type(component).__module__].SPEED == 1250
    code, out, err = _cli(["designs", "../v1/top.py:Top"], capsys)
    assert code == 0 and "connectors: bumper (pressed=pressed); wheels" in out, err


def test_run_design_takes_a_reference_and_params_from_the_command_line(tmp_path, capsys):
    summary = tmp_path / "s.json"
    code, out, _ = _cli(
        [
            "run",
            "--scenario",
            str(WALL_STOP),
            "--design",
            f"{DESIGNS}/wall_stop.py:wall_stop",
            "--set",
            "design.params={}",
            "--set",
            "design.params.speed=150",
            "--duration",
            "1",
            "--backend",
            "cxxrtl",
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(summary),
        ],
        capsys,
    )
    assert code == 0
    data = json.loads(summary.read_text())
    assert data["extra_outputs"]["stopped"] == {"last": 0, "min": 0, "max": 0}
    assert "design output distance_mm" in out
    # A function reference at speed 150 (--set): 1 s at 150 DPS after the wheels' ramp
    # (0.1 s at 1500 DPS/s, half of it lost), the first 1 ms of actuation delay aside.
    from fpga_robotics.sim.world import World

    spec = World.from_config({"people": [], "robot": {"model": "gopigo3"}}).robot_spec
    ramp = 150 / spec.wheel_accel_dps2
    expected = np.radians(150) * spec.wheel_radius * (1 - 0.001 - ramp / 2)
    assert data["path_length_m"] == pytest.approx(expected, abs=0.01)


#: (case, reference, params, words of the one-line error).
BAD = [
    ("missing file", "nowhere.py:Design", {}, "no file"),
    ("missing module", "no_such_package.designs:Design", {}, "no module 'no_such_package'"),
    ("missing name", "broken.py:Missing", {}, "has no 'Missing'; its components: Sized"),
    ("not a component", "broken.py:NotAComponent", {}, "is not an Amaranth wiring.Component"),
    (
        "a callable object that is no component",
        "broken.py:Stats",
        {"target": 1},
        "Stats is a StructLayout, not a wiring.Component class or a function returning one",
    ),
    (
        "a function that raises",
        "broken.py:raises",
        {},
        "building it raised ValueError: width 4 is not supported (broken.py:16)",
    ),
    (
        "a function returning no component",
        "broken.py:returns_a_number",
        {},
        "it returned int, not an Amaranth wiring.Component",
    ),
    (
        "a parameter of the wrong type",
        "broken.py:Sized",
        {"width": "wide"},
        "design.params.width must be an integer",
    ),
    (
        "an unknown parameter",
        "broken.py:Sized",
        {"depth": 2},
        "Sized takes no parameter 'depth'; it takes: width",
    ),
    ("a syntax error", "syntax_error.py:Broken", {}, "loading syntax_error.py (line 1)"),
    (
        "a constructor that forgets super().__init__()",
        "unelaborated.py:NoSuperInit",
        {},
        "NoSuperInit has no signature: its __init__ must call super().__init__()",
    ),
    (
        "an elaborate without the platform argument",
        "unelaborated.py:NoPlatform",
        {},
        "Amaranth calls elaborate(self, platform): add the platform argument",
    ),
    (
        "an elaborate that raises",
        "unelaborated.py:ElaborateRaises",
        {},
        "does not elaborate: ValueError: no such speed table (unelaborated.py:19)",
    ),
    (
        "an elaborate that calls sys.exit",
        "unelaborated.py:ElaborateExits",
        {},
        "does not elaborate: SystemExit: 0 (unelaborated.py:",
    ),
    (
        "a file that calls sys.exit",
        "exits.py:Design",
        {},
        "loading exits.py (line 2) raised SystemExit: 0",
    ),
    (
        "a signal driven from two domains",
        "unelaborated.py:DrivenTwice",
        {},
        "does not elaborate: SyntaxError: Driver-driver conflict",
    ),
    (
        "a combinational loop: its signals on the line, and the fix",
        "unelaborated.py:LoopsBack",
        {},
        "unelaborated.py:38: signal a bit 0; break the loop with a register (m.d.sync)",
    ),
    (
        "an input port the design drives: its line, and the fix",
        "unelaborated.py:DrivesItsInput",
        {},
        (
            "drives its input port 'line' (unelaborated.py:78): an In port is driven by its "
            "connector; declare it Out(...) or drive another signal"
        ),
    ),
    (
        "an input port an Instance drives",
        "unelaborated.py:DrivesItsInputByInstance",
        {},
        "does not elaborate: DriverConflict: Bit 0 of signal (sig line) has multiple drivers",
    ),
    (
        "an elaborate that returns nothing",
        "unelaborated.py:NoReturn",
        {},
        "returned None; missing return statement?",
    ),
    (
        "a port named after the clock",
        f"{DESIGNS / 'port_cases.py'}:ClkPort",
        {},
        "design 'ClkPort' has a port named 'clk', the name of the clock domain's own clock",
    ),
    (
        "a port wider than the simulators take (listed as recorded, run refused the backend)",
        f"{DESIGNS / 'port_cases.py'}:WidePort",
        {},
        "design 'WidePort': port 'huge' is 128 bits; the simulators take ports of at most 64",
    ),
    (
        "no file or module before the colon",
        ":WallStop",
        {},
        "name the file or module before ':' (FILE.py:WallStop or package.module:WallStop)",
    ),
    ("params of a built-in", "follow_target", {"speed": 1}, "takes its parameters from"),
    ("an unknown name", "follow_me", {}, "unknown design 'follow_me'"),
]


@pytest.mark.parametrize("case, reference, params, message", BAD, ids=[c[0] for c in BAD])
def test_bad_references_are_one_line_errors(
    case, reference, params, message, tmp_path, capsys, monkeypatch
):
    shutil.copy(DESIGNS / "broken.py", tmp_path / "broken.py")
    shutil.copy(DESIGNS / "unelaborated.py", tmp_path / "unelaborated.py")
    (tmp_path / "syntax_error.py").write_text("class Broken(\n")  # never closed
    (tmp_path / "exits.py").write_text("import sys\nsys.exit(0)  # argparse on a wrong argv, say\n")
    with pytest.raises(DesignError, match=message.replace("(", r"\(").replace(")", r"\)")):
        resolve_design(reference, params, base=tmp_path)
    # The same through the command line: exit 2, one line, nothing written.
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    argv = [
        "run",
        "--scenario",
        str(WALL_STOP),
        "--design",
        reference,
        "--rerun",
        "save:out.rrd",
        "--summary",
        "out.json",
        "--quiet",
        "--set",
        "design.params={}",
    ]
    for key, value in params.items():
        argv += ["--set", f"design.params.{key}={json.dumps(value)}"]
    code, _, err = _cli(argv, capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert message in err
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "__pycache__") == before


def _package(folder, name):
    """A package ``name`` in ``folder``: ``top.D`` drives at ``parts.SPEED``, imported
    relatively."""
    package = folder / name
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "parts.py").write_text("SPEED = 210\n")
    (package / "top.py").write_text(
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import Out\n\n"
        "from .parts import SPEED\n\n\n"
        "class D(wiring.Component):\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += [self.motor_left.eq(SPEED), self.motor_right.eq(-SPEED)]\n"
        "        return m\n"
    )
    return package


def test_a_package_module_reference_is_found_in_the_current_folder(tmp_path, monkeypatch):
    # As python -m fpga_robotics finds it: the fpga-robotics script's path has no current
    # folder, and this session's path has no tmp_path.
    name = f"ud_pkg_{tmp_path.name}"
    _package(tmp_path, name)
    assert str(tmp_path) not in sys.path
    monkeypatch.chdir(tmp_path)
    try:
        spec = resolve_design(f"{name}.top:D")
        assert spec.ports == {"motor_left": ("out", 16), "motor_right": ("out", 16)}
        assert str(tmp_path) not in sys.path  # put back after the import
    finally:
        for module in [m for m in sys.modules if m.partition(".")[0] == name]:
            del sys.modules[module]


def test_a_package_s_file_named_as_a_file_says_how_to_name_it(tmp_path, monkeypatch):
    package = _package(tmp_path, "ud_pkg_as_file")
    hint = (
        "ImportError: attempted relative import with no known parent package; top.py is a "
        f"module of the package 'ud_pkg_as_file': name it ud_pkg_as_file.top:D, running in "
        f"{str(tmp_path)!r} (or install the package)"
    )
    with pytest.raises(DesignError) as info:
        resolve_design(f"{package}/top.py:D")
    assert str(info.value).endswith(hint)
    # Named as a module from inside the package's folder: the same advice.
    monkeypatch.chdir(package)
    try:
        with pytest.raises(DesignError) as info:
            resolve_design("top:D")
        assert str(info.value).endswith(hint)
    finally:
        sys.modules.pop("top", None)


def test_a_design_without_a_clock_is_refused_by_mutate(tmp_path, capsys, monkeypatch):
    # Combinational logic only: it resolves (it may be exported for a board) and runs in the
    # loop (below), but the mutation judges compare netlists cycle by cycle through its clock.
    shutil.copy(DESIGNS / "unelaborated.py", tmp_path / "unelaborated.py")
    spec = resolve_design("unelaborated.py:NoClock", {}, base=tmp_path)
    assert not spec.clocked
    # No docstring of its own: described by its name, not by wiring.Component's docstring.
    assert spec.description == "the Amaranth design NoClock"
    assert resolve_design(str(DESIGNS / "wall_stop.py") + ":WallStop", {}).clocked
    message = "has no clock: nothing in its sync domain (m.d.sync)"
    monkeypatch.chdir(tmp_path)
    code, _, err = _cli(
        ["mutate", "--design", "unelaborated.py:NoClock", "--mutants", "2", "--quiet"], capsys
    )
    assert code == 2 and len(err.strip().splitlines()) == 1 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "__pycache__") == [
        "unelaborated.py"
    ]


@pytest.mark.parametrize("backend", ["pysim", "cxxrtl"])
def test_a_purely_combinational_design_runs_in_the_loop(tmp_path, backend):
    # comb_stop.py has nothing in m.d.sync: the wheels are 300 DPS until the bumper closes,
    # 0 while it is closed, in the same cycle. The robot drives at the wall 1.5 m ahead,
    # stops on it and stays pressed there.
    shutil.copy(DESIGNS / "comb_stop.py", tmp_path / "comb_stop.py")
    text = (Path(__file__).parent / "data" / "bump_wall.toml").read_text()
    text += '\n[design]\ntop = "comb_stop.py:CombStop"\n[design.params]\nspeed = 300\n'
    (tmp_path / "comb.toml").write_text(text)
    assert not resolve_design(str(tmp_path / "comb_stop.py") + ":CombStop", {}).clocked
    result = run_scenario(load_scenario(str(tmp_path / "comb.toml")), backend=backend)
    traj = result.trajectory
    pressed = traj["design.pressed_seen"]
    assert pressed[0] == 0 and pressed[-1] == 1
    # The wheel law, combinational: at every row, 300 DPS unless pressed, then 0.
    assert list(traj["motor_left"]) == [0.0 if p else 300.0 for p in pressed]
    assert (traj["motor_right"] == traj["motor_left"]).all()
    assert result.summary["verdict"] == "pass"


def test_a_design_with_an_instance_is_refused_where_it_would_be_simulated(
    tmp_path, capsys, monkeypatch
):
    # No simulator has my_ip: pysim would read its output as 0 and pass, the compiled
    # backends fail inside Yosys. Export (and so the board) takes it as it is.
    shutil.copy(DESIGNS / "unelaborated.py", tmp_path / "unelaborated.py")
    spec = resolve_design("unelaborated.py:BlackBox", {}, base=tmp_path)
    assert spec.black_boxes == ("my_ip",)
    # Submodules of its own are no black boxes.
    assert resolve_design(str(DESIGNS / "wall_stop.py") + ":WallStop", {}).black_boxes == ()
    message = "instantiates 'my_ip' (an Instance), which the simulators here cannot run"
    monkeypatch.chdir(tmp_path)
    for argv in (
        ["run", "--scenario", str(WALL_STOP), "--design", "unelaborated.py:BlackBox",
         "--backend", "pysim", "--rerun", "off", "--set", "design.params={}"],
        ["mutate", "--design", "unelaborated.py:BlackBox", "--mutants", "2", "--quiet"],
    ):  # fmt: skip
        code, _, err = _cli(argv, capsys)
        assert code == 2 and len(err.strip().splitlines()) == 1 and message in err, err
    code, _, _ = _cli(["export", "--design", "unelaborated.py:BlackBox", "-o", "bb.v"], capsys)
    assert code == 0 and "my_ip ip (" in (tmp_path / "bb.v").read_text()


UNDEFINED_DOMAIN = """
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Fast(wiring.Component):
    pressed: In(1)
    ext_clk: In(1)  # a port of its own whose name ends as a domain's clock does
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        seen = Signal()
        m.d.fast += seen.eq(self.pressed | self.ext_clk)
        m.d.sync += self.motor_left.eq(seen)
        return m
"""


def test_a_domain_used_and_not_defined_is_refused_where_nothing_would_clock_it(
    tmp_path, capsys, monkeypatch
):
    # Amaranth made it a fast_clk input: a run passed with its flip-flops never clocked, the
    # board stopped with a traceback. Export writes it with that input, for a top of one's own.
    (tmp_path / "fast.py").write_text(UNDEFINED_DOMAIN)
    spec = resolve_design(f"{tmp_path}/fast.py:Fast", {})
    assert spec.free_domains == ("fast",)
    assert resolve_design(str(DESIGNS / "wall_stop.py") + ":WallStop", {}).free_domains == ()
    message = (
        "uses clock domain 'fast' (m.d.fast) without defining it, so nothing here clocks it "
        "(Amaranth makes it an input fast_clk): use m.d.sync, or define it (m.domains.fast = "
        "ClockDomain(...)) and drive its clock in the design"
    )
    monkeypatch.chdir(tmp_path)
    for argv in (
        ["run", "--scenario", str(WALL_STOP), "--design", "fast.py:Fast",
         "--backend", "pysim", "--rerun", "off", "--set", "design.params={}"],
        ["mutate", "--design", "fast.py:Fast", "--mutants", "2", "--quiet"],
        ["board", "--design", "fast.py:Fast", "-o", "board"],
    ):  # fmt: skip
        code, _, err = _cli(argv, capsys)
        assert code == 2 and len(err.strip().splitlines()) == 1 and message in err, err
    code, _, _ = _cli(["export", "--design", "fast.py:Fast", "-o", "fast.v"], capsys)
    assert code == 0 and "input fast_clk;" in (tmp_path / "fast.v").read_text()


def test_a_scenario_names_its_design_relative_to_its_folder(tmp_path):
    shutil.copy(DESIGNS / "wall_stop.py", tmp_path / "mine.py")
    text = WALL_STOP.read_text().replace("wall_stop.py:WallStop", "mine.py:WallStop")
    (tmp_path / "s.toml").write_text(text)
    scenario = load_scenario(str(tmp_path / "s.toml"), ["design.params.stop_mm=100"])
    assert scenario.top == f"{(tmp_path / 'mine.py').resolve()}:WallStop"
    assert scenario.design_params == {"speed": 300, "stop_mm": 100}
    assert scenario.sim.timing == "real_clock"
    with pytest.raises(ScenarioError, match="design.params.stop_mm must be an integer"):
        load_scenario(str(tmp_path / "s.toml"), ['design.params.stop_mm="near"'])
    with pytest.raises(ScenarioError, match="design.ultrasound is a table of a built-in"):
        load_scenario(str(tmp_path / "s.toml"), ["design.ultrasound.trigger_us=12"])


# Verilog designs: an active-low reset, no reset, an output no connector reads ------------

DATA = Path(__file__).parent / "data"
BUMP_WALL = DATA / "bump_wall.toml"


def _verilog_run(capsys, tmp_path, design, ports, *more):
    summary = tmp_path / f"{Path(ports).stem}.json"
    code, out, err = _cli(
        [
            "run",
            "--scenario",
            str(BUMP_WALL),
            "--design",
            design,
            "--ports",
            str(ports),
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(summary),
            *more,
        ],
        capsys,
    )
    assert code == 0, err
    return json.loads(summary.read_text()), out


def test_verilog_designs_with_and_without_reset_record_an_unread_output(tmp_path, capsys):
    # tests/data/bump_stop.v (active-low reset) with its hit_o recorded as an extra output.
    ports = tmp_path / "ports.toml"
    ports.write_text(
        (DATA / "bump_stop_ports.toml").read_text() + '\n[extra_outputs]\nhit = "hit_o"\n'
    )
    with_reset, out = _verilog_run(capsys, tmp_path, f"verilog:{DATA / 'bump_stop.v'}", ports)
    without, _ = _verilog_run(
        capsys,
        tmp_path,
        f"verilog:{DESIGNS / 'bump_stop_noreset.v'}",
        DESIGNS / "bump_stop_noreset_ports.toml",
    )
    for summary in (with_reset, without):
        assert summary["verdict"] == "pass"
        # Driving until the bumper closed, then stopped: hit went 0 -> 1 once.
        assert summary["extra_outputs"] == {"hit": {"last": 1, "min": 0, "max": 1}}
    assert "design output hit: last 1, min 0, max 1" in out
    # A register's initial value is what the reset gave: the same run, to the millimetre.
    assert with_reset["path_length_m"] == without["path_length_m"]
    assert with_reset["sim_cycles"] == without["sim_cycles"]


def test_a_verilog_design_by_reference_in_the_scenario(tmp_path):
    ports = DESIGNS / "bump_stop_noreset_ports.toml"
    text = BUMP_WALL.read_text() + (
        f'[design]\ntop = "verilog:{DESIGNS / "bump_stop_noreset.v"}"\nports = "{ports}"\n'
    )
    (tmp_path / "s.toml").write_text(text)
    result = run_scenario(load_scenario(str(tmp_path / "s.toml")), backend="auto")
    traj = result.trajectory
    assert ((traj["design.hit"] == 1) == (traj["motor_left"] == 0)).all()
    assert ((traj["design.hit"] == 1) == (traj["bumper.pressed"] == 1)).sum() >= len(
        traj["t"]
    ) - 1  # the latch follows the bumper within a row


def test_a_design_without_wheels_runs_and_the_robot_stands(tmp_path):
    text = BUMP_WALL.read_text().replace("start = [0.5, 0.5]", "start = [1.88, 0.5]") + (
        f'[design]\ntop = "{DESIGNS / "bump_watch.py"}:BumpWatch"\n'
    )
    (tmp_path / "s.toml").write_text(text)
    scenario = load_scenario(str(tmp_path / "s.toml"), ["sim.duration=0.5"])
    result = run_scenario(scenario, backend="pysim")
    traj = result.trajectory
    assert "motor_left" in result.summary["absent_outputs"]
    assert np.isnan(traj["motor_left"]).all() and result.summary["path_length_m"] == 0
    # Placed 1 cm from the wall (x = 2 less the 0.11 m body): the 3 cm bumper is closed
    # from the first step on (row 0 is read before it), one closing counted.
    assert (traj["bumper.pressed"][1:] == 1).all()
    assert traj["design.presses"][-1] == 1


def test_the_page_shows_the_files_the_tests_run():
    """docs/your_design.md's design, scenario and port map are these files, word for word."""
    page = (Path(__file__).parent.parent / "docs" / "your_design.md").read_text()
    for name in ("wall_stop.py", "wall_stop.toml", "bump_stop_noreset_ports.toml"):
        assert (DESIGNS / name).read_text().rstrip("\n") + "\n```" in page, name


def test_installed_packages_offer_designs_by_entry_point(tmp_path, monkeypatch, capsys):
    """A distribution on the path with an ``fpga_robotics.designs`` entry point: its name is
    a reference, listed by ``fpga-robotics designs``."""
    package = tmp_path / "my_robot"
    package.mkdir()
    (package / "__init__.py").write_text("")
    shutil.copy(DESIGNS / "wall_stop.py", package / "designs.py")
    info = tmp_path / "my_robot-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: my-robot\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(
        "[fpga_robotics.designs]\nwall_stopper = my_robot.designs:WallStop\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    spec = resolve_design("wall_stopper", {"stop_mm": 100})
    assert spec.reference == "my_robot.designs:WallStop"
    assert spec.extra_outputs == ("distance_mm", "stopped")
    from fpga_robotics.cli.designs import main

    assert main([]) == 0
    out = capsys.readouterr().out
    assert "my_robot.designs:WallStop  (installed: my_robot.designs:WallStop)" in out
    assert "follow_line  (built-in)" in out


def test_shadow_runs_a_previous_version_of_the_design_on_the_same_pins(tmp_path, capsys):
    """--shadow REF in real-clock timing: the shadow gets every input the primary gets; its
    wheels differ exactly while neither has stopped, its measurements never."""
    old = (
        (DESIGNS / "wall_stop.py")
        .read_text()
        .replace("Mux(self.stopped, 0, self.speed)", "Mux(self.stopped, 0, self.speed - 50)")
    )
    (tmp_path / "wall_stop_v1.py").write_text(old)
    summary = tmp_path / "s.json"
    code, out, err = _cli(
        [
            "run",
            "--scenario",
            str(WALL_STOP),
            "--shadow",
            f"{tmp_path}/wall_stop_v1.py:WallStop",
            "--backend",
            "cxxrtl",
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(summary),
        ],
        capsys,
    )
    assert code == 0, err
    shadow = json.loads(summary.read_text())["shadow"]
    frames = shadow["frames"]
    moving = shadow["differing_frames"]["motor_left"]
    assert shadow["first_divergence"] == {
        "frame": 0,
        "time_s": 0.0,
        "outputs": {
            "motor_left": {"primary": 300, "shadow": 250},
            "motor_right": {"primary": 300, "shadow": 250},
        },
    }
    assert shadow["differing_frames"]["motor_right"] == moving
    assert shadow["differing_frames"]["distance_mm"] == 0
    assert shadow["differing_frames"]["stopped"] == 0
    assert shadow["differing_frames"]["trig"] == 0
    assert 0 < moving < frames == 360
    assert "first differs at frame 0 (0.00 s): motor_left 300 vs 250" in out


def test_a_shadow_runs_with_the_scenario_s_params_it_takes_and_its_own(tmp_path, capsys):
    """--shadow REF gets the scenario's [design.params] its signature takes (a changed
    default the scenario sets does not show: the summary names the params), --shadow-param
    NAME=VALUE gives it its own; a previous version without a parameter runs without it."""
    v2 = (DESIGNS / "wall_stop.py").read_text().replace("stop_mm: int = 250", "stop_mm: int = 100")
    (tmp_path / "wall_stop_v2.py").write_text(v2)
    # Started 0.6 m from the wall: the primary stops after about 1.3 s, v2 at 100 mm later.
    base = ["run", "--scenario", str(WALL_STOP), "--set", "robot.start=[1.9, 0.5]"]
    base += ["--duration", "3", "--backend", "cxxrtl", "--rerun", "off", "--quiet"]

    def shadow(*options):
        summary = tmp_path / "s.json"
        code, out, err = _cli([*base, *options, "--summary", str(summary)], capsys)
        assert code == 0, err
        return json.loads(summary.read_text())["shadow"], out

    v2 = f"{tmp_path}/wall_stop_v2.py:WallStop"
    same, out = shadow("--shadow", v2)
    assert same["params"] == {"speed": 300, "stop_mm": 250}
    assert same["first_divergence"] is None
    assert f"shadow {v2} with speed=300, stop_mm=250: identical outputs on all 90 frames" in out
    own, out = shadow("--shadow", v2, "--shadow-param", "stop_mm=100")
    assert own["params"] == {"speed": 300, "stop_mm": 100}
    first = own["first_divergence"]
    assert first["outputs"]["motor_left"] == {"primary": 0, "shadow": 300}
    assert first["outputs"]["stopped"] == {"primary": 1, "shadow": 0}
    assert f"shadow {v2} with speed=300, stop_mm=100: first differs at frame" in out
    function, _ = shadow("--shadow", f"{DESIGNS}/wall_stop.py:wall_stop")  # takes speed only
    assert function["params"] == {"speed": 300}
    assert function["first_divergence"] is None


def test_a_shadow_parameter_without_default_is_asked_for_by_shadow_param(tmp_path, capsys):
    needs = (
        DESIGNS / "wall_stop.py"
    ).read_text() + "\n\ndef needs(gap: int):\n    return WallStop(stop_mm=gap)\n"
    (tmp_path / "needs.py").write_text(needs)
    argv = ["run", "--scenario", str(WALL_STOP), "--shadow", f"{tmp_path}/needs.py:needs"]
    code, _, err = _cli([*argv, "--rerun", "off"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "parameter 'gap' has no default" in err
    assert "give it with --shadow-param gap=VALUE" in err


def test_a_bad_shadow_param_value_is_told_as_that_option(tmp_path, capsys):
    # It was said as design.params.stop_mm, a key the scenario file has with a good value.
    argv = ["run", "--scenario", str(WALL_STOP), "--rerun", "off"]
    argv += ["--shadow", f"{DESIGNS}/wall_stop.py:WallStop", "--shadow-param", "stop_mm=near"]
    code, _, err = _cli(argv, capsys)
    assert code == 2
    assert err == (
        "fpga-robotics run: error: --shadow-param stop_mm must be an integer (a parameter of "
        "WallStop), got 'near'\n"
    )


_BUMP_STOP_AMARANTH = """
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class BumpStop(wiring.Component):
    pressed: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        hit = Signal()
        with m.If(self.pressed):
            m.d.sync += hit.eq(1)
        with m.If(~hit):
            m.d.comb += [self.motor_left.eq(300), self.motor_right.eq(300)]
        return m
"""


@pytest.mark.parametrize("verilog_shadow", [True, False], ids=["verilog shadow", "amaranth shadow"])
def test_a_verilog_design_shadows_an_amaranth_one_and_the_other_way(
    tmp_path, capsys, verilog_shadow
):
    """--shadow verilog:FILE.v --shadow-ports MAP beside an Amaranth design, and an Amaranth
    shadow beside a Verilog design: the bumper closes for both at once (the shadow gets the
    primary's inputs), so they differ exactly while the robot drives (300 against 250 DPS)."""
    data = DESIGNS.parent
    (tmp_path / "bump_stop.py").write_text(_BUMP_STOP_AMARANTH)
    v2 = (data / "bump_stop.v").read_text().replace("12'sd300", "12'sd250")
    (tmp_path / "bump_v2.v").write_text(v2)
    amaranth, verilog = f"{tmp_path}/bump_stop.py:BumpStop", f"verilog:{tmp_path}/bump_v2.v"
    ports = str(data / "bump_stop_ports.toml")
    if verilog_shadow:
        design = ["--design", amaranth, "--shadow", verilog, "--shadow-ports", ports]
    else:
        design = ["--design", verilog, "--ports", ports, "--shadow", amaranth]
    summary = tmp_path / "s.json"
    argv = ["run", "--scenario", str(data / "bump_wall.toml"), *design, "--rerun", "off"]
    code, _, err = _cli([*argv, "--quiet", "--summary", str(summary)], capsys)
    assert code == 0, err
    shadow = json.loads(summary.read_text())["shadow"]
    first, other = (300, 250) if verilog_shadow else (250, 300)
    assert shadow["first_divergence"]["frame"] == 0
    assert shadow["first_divergence"]["outputs"]["motor_left"] == {
        "primary": first,
        "shadow": other,
    }
    moving = shadow["differing_frames"]["motor_left"]
    assert 0 < moving < shadow["frames"] == 360
    assert shadow["differing_frames"]["motor_right"] == moving


def test_design_runs_an_amaranth_design_in_place_of_a_scenario_s_verilog_one(tmp_path, capsys):
    """--design FILE.py:Name on a scenario whose design.verilog names another design: the
    Amaranth one runs (300 DPS, farther than the Verilog one's 250 in the same time)."""
    data = DESIGNS.parent
    (tmp_path / "bump_stop.py").write_text(_BUMP_STOP_AMARANTH)
    v2 = (data / "bump_stop.v").read_text().replace("12'sd300", "12'sd250")
    (tmp_path / "bump_v2.v").write_text(v2)
    scenario = (
        (data / "bump_wall.toml")
        .read_text()
        .replace(
            "[sim]",
            f'[design]\nverilog = ["bump_v2.v"]\nports = "{data / "bump_stop_ports.toml"}"\n[sim]',
        )
    )
    (tmp_path / "v.toml").write_text(scenario)
    paths = {}
    for name, design in (
        ("verilog", []),
        ("amaranth", ["--design", f"{tmp_path}/bump_stop.py:BumpStop"]),
    ):
        summary = tmp_path / f"{name}.json"
        argv = ["run", "--scenario", str(tmp_path / "v.toml"), *design, "--duration", "3"]
        code, _, err = _cli([*argv, "--rerun", "off", "--quiet", "--summary", str(summary)], capsys)
        assert code == 0, err
        paths[name] = json.loads(summary.read_text())["path_length_m"]
    assert paths["amaranth"] / paths["verilog"] == pytest.approx(300 / 250, rel=0.05)


def test_a_verilog_shadow_needs_its_port_map_and_files(tmp_path, capsys):
    data = DESIGNS.parent
    base = ["run", "--scenario", str(data / "bump_wall.toml"), "--rerun", "off"]
    base += ["--design", "verilog:" + str(data / "bump_stop.v")]
    base += ["--ports", str(data / "bump_stop_ports.toml")]
    for extra, words in [
        (["--shadow", "verilog:" + str(data / "bump_stop.v")], "needs --shadow-ports"),
        (["--shadow", "verilog:nope.v", "--shadow-ports", str(data / "bump_stop_ports.toml")],
         "no such file: nope.v"),
        (["--shadow-ports", str(data / "bump_stop_ports.toml")], "goes with --shadow verilog"),
        (["--shadow", "verilog:" + str(data / "bump_stop.v"), "--shadow-ports",
          str(data / "bump_wall.toml")], "--shadow-ports"),
    ]:  # fmt: skip
        code, _, err = _cli([*base, *extra], capsys)
        assert code == 2 and words in err and "Traceback" not in err, err


def test_designs_checks_a_verilog_port_map_against_the_design(tmp_path, capsys):
    verilog = f"verilog:{DESIGNS / 'bump_stop_noreset.v'}"
    ports = DESIGNS / "bump_stop_noreset_ports.toml"
    code, out, _ = _cli(["designs", verilog, "--ports", str(ports)], capsys)
    assert code == 0
    assert (
        "ports: in clk[1], in bump_i[1], out left_dps[12], out right_dps[12], out hit_o[1]" in out
    )
    assert "recorded outputs: hit" in out
    for change, message in (
        (("bump_i", "bump"), "the design bump_stop_noreset has no port 'bump'"),
        (('hit = "hit_o"', 'hit = "hit"'), "has no port 'hit'"),
        (('top = "bump_stop_noreset"', 'top = "bump_stop"'), "Verilator cannot read"),
    ):
        bad = tmp_path / "bad.toml"
        bad.write_text(ports.read_text().replace(*change))
        code, _, err = _cli(["designs", verilog, "--ports", str(bad)], capsys)
        assert code == 2 and len(err.strip().splitlines()) == 1, err
        assert message in err, err


def test_designs_shows_a_verilog_camera_on_the_ports_its_map_names(tmp_path, capsys):
    red_count = Path(__file__).parent / "data" / "red_count"
    verilog, ports = f"verilog:{red_count / 'red_count.v'}", red_count / "red_count_ports.toml"
    code, out, _ = _cli(["designs", verilog, "--ports", str(ports)], capsys)
    assert code == 0
    # Its own ports, as its wheels are: no colour port, as its map has none.
    assert "connectors: camera (pixels=pix_valid/pix_payload); wheels (motor_left=left, " in out
    with_color = tmp_path / "ports.toml"
    text = ports.read_text().replace("\nresult", '\ncolor = { port = "sel" }\nresult')
    with_color.write_text(text)
    spec = resolve_design(verilog, ports=str(with_color))
    assert spec.bindings["camera"] == {"pixels": "pix_valid/pix_payload", "color_sel": "sel"}


def test_a_campaign_takes_design_references_and_their_params_as_axes(tmp_path, monkeypatch):
    from fpga_robotics.sweep.campaign import load_campaign, read_campaign_file
    from fpga_robotics.sweep.plan import make_plan

    for name in ("wall_stop.py", "wall_stop.toml"):
        shutil.copy(DESIGNS / name, tmp_path / name)
    (tmp_path / "c.toml").write_text(
        'scenarios = ["wall_stop.toml"]\ndesign = "wall_stop.py:wall_stop"\n'
        'backend = "cxxrtl"\nset = ["design.params={}"]\n'
        '[grid]\n"design.params.speed" = [100, 200]\n'
    )
    monkeypatch.chdir(tmp_path.parent)  # file paths are from the campaign's folder
    data, path = read_campaign_file(str(tmp_path / "c.toml"))
    plan = make_plan(load_campaign(data, source=str(path)))
    assert [r.argv()[r.argv().index("--design") + 1] for r in plan.runs] == [
        f"{tmp_path.name}/wall_stop.py:wall_stop"
    ] * 2
    # The design's file names the run: another version of it is another run.
    first = plan.ids[plan.runs[0]]
    (tmp_path / "wall_stop.py").write_text((DESIGNS / "wall_stop.py").read_text() + "\n# v2\n")
    again = make_plan(
        load_campaign(read_campaign_file(str(tmp_path / "c.toml"))[0], source=str(path))
    )
    assert again.ids[again.runs[0]] != first
    assert len(set(plan.ids.values())) == 2


def test_export_writes_a_design_of_ones_own_and_refuses_bad_params(tmp_path, capsys):
    out_v = tmp_path / "ws.v"
    code, out, err = _cli(
        [
            "export",
            "--design",
            f"{DESIGNS}/wall_stop.py:WallStop",
            "--param",
            "speed=200",
            "-o",
            str(out_v),
        ],
        capsys,
    )
    assert code == 0, err
    assert out == f"wrote {out_v} (module WallStop, 6 ports)\n"
    text = out_v.read_text()
    assert "module WallStop(" in text
    # Every port of the design, at its width, as the resolver reads it.
    for port, width in (("trig", 1), ("echo", 1), ("motor_left", 16), ("distance_mm", 16)):
        decl = f"[{width - 1}:0] {port};" if width > 1 else f" {port};"
        assert decl in text, port
    bad = tmp_path / "bad.v"
    code, out, err = _cli(
        [
            "export",
            "--design",
            f"{DESIGNS}/wall_stop.py:WallStop",
            "--param",
            "speed=fast",
            "-o",
            str(bad),
        ],
        capsys,
    )
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert "--param speed must be an integer (a parameter of WallStop), got 'fast'" in err
    assert not bad.exists()


NEEDS_SPEED = """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class P(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def __init__(self, speed):
        self.speed = speed
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.motor_left.eq(self.speed), self.motor_right.eq(self.speed)]
        return m
"""


def test_a_bad_parameter_is_told_as_the_command_takes_it(tmp_path, capsys, monkeypatch):
    # designs, export, board and mutate take a design's parameters as --param; a run as
    # [design.params] or --set.
    (tmp_path / "p.py").write_text(NEEDS_SPEED)
    monkeypatch.chdir(tmp_path)
    missing = "parameter 'speed' has no default; give it as --param speed=VALUE"
    # A typo is answered with the name it misspells.
    unknown = "--param spd: P takes no parameter 'spd' (did you mean 'speed'?); it takes: speed"
    for command in (
        ["designs", "p.py:P"],
        ["export", "--design", "p.py:P", "-o", "p.v"],
        ["board", "--design", "p.py:P", "-o", "board"],
        ["mutate", "--design", "p.py:P", "--out", "mutants"],
    ):
        for extra, message in (([], missing), (["--param", "spd=1"], unknown)):
            code, out, err = _cli([*command, *extra], capsys)
            assert (code, out, err.count("\n")) == (2, "", 1), err
            assert message in err, err
    run = ["run", "--scenario", str(WALL_STOP), "--design", "p.py:P", "--set", "design.params={}"]
    code, _, err = _cli(run, capsys)
    assert code == 2
    assert "give it in [design.params] (or --set design.params.speed=VALUE)" in err
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "__pycache__") == ["p.py"]


TYPED_PARAMS = """
import enum

from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Mode(enum.Enum):
    STOP = 0
    REVERSE = 1


class Typed(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def __init__(self, mode: Mode = Mode.STOP, taps: list = [1, 2], pair=(3, 4), gain=1.5):
        self.mode, self.taps, self.pair, self.gain = mode, taps, pair, gain
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.motor_left.eq(self.taps[0])
        return m
"""


def _built(reference, params):
    component = resolve_design(reference, params).build()
    Fragment.get(component, None)  # used: Amaranth warns of a component never elaborated
    return component


def test_parameters_reach_the_design_as_their_annotation_or_default_types(tmp_path):
    (tmp_path / "typed.py").write_text(TYPED_PARAMS)
    reference = f"{tmp_path}/typed.py:Typed"
    for given in ("REVERSE", "Mode.REVERSE"):
        design = _built(reference, {"mode": given})
        assert type(design.mode).__name__ == "Mode" and design.mode.name == "REVERSE"
    # TOML has arrays and integers only: each arrives as its parameter's list, tuple, float.
    design = _built(reference, {"taps": [5, 6], "pair": [7, 8], "gain": 2})
    assert (design.taps, design.pair, design.gain) == ([5, 6], (7, 8), 2.0)
    assert (type(design.taps), type(design.pair), type(design.gain)) == (list, tuple, float)
    for bad in ("bogus", 1):
        with pytest.raises(DesignError) as info:
            resolve_design(reference, {"mode": bad})
        assert str(info.value) == (
            f"design.params.mode must be one of STOP, REVERSE (a parameter of Typed), got {bad!r}"
        )


def test_a_bad_enum_parameter_is_one_line_from_the_command_line(tmp_path, capsys, monkeypatch):
    (tmp_path / "typed.py").write_text(TYPED_PARAMS)
    monkeypatch.chdir(tmp_path)
    code, out, err = _cli(["designs", "typed.py:Typed", "--param", "mode=bogus"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert "--param mode must be one of STOP, REVERSE (a parameter of Typed), got 'bogus'" in err
    code, _, err = _cli(
        [
            "run",
            "--scenario",
            str(WALL_STOP),
            "--design",
            "typed.py:Typed",
            "--set",
            "design.params={}",
            "--set",
            "design.params.mode=nonsense",
        ],
        capsys,
    )
    assert code == 2 and "design.params.mode must be one of STOP, REVERSE" in err


GENERIC_PARAMS = """
from typing import Literal, Optional

from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Generic(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def __init__(self, limit: Optional[int] = None, cap: float | None = 2.0,
                 side: Literal["left", "right"] = "left", taps: tuple[int, ...] = (1,),
                 gains: list[float] = [1.0], pair: tuple[int, str] = (1, "a"),
                 either: int | str = 0):
        self.limit, self.cap, self.side, self.taps = limit, cap, side, taps
        self.gains, self.pair, self.either = gains, pair, either
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.motor_left.eq(1)
        return m
"""


def test_generic_annotations_check_what_they_say(tmp_path):
    # Optional, Literal and the items of list[X] and tuple[...], by their annotation's words.
    (tmp_path / "generic.py").write_text(GENERIC_PARAMS)
    reference = f"{tmp_path}/generic.py:Generic"
    design = _built(
        reference,
        {"limit": 7, "cap": None, "side": "right", "taps": [3, 4], "gains": [2], "either": "x"},
    )
    assert (design.limit, design.cap, design.side) == (7, None, "right")
    assert (design.taps, design.gains, design.either) == ((3, 4), [2.0], "x")
    assert type(design.gains[0]) is float
    assert _built(reference, {"limit": None, "pair": [2, "b"]}).pair == (2, "b")
    for key, bad, words in (
        ("limit", "x", "an integer"),
        ("cap", "high", "a number"),
        ("side", "up", "one of 'left', 'right'"),
        ("side", 1, "one of 'left', 'right'"),
        ("taps", [1.5], "an array of integers"),
        ("gains", [1, "a"], "an array of numbers"),
        ("pair", [1, 2], "an array of 2 items (an integer, a string)"),
        ("pair", [1], "an array of 2 items (an integer, a string)"),
    ):
        with pytest.raises(DesignError) as info:
            resolve_design(reference, {key: bad})
        assert str(info.value) == (
            f"design.params.{key} must be {words} (a parameter of Generic), got {bad!r}"
        )


@pytest.mark.slow
def test_the_exported_verilog_drives_as_its_amaranth_design(tmp_path, capsys):
    """Round trip: wall_stop.py exported, run as Verilog through a port map, gives the
    Amaranth design's trajectory (same stop, same recorded distance) in the same scenario."""
    out_v = tmp_path / "WallStop.v"
    code, _out, err = _cli(
        ["export", "--design", f"{DESIGNS}/wall_stop.py:WallStop", "-o", str(out_v)], capsys
    )
    assert code == 0, err
    ports = tmp_path / "ports.toml"
    ports.write_text(
        'top = "WallStop"\nclock = { port = "clk" }\nreset = { port = "rst" }\n'
        '[outputs]\nmotor_left = { port = "motor_left", width = 16, signed = true }\n'
        'motor_right = { port = "motor_right", width = 16, signed = true }\n'
        '[connectors.ultrasound]\ntrig = "trig"\necho = "echo"\n'
        '[extra_outputs]\ndistance_mm = "distance_mm"\nstopped = "stopped"\n'
    )
    amaranth = run_scenario(load_scenario(str(WALL_STOP), ["sim.duration=4"]), backend="cxxrtl")
    scenario = load_scenario(
        str(WALL_STOP),
        [
            "sim.duration=4",
            f'design.top="verilog:{out_v}"',
            f'design.ports="{ports}"',
            "design.params={}",
        ],
    )
    verilog = run_scenario(scenario, backend="verilator")
    for column in ("x", "y", "heading", "motor_left", "design.distance_mm", "design.stopped"):
        np.testing.assert_array_equal(
            amaranth.trajectory[column], verilog.trajectory[column], err_msg=column
        )


def test_a_design_top_given_on_the_command_line_replaces_the_files_design():
    """line_track's file runs follow_line with a [design.line] table: another design.top from
    an override (run --design) drops that table, the same top keeps it, and a file that names
    a design of its own beside a built-in's table is still refused."""
    own = f"design.top={json.dumps(str(DESIGNS / 'wall_stop.py') + ':WallStop')}"
    replaced = load_scenario("line_track", [own])
    assert replaced.top.endswith("wall_stop.py:WallStop") and replaced.design_tables == {}
    same = load_scenario("line_track", ['design.top="follow_line"'])
    assert same.design_tables["line"].base_dps == 450  # the file's table, kept
    with pytest.raises(ScenarioError, match="design.line is a table of a built-in design"):
        load_scenario("line_track", [own, "design.line.base_dps=300"])


@pytest.mark.parametrize("name", ["OwnSync", "OwnSyncBelow"])
def test_a_design_defining_its_own_sync_domain_is_refused_by_every_command(
    name, tmp_path, capsys, monkeypatch
):
    """Its clock would be left undriven (export), clash with the board's sync domain (board,
    a traceback), or read as no clock at all (run): each command says why in one line."""
    shutil.copy(DESIGNS / "own_sync.py", tmp_path / "own_sync.py")
    monkeypatch.chdir(tmp_path)
    reference = f"own_sync.py:{name}"
    message = "defines its own 'sync' clock domain (m.domains.sync)"
    for argv in (
        ["designs", reference],
        ["export", "--design", reference, "-o", "out.v"],
        ["board", "--design", reference, "-o", "b"],
        ["formal", "--design", reference],
        ["run", "--scenario", str(WALL_STOP), "--design", reference, "--rerun", "off",
         "--set", "design.params={}"],
    ):  # fmt: skip
        code, out, err = _cli(argv, capsys)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (argv, err)
        assert message in err, err
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "__pycache__") == ["own_sync.py"]


def test_a_shadow_beside_a_verilog_design_keeps_the_scenario_s_params(tmp_path):
    """A primary --design verilog:... takes no [design.params]; a shadow design reference
    still gets the scenario's (docs/your_design.md), not its own defaults."""
    from fpga_robotics.cli import run

    scenario = tmp_path / "wall_stop.toml"
    scenario.write_text(WALL_STOP.read_text().replace("stop_mm = 250", "stop_mm = 120"))
    shutil.copy(DESIGNS / "wall_stop.py", tmp_path)
    verilog = DESIGNS / "bump_stop_noreset.v"
    argv = ["--scenario", str(scenario), "--design", f"verilog:{verilog}", "--backend", "cxxrtl"]
    argv += ["--ports", str(DESIGNS / "bump_stop_noreset_ports.toml")]
    argv += ["--shadow", f"{DESIGNS}/wall_stop.py:WallStop", "--shadow-param", "speed=200"]
    args = run.build_parser().parse_args(argv)
    primary = run.load_run_scenario(args)
    assert primary.design_params == {}
    shadow, _ = run.shadow_designs(args, primary)
    assert shadow.design_params == {"speed": 200, "stop_mm": 120}


ASSERTS = """
from amaranth import Module, Signal, signed
from amaranth.hdl import Assert
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Asserts(wiring.Component):
    trig: Out(1)
    echo: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        t = Signal(16)
        m.d.sync += t.eq(t + 1)
        m.d.comb += Assert(t < 100, "t too big")
        return m
"""


@pytest.mark.parametrize("backend", ["cxxrtl", "verilator"])
def test_a_failing_assert_is_left_out_by_the_compiled_backends(backend, tmp_path, capfd):
    """As the docs say: they printed it instead, Verilator on every clock (1.8 MB in 0.2 s
    of a run), CXXRTL once, and ran on; pysim stops at it."""
    (tmp_path / "asserts.py").write_text(ASSERTS)
    argv = ["run", "--scenario", str(WALL_STOP), "--design", f"{tmp_path}/asserts.py:Asserts"]
    argv += ["--set", "design.params={}", "--duration", "0.05", "--rerun", "off", "--quiet"]
    argv.append("--backend")
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, backend])
    out, err = capfd.readouterr()
    if info.value.code == 2 and "cannot run here" in err:
        pytest.skip(err)
    assert info.value.code == 0, err
    assert "too big" not in out + err
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "pysim"])
    out, err = capfd.readouterr()
    assert info.value.code == 2 and "Assertion violated: t too big" in err, err
