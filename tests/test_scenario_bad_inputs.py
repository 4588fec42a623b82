"""Bad scenario inputs through the real command line: each one stops before the run with exit
status 2 and exactly one line on stderr that names the key (no traceback), and leaves no
file behind.

Every case runs ``fpga_robotics.run.main`` in-process through ``run_cli`` (what ``python -m
fpga_robotics.run`` does), from an empty working folder; an input that is wrongly accepted
runs a short simulation and fails its case.
"""

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main

#: Every case runs with these; ``--rerun save`` would write ``runs/<scenario name>.rrd``.
BASE = ["--backend", "model", "--quiet"]
OFF = ["--rerun", "off"]

#: Scenario files the cases refer to as ``{in}/NAME.toml``.
FILES = {
    "escape": 'name = "../../escape/x"\n[sim]\nduration = 0.5\n',
    "absolute": 'name = "/tmp/x"\n[sim]\nduration = 0.5\n',
    "hidden": 'name = ".x"\n[sim]\nduration = 0.5\n',
    "long": f'name = "{"a" * 65}"\n[sim]\nduration = 0.5\n',
    "nan_change": '[sim]\nduration = 0.5\n[color]\nchanges = [{at = nan, color = "green"}]\n',
    "camera_int": "camera = 5\n[sim]\nduration = 0.5\n",
    "ov7670_unknown": '[sim]\nduration = 0.5\n[camera]\nsensor = "ov7670"\n'
    "[camera.ov7670]\nmax_gian = 8\n",
    "servo_unsigned": "people = []\n[sim]\nduration = 0.5\nclock_hz = 10000.0\n[design]\n"
    'top = "pan.py:Pan"\n[[robot.actuators]]\nkind = "servo"\nname = "pan"\n',
}
#: Design files beside them, ``{in}/NAME``.
DESIGNS = {
    # The servo's width, unsigned: its -100 would be read as 924, the end stop.
    "pan.py": """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Pan(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    angle: Out(10)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.angle.eq(-100)
        return m
""",
}

#: The shipped turret, short; its servo bound to a port, and a second camera on the pan one's bundle.
TURRET = ("--scenario", "turret", "--duration", "0.2")
SERVO = 'robot.actuators.0.ports={{angle="{}"}}'
TWO_CAMERAS = (
    'robot.sensors=[{kind="camera", name="pancam", height=0.2, ports={pixels="turret_pixels"}}, '
    '{kind="camera", name="rear", height=0.3, yaw_deg=180, ports={pixels="turret_pixels"}}]'
)
TWO_CAMERAS_SAY = (
    "robot.sensors[1] (rear) drives input 'turret_pixels__valid', which robot.sensors[0] "
    "(pancam) drives too; bind it to another port bundle"
)

# (id, arguments, text the one line must contain)
CASES = [
    # 5. absurd sizes: refused at load with the limit, instead of a silent hang
    ("duration-1e9", ["--duration", "1e9"], "sim.duration must be <= 86400 s (one day)"),
    ("physics-dt-1e-9", ["--set", "sim.physics_dt=1e-9"], "sim.physics_dt must be >= 1e-05"),
    (
        "too-many-steps",
        ["--set", "sim.duration=86400", "--set", "sim.physics_dt=1e-4"],
        "864000000 physics steps; the limit is 100000000",
    ),
    (
        "too-many-frames",
        ["--set", "camera.fps=1000", "--set", "sim.physics_dt=0.001", "--duration", "20000"],
        "20000000 camera frames; the limit is 10000000",
    ),
    ("fps-tiny", ["--set", "camera.fps=1e-9"], "camera.fps must be >= 0.1"),
    ("fps-huge", ["--set", "camera.fps=1e9"], "camera.fps must be <= 1000"),
    ("resolution-huge", ["--resolution", "8192x6144"], "camera.resolution 8192x6144"),
    ("resolution-narrow", ["--resolution", "8x6"], "camera.resolution 8x6"),
    ("delay-huge", ["--set", "sim.actuation_delay=1e9"], "sim.actuation_delay must be <= 10"),
    # 6. a scenario name becomes a file name (runs/<name>.rrd)
    ("name-escape", ["--scenario", "{in}/escape.toml", "--rerun", "save"], "name '../../escape/x'"),
    ("name-absolute", ["--scenario", "{in}/absolute.toml", "--rerun", "save"], "name '/tmp/x'"),
    ("name-hidden", ["--scenario", "{in}/hidden.toml", "--rerun", "save"], "name '.x'"),
    ("name-long", ["--scenario", "{in}/long.toml", "--rerun", "save"], "at most 64"),
    ("name-set", ["--set", "name=a/b", "--rerun", "save"], "name 'a/b'"),
    ("name-not-a-string", ["--set", "name=1"], "name must be a string"),
    # 8. wrong types, camera geometry the renderer cannot draw
    ("camera-int", ["--set", "camera=5"], "camera must be a table"),
    ("camera-int-in-file", ["--scenario", "{in}/camera_int.toml"], "camera must be a table"),
    ("color-int", ["--set", "color=1"], "color must be a table"),
    ("checks-int", ["--set", "checks=1"], "checks must be a table"),
    ("sim-int", ["--set", "sim=1"], "sim must be a table"),
    (
        "mount-height-above-ceiling",
        ["--set", "camera.mount_height=3"],
        "camera.mount_height must be below the ceiling (room.height = 2.5 m), got 3",
    ),
    (
        "robot-camera-above-ceiling",
        ["--set", "robot.camera_height=3"],
        "robot.camera_height must be below the ceiling (room.height = 2.5 m), got 3",
    ),
    (
        "room-below-camera",
        ["--set", "room.height=0.25"],
        "robot.camera_height must be below the ceiling (room.height = 0.25 m), got 0.3",
    ),
    (
        "robot-tilt-90",
        ["--set", "robot.camera_tilt_deg=90"],
        "robot.camera_tilt_deg must be <= 85, got 90",
    ),
    (
        "robot-tilt-70",
        ["--set", "robot.camera_tilt_deg=70"],
        "|robot.camera_tilt_deg| must be at most 65.4",
    ),
    ("camera-tilt-pi/2", ["--set", "camera.tilt=1.5707963"], "|camera.tilt| must be at most 1.142"),
    ("camera-tilt-1.2", ["--set", "camera.tilt=-1.2"], "|camera.tilt| must be at most 1.142"),
    ("hfov-3.1405", ["--set", "camera.hfov=3.1405"], "camera.hfov must be <= 3.1"),
    (
        "hfov-tall-image",
        ["--set", "camera.hfov=3.0", "--resolution", "40x160"],
        "camera.hfov must be at most 2.98",
    ),
    (
        "hfov-with-tilt",
        ["--set", "camera.hfov=2.5", "--set", "camera.tilt=0.8"],
        "|camera.tilt| must be at most",
    ),
    # 9. misleading messages
    ("scenario-folder", ["--scenario", "{in}"], "is a folder"),
    ("scenario-device", ["--scenario", "/dev/null"], "is not a regular file"),
    ("scenario-shipped-with-suffix", ["--scenario", "lost_target.toml"], "--scenario lost_target"),
    ("scenario-missing", ["--scenario", "nothere.toml"], "'nothere.toml' does not exist"),
    (
        "base-dps-word",
        ["--set", "design.base_dps=fast"],
        "design.base_dps must be an array of 8 integers",
    ),
    (
        "base-dps-short",
        ["--set", "design.base_dps=[1, 2]"],
        "design.base_dps must be an array of 8 integers",
    ),
    (
        "thresholds-int",
        ["--set", "design.proximity_thresholds=5"],
        "design.proximity_thresholds must be an array of 7 integers",
    ),
    ("design-int", ["--set", "design=1"], "design must be a table"),
    ("design-float", ["--set", "design.kp_num=1.5"], "design.kp_num must be an integer"),
    ("design-range", ["--set", "design.kp_shift=99"], "design.kp_shift must be <= 15, got 99"),
    ("people-index-out-of-range", ["--set", "people[3].speed=1"], "people is a list of 1"),
    # 10. nonsense values
    ("change-at-nan", ["--scenario", "{in}/nan_change.toml"], "color.changes[0].at"),
    (
        "change-at-nan-set",
        ["--set", 'color.changes=[{at = nan, color = "green"}]'],
        "color.changes[0].at must be a time in 0..86400 s, got nan",
    ),
    (
        "change-at-huge",
        ["--set", 'color.changes=[{at = 1e300, color = "green"}]'],
        "color.changes[0].at must be a time in 0..86400 s",
    ),
    ("noise-huge", ["--set", "camera.noise_std=1e300"], "camera.noise_std must be <= 64"),
    (
        "mount-forward-huge",
        ["--set", "camera.mount_forward=1e300"],
        "camera.mount_forward must be <= 2",
    ),
    (
        "check-inf",
        ["--set", "checks.acquired_within_s=inf"],
        "checks.acquired_within_s must be a number in 0..86400",
    ),
    (
        "check-fraction",
        ["--set", "checks.found_min_fraction=5"],
        "checks.found_min_fraction must be a number in 0..1",
    ),
    (
        "check-count-float",
        ["--set", "checks.max_person_collisions=1.5"],
        "checks.max_person_collisions must be an integer",
    ),
    (
        "check-bool",
        ["--set", "checks.acquired_within_s=true"],
        "checks.acquired_within_s must be a number",
    ),
    ("description-int", ["--set", "description=5"], "description must be a string"),
    ("seed-huge", ["--set", f"seed={2**64}"], "seed must be an integer in 0.."),
    (
        "light-direction-huge",
        ["--set", "lighting.direction=[1e300, 1e300, 1]"],
        "lighting.direction[0] must be",
    ),
    (
        "light-direction-tiny",
        ["--set", "lighting.direction=[1e-300, 0, 0]"],
        "lighting.direction must have a length of at least",
    ),
    (
        "keyframe-time-huge",
        ["--set", "lighting.keyframes=[[1e300, 1, 1]]"],
        "lighting.keyframes[0][0] (t) must be",
    ),
    ("robot-radius-tiny", ["--set", "robot.body_radius=1e-300"], "robot.body_radius must be"),
    ("robot-mass-tiny", ["--set", "robot.mass=1e-300"], "robot.mass must be"),
    ("person-radius-tiny", ["--set", "people.0.radius=1e-300"], "people[0].radius must be"),
    (
        "furniture-tiny",
        ["--set", "room.furniture=[{center = [3, 2], size = [1e-300, 1e-300]}]"],
        "room.furniture[0].size[0] must be",
    ),
    ("yield-gap-negative", ["--set", "people.0.yield_gap=-1"], "people[0].yield_gap must be"),
    # the sensor model (camera.sensor, [camera.ov7670])
    (
        "sensor-unknown",
        ["--set", "camera.sensor=ov7725"],
        "camera.sensor must be one of 'plain', 'ov7670', got 'ov7725'",
    ),
    ("sensor-table-int", ["--set", "camera.ov7670=3"], "camera.ov7670 must be a table"),
    (
        "sensor-key-unknown",
        ["--set", "camera.ov7670.gian=2"],
        "unknown scenario key 'camera.ov7670.gian'",
    ),
    (
        "sensor-key-unknown-in-file",
        ["--scenario", "{in}/ov7670_unknown.toml"],
        "unknown key camera.ov7670.max_gian (did you mean camera.ov7670.max_gain",
    ),
    (
        "sensor-gain-below-1",
        ["--set", "camera.ov7670.max_gain=0.5"],
        "camera.ov7670.max_gain must be >= 1, got 0.5",
    ),
    (
        "sensor-sensitivity-nan",
        ["--set", "camera.ov7670.sensitivity=nan"],
        "camera.ov7670.sensitivity must be a finite number",
    ),
    (
        "sensor-exposure-huge",
        ["--set", "camera.ov7670.exposure=2"],
        "camera.ov7670.exposure must be <= 1",
    ),
    (
        "sensor-bool-int",
        ["--set", "camera.ov7670.awb=1"],
        "camera.ov7670.awb must be true or false, got 1",
    ),
    (
        "sensor-gamma-unknown",
        ["--set", "camera.ov7670.gamma=srgb"],
        "camera.ov7670.gamma must be one of 'default', 'driver', 'off', got 'srgb'",
    ),
    (
        "sensor-bayer-unknown",
        ["--set", "camera.ov7670.bayer=BBGG"],
        "camera.ov7670.bayer must be one of",
    ),
    (
        "sensor-settle-float",
        ["--set", "camera.ov7670.settle_frames=2.5"],
        "camera.ov7670.settle_frames must be an integer 0..1000",
    ),
    (
        "sensor-window-reversed",
        ["--set", "camera.ov7670.aec_window=[117, 99]"],
        "camera.ov7670.aec_window must be [low, high]",
    ),
    (
        "sensor-window-outside-zone",
        ["--set", "camera.ov7670.aec_window=[30, 117]"],
        "camera.ov7670.aec_window [30, 117] must lie inside camera.ov7670.aec_fast_zone [64, 208]",
    ),
    (
        "sensor-snr-huge",
        ["--set", "camera.ov7670.snr_db=1e300"],
        "camera.ov7670.snr_db must be <= 80",
    ),
    # connector tables: the wheels are not declared, further cameras fit the room and the step
    (
        "wheels-declared",
        ["--scenario", "corridor", "--set", 'robot.actuators=[{kind="wheels"}]'],
        "robot.actuators[0].kind: the wheels are always there, bound in the design",
    ),
    (
        "sensor-as-actuator",
        ["--scenario", "corridor", "--set", 'robot.actuators=[{kind="lidar"}]'],
        "robot.actuators[0]: a 'lidar' connector is a sensor; declare it in [[robot.sensors]]",
    ),
    (
        "camera-above-ceiling",
        ["--scenario", "turret", "--duration", "0.2", "--set", "robot.sensors.0.height=2.6"],
        "robot.sensors[0].height 2.6 m must be below the ceiling (room.height 2.5 m)",
    ),
    (
        "camera-on-the-floor",
        ["--scenario", "turret", "--duration", "0.2", "--set", "robot.sensors.0.height=0"],
        "robot.sensors[0] (camera 'turret'): give its height above the floor",
    ),
    (
        "camera-faster-than-physics",
        [
            *("--scenario", "turret", "--duration", "0.2"),
            *("--set", "robot.sensors.0.fps=150", "--set", "sim.physics_dt=0.01"),
        ],
        "robot.sensors[0].fps 150 is more than one frame a physics step (sim.physics_dt 0.01 s",
    ),
    # a further camera's servo, target and port bundle: refused before the recorder opens
    (
        "camera-on-no-servo",
        [*TURRET, "--rerun", "save", "--set", 'robot.sensors.0.on="tilt"'],
        "camera 'turret': on = 'tilt' names no servo; declare [[robot.actuators]]",
    ),
    (
        "camera-target-in-an-empty-room",
        [*TURRET, "--rerun", "save", "--set", "people=[]"],
        "camera 'turret': target = 'watcher' names no person; the room has no people",
    ),
    (
        "camera-on-no-channel",
        [*TURRET, "--rerun", "save", "--set", 'robot.sensors.0.ports={pixels="nope"}'],
        "design 'turret_tracker' has no frame channel on pixels = 'nope'",
    ),
    (
        "camera-of-another-size-than-its-channel",
        [*TURRET, "--rerun", "save", "--set", 'robot.sensors.0.resolution="80x60"'],
        "its resolution 80x60 differs from the 160x120 frames design 'turret_tracker' takes",
    ),
    # real-clock timing: a clock too slow for a line of a streaming camera's pixels
    (
        "body-camera-pixels-beyond-the-clock",
        [
            *("--scenario", "obstacle_between", "--duration", "0.2", "--rerun", "save"),
            *("--set", "sim.clock_hz=100000"),
        ],
        (
            "camera: a 100000 Hz clock has 26 cycles per line at 30 fps, too few for 160 "
            "pixels; lower the resolution or fps (camera.resolution, camera.fps), or raise "
            "sim.clock_hz"
        ),
    ),
    (
        "further-camera-pixels-beyond-the-clock",
        [
            *(*TURRET, "--rerun", "save", "--set", 'sim.timing="real_clock"'),
            *("--set", "sim.clock_hz=1000000", "--set", "robot.sensors.0.fps=120"),
        ],
        (
            "camera 'turret': a 1e+06 Hz clock has 65 cycles per line at 120 fps, too few for "
            "160 pixels; lower the resolution or fps (robot.sensors[0].resolution, "
            "robot.sensors[0].fps), or raise sim.clock_hz"
        ),
    ),
    (
        # Captures at steps 0, 2, 5, 7 ... (2.4 steps a frame): 8.3 ms for 9.4 ms of pixels.
        "body-camera-frames-closer-than-their-pixels",
        [
            *("--scenario", "obstacle_between", "--duration", "0.2", "--rerun", "save"),
            *("--set", "camera.fps=100"),
        ],
        (
            "camera: camera.fps 100 on physics steps of 0.00416667 s: its captures fall on "
            "steps as little as 8.333 ms apart, less than its pixels take on the clock "
            "(9.357 ms); give it a frame period of whole physics steps (80 or 120 fps)"
        ),
    ),
    (
        "further-camera-frames-closer-than-their-pixels",
        [
            *(*TURRET, "--rerun", "save", "--set", 'sim.timing="real_clock"'),
            *("--set", "robot.sensors.0.fps=160"),
        ],
        "camera 'turret': robot.sensors[0].fps 160 on physics steps of 0.00416667 s",
    ),
    # a servo's port: a 10-bit signed output, and in compressed timing a channel's
    (
        "servo-on-an-input",
        [*TURRET, "--set", 'sim.timing="real_clock"', "--set", SERVO.format("color_sel")],
        (
            "the servo connector 'pan': pin 'angle' is out 10 bit(s) signed but port "
            "'color_sel' of design 'turret_tracker' is in 3 bit(s)"
        ),
    ),
    (
        "servo-on-a-wider-output",
        [*TURRET, "--set", 'sim.timing="real_clock"', "--set", SERVO.format("motor_left")],
        "port 'motor_left' of design 'turret_tracker' is out 16 bit(s) signed",
    ),
    (
        "servo-on-an-unsigned-output",
        [*TURRET, "--set", SERVO.format("turret_centroid_x")],
        "port 'turret_centroid_x' of design 'turret_tracker' is out 8 bit(s);",
    ),
    (
        # The run's width, not the default resolution's (8 bits at 160x120).
        "servo-on-an-unsigned-output-at-640x480",
        [
            *(*TURRET, "--set", 'sim.timing="real_clock"', "--set", SERVO.format("centroid_x")),
            *("--set", "camera.resolution=640x480"),
        ],
        "port 'centroid_x' of design 'turret_tracker' is out 10 bit(s);",
    ),
    (
        "servo-on-an-unsigned-output-of-its-width",
        ["--scenario", "{in}/servo_unsigned.toml"],
        (
            "the servo connector 'pan': pin 'angle' is out 10 bit(s) signed but port 'angle' "
            "of design 'Pan' is out 10 bit(s); it takes a signed output of at most 10 bits"
        ),
    ),
    (
        "servo-on-no-channel",
        [*TURRET, "--set", SERVO.format("centroid_x")],
        (
            # Only the channel outputs a servo can take are offered.
            "in compressed timing a servo hears an output of a further camera's channel of "
            "design 'turret_tracker', signed and at most 10 bits (servo_angle), not "
            "'centroid_x'"
        ),
    ),
    (
        "servo-on-a-design-without-one",
        [*TURRET, "--set", 'design.top="follow_target"', "--set", "robot.sensors.0.ports={}"],
        (
            "the servo connector 'pan': design 'follow_target' drives no servo (it binds no "
            "output to pin 'angle'); bind one with ports = {angle = \"PORT\"}"
        ),
    ),
    (
        "servo-on-a-design-without-one-real-clock",
        [
            *TURRET,
            *("--set", 'sim.timing="real_clock"', "--set", 'design.top="follow_target"'),
            *("--set", "robot.sensors.0.ports={}"),
        ],
        "the servo connector 'pan': design 'follow_target' drives no servo",
    ),
    # one table drives a design input
    (
        "two-lidars-on-one-stream",
        [
            *("--scenario", "corridor", "--duration", "0.2"),
            *("--set", 'robot.sensors=[{kind="lidar"}, {kind="lidar", yaw_deg=180}]'),
        ],
        (
            "robot.sensors[1] (lidar1) drives input 'lidar__valid', which robot.sensors[0] "
            '(lidar) drives too; bind it elsewhere with ports = {valid = "PORT", payload = "PORT"}'
        ),
    ),
    ("two-cameras-on-one-bundle", [*TURRET, "--set", TWO_CAMERAS], TWO_CAMERAS_SAY),
    (
        "two-cameras-on-one-bundle-real-clock",
        [*TURRET, "--set", TWO_CAMERAS, "--set", 'sim.timing="real_clock"'],
        TWO_CAMERAS_SAY,
    ),
    # FollowTarget's keys on a design that reads none of them: refused, as export does
    (
        "preset-on-follow-line",
        ["--scenario", "line_track", "--set", "design.preset=published"],
        (
            "design.preset applies to a design with FollowTarget or a camera "
            "(follow_target, follow_target_safe, turret_tracker), not to design.top = "
            "'follow_line'"
        ),
    ),
    (
        "follow-target-keys-on-corridor",
        ["--scenario", "corridor", "--set", "design.diff_min=0", "--set", "design.max_dps=10"],
        "design.diff_min, design.max_dps apply to a design with FollowTarget or a camera",
    ),
]


def run(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        run_cli(main, argv, prog="fpga-robotics run")
    out, err = capsys.readouterr()
    return exc.value.code, out, err


def files_under(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("args,expect", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_one_line_exit_2_and_leaves_nothing(
    args, expect, tmp_path, monkeypatch, capsys
):
    inputs = tmp_path / "in"
    inputs.mkdir()
    for name, text in FILES.items():
        (inputs / f"{name}.toml").write_text(text)
    for name, text in DESIGNS.items():
        (inputs / name).write_text(text)
    cwd = tmp_path / "work" / "here"  # runs/../../escape would land in tmp_path
    cwd.mkdir(parents=True)
    monkeypatch.chdir(cwd)
    before = files_under(tmp_path)
    argv = [a.replace("{in}", str(inputs)) for a in args]
    if "--rerun" not in argv:
        argv += OFF
    code, out, err = run(BASE + argv, capsys)
    assert (code, out) == (2, ""), err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("fpga-robotics run: error: "), lines[0]
    assert expect in lines[0]
    assert "Traceback" not in err
    assert files_under(tmp_path) == before


def test_the_table_has_no_duplicate_ids():
    ids = [c[0] for c in CASES]
    assert len(ids) == len(set(ids))
