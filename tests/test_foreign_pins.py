"""Foreign Verilog designs in real-clock timing (docs/foreign.md, "Sensors on pins"): a port
map's ``[connectors.<kind>]`` binds a connector's pins to the design's ports, and the design
runs on a compiled pin backend in the closed loop (``auto``: CXXRTL; tests/test_foreign_cxxrtl.py
compares it with Verilator).

The design is tests/data/bump_stop.v: on at 300 DPS until the bumper closes, then stopped for
good (an active-low reset, 12-bit wheel speeds sign-extended by the map). It must stop short
of the wall by the bumper's margin less the braking distance, and drive exactly as the same
logic written in Amaranth and registered with ``register_top``.
"""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from renamed_design import RENAMED, RENAMED_MAP

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.designs.builtin import TOPS, Top, register_top
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.port_map import PortMapError, parse_port_map

DATA = Path(__file__).parent / "data"
VERILOG = DATA / "bump_stop.v"
PORTS = DATA / "bump_stop_ports.toml"
MARGIN = 0.03  # the bumper closes 3 cm from the wall
ROOM_WIDTH, START_X = 2.0, 0.5

#: A scenario: the robot drives at a wall 2 m away (x = 2) until its bumper closes.
SCENARIO = """
people = []
[sim]
duration = {duration}
clock_hz = 10000.0
{design}
[room]
width = 2.0
depth = 1.0
[robot]
model = "gopigo3"
start = [0.5, 0.5]
[[robot.sensors]]
kind = "bumper"
margin = 0.03
[checks]
max_wall_collisions = 0
"""
VERILOG_DESIGN = f'[design]\nverilog = "{VERILOG}"\nports = "{PORTS}"'


class BumpStop(wiring.Component):
    """tests/data/bump_stop.v in Amaranth (docs/connectors.md's example)."""

    bump: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        hit = Signal()
        with m.If(self.bump):
            m.d.sync += hit.eq(1)
        speed = Signal(signed(16))
        m.d.comb += speed.eq(Mux(hit, 0, 300))
        m.d.comb += [self.motor_left.eq(speed), self.motor_right.eq(speed)]
        return m


def _scenario(tmp_path, design, duration=12.0, name="bump.toml"):
    path = tmp_path / name
    path.write_text(SCENARIO.format(duration=duration, design=design))
    return load_scenario(str(path))


@pytest.fixture(scope="module")
def verilog_run(tmp_path_factory):
    scenario = _scenario(tmp_path_factory.mktemp("vlog"), VERILOG_DESIGN)
    assert scenario.sim.timing == "real_clock"  # "auto": the port map binds a connector
    return run_scenario(scenario, backend="auto")


def test_the_verilog_design_stops_short_of_the_wall_by_margin_less_braking(verilog_run):
    from fpga_robotics.sim.world import World

    spec = World.from_config(
        {
            "room": {"width": 2.0, "depth": 1.0},
            "people": [],
            "robot": {"model": "gopigo3", "start": [0.5, 0.5]},
        }
    ).robot_spec
    traj = verilog_run.trajectory
    assert verilog_run.summary["verdict"] == "pass"
    assert verilog_run.summary["timing"] == "real_clock"
    assert traj["bumper.pressed"][-1] == 1.0
    assert traj["motor_left"][0] == 300 and traj["motor_left"][-1] == 0
    # From 300 DPS at the wheels' ramp: v0^2 / (2 a) of wheel angle, times the wheel radius.
    braking = math.radians(300.0**2 / (2 * spec.wheel_accel_dps2)) * spec.wheel_radius
    gap = ROOM_WIDTH - spec.body_radius - traj["x"][-1]
    # Discrete time moves it by up to a physics step (1/240 s) of travel at 0.17 m/s each:
    # the bumper is sampled at a step's start, the 1 ms actuation delay ends at a step, the
    # wheels ramp step by step.
    step = math.radians(300.0) * spec.wheel_radius / 240
    assert MARGIN - braking - 3 * step <= gap <= MARGIN - braking + step
    # Absent outputs stay absent (the map names no found/proximity/centroid).
    assert set(verilog_run.summary["absent_outputs"]) == {
        "found",
        "proximity",
        "centroid_x",
        "centroid_leds",
    }


def test_the_verilog_design_drives_exactly_as_its_amaranth_twin(verilog_run, tmp_path):
    register_top(
        Top(
            "bump_stop_twin",
            "BumpStop in Amaranth",
            camera=False,
            component=BumpStop,
            takes_follow_target_params=False,
            bindings={
                "wheels": {"motor_left": "motor_left", "motor_right": "motor_right"},
                "bumper": {"pressed": "bump"},
            },
        )
    )
    try:
        twin = run_scenario(
            _scenario(tmp_path, '[design]\ntop = "bump_stop_twin"'), backend="pysim"
        )
    finally:
        TOPS.pop("bump_stop_twin", None)
    for key in ("x", "y", "heading", "motor_left", "motor_right", "bumper.pressed"):
        assert (twin.trajectory[key] == verilog_run.trajectory[key]).all(), key
    assert twin.summary["sim_cycles"] == verilog_run.summary["sim_cycles"]


def test_a_verilog_design_runs_on_the_compiled_backends_only(tmp_path):
    from fpga_robotics.loop.real_clock import pin_design_source
    from fpga_robotics.sim.pins import PinError, get_pin_backend

    source = pin_design_source(_scenario(tmp_path, VERILOG_DESIGN, duration=0.1))
    assert set(source.ports) == {"motor_left", "motor_right", "bump_i"}
    with pytest.raises(
        PinError,
        match="the pysim pin backend cannot run a Verilog "
        "design.*use the cxxrtl or verilator backend",
    ):
        get_pin_backend("pysim", source)


def _map(**extra):
    text = PORTS.read_text()
    for key, value in extra.items():
        text = text.replace(key, value)
    return text


#: (case, port map text or a change to the scenario, words of the one-line error).
BAD_MAPS = [
    (
        "unknown connector kind",
        _map(**{"[connectors.bumper]": "[connectors.sonar]"}),
        "connectors.sonar: unknown connector kind; known: bumper, ",
    ),
    (
        "unknown pin",
        _map(pressed="pushed"),
        "connectors.bumper.pushed: the bumper connector has no pin 'pushed'",
    ),
    (
        "missing port",
        _map(**{'pressed = "bump_i"': 'pressed = "bump"'}),
        "connectors.bumper.pressed: the design bump_stop has no port 'bump'",
    ),
    (
        "wrong direction",
        _map(**{'pressed = "bump_i"': 'pressed = "hit_o"\n[constants]\nbump_i = 0'}),
        (
            "connectors.bumper.pressed: port 'hit_o' of bump_stop is an output; the bumper pin "
            "'pressed' needs an input"
        ),
    ),
    (
        "camera as a connector",
        _map(**{"[connectors.bumper]": "[connectors.camera]"}),
        "connectors.camera: the camera is bound by pixels and color",
    ),
]


def _run_cli(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        run_cli(run_main, argv, prog="fpga-robotics run")
    err = capsys.readouterr().err
    return exit_info.value.code, err


@pytest.mark.parametrize("case, text, message", BAD_MAPS, ids=[c[0] for c in BAD_MAPS])
def test_bad_connector_maps_are_one_line_errors(case, text, message, tmp_path, capsys):
    ports = tmp_path / "ports.toml"
    ports.write_text(text)
    scenario = tmp_path / "bump.toml"
    scenario.write_text(SCENARIO.format(duration=0.1, design=""))
    code, err = _run_cli(
        [
            "--scenario",
            str(scenario),
            "--design",
            f"verilog:{VERILOG}",
            "--ports",
            str(ports),
            "--rerun",
            "off",
            "--quiet",
        ],
        capsys,
    )
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert message in err


def test_a_too_wide_port_is_refused(tmp_path, capsys):
    wide = tmp_path / "wide.v"
    wide.write_text(VERILOG.read_text().replace("input bump_i", "input [3:0] bump_i"))
    scenario = tmp_path / "bump.toml"
    scenario.write_text(SCENARIO.format(duration=0.1, design=""))
    code, err = _run_cli(
        [
            "--scenario",
            str(scenario),
            "--design",
            f"verilog:{wide}",
            "--ports",
            str(PORTS),
            "--rerun",
            "off",
            "--quiet",
        ],
        capsys,
    )
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert (
        "connectors.bumper.pressed: port 'bump_i' of bump_stop is 4 bits wide; the "
        "bumper pin 'pressed' takes 1 bit"
    ) in err


def test_other_backends_and_compressed_timing_are_usage_errors(tmp_path, capsys):
    scenario = tmp_path / "bump.toml"
    scenario.write_text(SCENARIO.format(duration=0.1, design=VERILOG_DESIGN))
    code, err = _run_cli(
        ["--scenario", str(scenario), "--backend", "pysim", "--rerun", "off"], capsys
    )
    assert code == 2 and "runs on the cxxrtl or verilator backend, not 'pysim'" in err
    code, err = _run_cli(
        ["--scenario", str(scenario), "--set", 'sim.timing="compressed"', "--rerun", "off"], capsys
    )
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert 'needs sim.timing = "real_clock"' in err
    code, err = _run_cli(
        ["--scenario", str(scenario), "--runtime", "mode=1", "--rerun", "off"], capsys
    )
    # In real-clock timing --runtime holds a [runtime] input of the map; this map has none.
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "--runtime: the design has no [runtime] input 'mode' (its runtime inputs: none)" in err


def test_parse_errors_name_the_key():
    base = {
        "top": "t",
        "clock": {"port": "clk"},
        "reset": {"port": "rst"},
        "outputs": {"motor_left": "l", "motor_right": "r"},
    }
    # Wheels alone: a design without a camera and without connectors (it runs on pins).
    pm = parse_port_map(base)
    assert not pm.has_pixels and not pm.connectors
    assert set(pm.outputs) == {"motor_left", "motor_right"}
    with pytest.raises(PortMapError, match="missing \\[pixels\\]"):
        parse_port_map({k: v for k, v in base.items() if k != "outputs"})  # nothing at all
    pm = parse_port_map({**base, "connectors": {"bumper": {"pressed": "b"}}})
    assert not pm.has_pixels and pm.connector_ports() == {"b": "connectors.bumper.pressed"}
    with pytest.raises(PortMapError, match="connectors.bumper.pressed must be a Verilog port"):
        parse_port_map({**base, "connectors": {"bumper": {"pressed": 3}}})
    with pytest.raises(PortMapError, match="port 'l' is mapped more than once"):
        parse_port_map({**base, "connectors": {"bumper": {"pressed": "l"}}})
    with pytest.raises(PortMapError, match="outputs.found is read when a frame's result"):
        parse_port_map(
            {
                **base,
                "outputs": {**base["outputs"], "found": "f"},
                "connectors": {"bumper": {"pressed": "b"}},
            }
        )


@pytest.mark.slow
def test_a_camera_design_in_verilog_follows_as_follow_target_does(tmp_path):
    from fpga_robotics.hw.verilog import generate_verilog

    real_clock = [
        'camera.resolution="40x30"',
        'sim.timing="real_clock"',
        "sim.clock_hz=2e5",
        "sim.duration=0.6",
    ]
    builtin = load_scenario("follow_person", real_clock)
    params = builtin.params
    (tmp_path / "follow_target.v").write_text(generate_verilog(params))
    (tmp_path / "robot_top.v").write_text(RENAMED % {"xmsb": params.x_bits - 1})
    (tmp_path / "robot.toml").write_text(RENAMED_MAP % {"latency": params.motor_latency})
    verilog = load_scenario(
        "follow_person",
        [
            *real_clock,
            f'design.verilog=["{tmp_path}/robot_top.v", "{tmp_path}/follow_target.v"]',
            f'design.ports="{tmp_path}/robot.toml"',
        ],
    )
    theirs = run_scenario(verilog, backend="auto")
    ours = run_scenario(builtin, backend="pysim")
    assert theirs.summary["sim_cycles"] == ours.summary["sim_cycles"] == 120_000
    # The robot moves: the frames' commands reach the wheels.
    assert (ours.trajectory["motor_left"] != 0).any()
    for key in ("x", "y", "heading", "motor_left", "motor_right", "centroid_leds"):
        assert (theirs.trajectory[key] == ours.trajectory[key]).all(), key
    assert "found" in theirs.summary["absent_outputs"]


SAFE_MAP = """\
style = "stream"
top = "follow_target"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "pixels__valid", payload = "pixels__payload" }
color = { port = "color_sel" }
result = { strobe = "frame_done", latency = %(latency)d }

[outputs]
found = "found"
motor_left = "motor_left"
motor_right = "motor_right"

[connectors.ultrasound]
trig = "us_trig"
echo = "us_echo"
"""


@pytest.mark.slow
def test_a_camera_and_ultrasound_design_in_verilog_stops_as_follow_target_safe(tmp_path):
    """FollowTargetSafe exported to Verilog, its HC-SR04 pins bound by the port map, 0.3 m
    from a box: its interlock stops the wheels at the same cycles as the Amaranth design's."""
    from fpga_robotics.designs.builtin import build_component, get_top
    from fpga_robotics.hw.safe_follow import FollowTargetSafe
    from fpga_robotics.hw.verilog import generate_verilog

    scene = [
        'camera.resolution="40x30"',
        "sim.clock_hz=2e5",
        "sim.duration=0.5",
        "robot.start=[2.05, 2.0]",
    ]
    builtin = load_scenario("obstacle_between", [*scene, "design.ultrasound.clock_hz=200000"])
    component = build_component(
        get_top("follow_target_safe"), builtin.params, builtin.design_tables
    )
    assert isinstance(component, FollowTargetSafe)
    (tmp_path / "safe.v").write_text(generate_verilog(component=component))
    (tmp_path / "safe.toml").write_text(SAFE_MAP % {"latency": builtin.params.motor_latency})
    verilog = load_scenario(
        "obstacle_between",
        [
            *scene,
            f'design.top="verilog:{tmp_path}/safe.v"',
            f'design.ports="{tmp_path}/safe.toml"',
        ],
    )
    assert verilog.sim.timing == "real_clock"
    theirs = run_scenario(verilog, backend="auto")
    ours = run_scenario(builtin, backend="pysim")
    # The interlock held the wheels: the box's face is 0.25 m ahead of the sensor.
    assert ours.trajectory["design.obstacle"][-1] == 1
    assert ours.trajectory["motor_left"][-1] == 0 == ours.trajectory["motor_right"][-1]
    for key in ("x", "y", "heading", "motor_left", "motor_right", "found", "front.echo_edges"):
        assert np.array_equal(theirs.trajectory[key], ours.trajectory[key], equal_nan=True), key


def test_verilog_yosys_cannot_read_names_the_user_s_top_and_the_option_to_change(tmp_path, capsys):
    from fpga_robotics.cli import run
    from fpga_robotics.hw.errors import UsageError
    from fpga_robotics.sweep import runner

    # SystemVerilog's `inside`: Verilator reads it, Yosys does not (docs/foreign.md).
    text = VERILOG.read_text().replace("module bump_stop", "module bump_sv")
    text = text.replace("else if (bump_i)", "else if (bump_i inside {1'b1})")
    (tmp_path / "bump_sv.sv").write_text(text)
    (tmp_path / "bump_sv.toml").write_text(
        PORTS.read_text().replace('top = "bump_stop"', 'top = "bump_sv"')
    )
    scenario = tmp_path / "bump.toml"
    design = (
        f'[design]\nverilog = "{tmp_path / "bump_sv.sv"}"\nports = "{tmp_path / "bump_sv.toml"}"'
    )
    scenario.write_text(SCENARIO.format(duration=0.1, design=design))
    argv = ["--scenario", str(scenario), "--backend", "cxxrtl", "--rerun", "off"]
    code, err = _run_cli(argv, capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    # The port map's top, not the generated wrapper's; the option that picks its backend.
    assert "Yosys cannot read the design for CXXRTL (top bump_sv): bump_sv.sv:" in err
    assert err.rstrip().endswith("run it on the Verilator backend (--backend verilator)")
    # As a shadow design, its backend is --shadow-backend's.
    args, loaded, _ = runner.load_run(argv)
    with pytest.raises(UsageError) as info:
        run._open_pin_design(args, loaded, "--shadow verilog:bump_sv.sv", "--shadow-backend")
    message = str(info.value)
    assert message.startswith("--shadow verilog:bump_sv.sv: ") and "(top bump_sv)" in message
    assert message.endswith("(--shadow-backend verilator)")


#: A combinational loop in Verilog Yosys cannot read (``inside``), so no check finds it before
#: the run: y = ~y, whichever value the bumper's pin has.
LOOP_SV = """\
module loopsv (input clk, input rst, input a, output signed [15:0] l, output signed [15:0] r);
  wire x, y;
  assign x = ~y ^ a;
  assign y = x inside {1'b1};
  assign l = y ? 16'sd100 : 16'sd0;
  assign r = l;
endmodule
"""


@pytest.mark.slow  # builds a Verilator model
def test_a_loop_only_verilator_reads_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "loopsv.sv").write_text(LOOP_SV)
    (tmp_path / "ports.toml").write_text(
        PORTS.read_text()
        .replace('"bump_stop"', '"loopsv"')
        .replace('"rst_n", active_low = true', '"rst"')
        .replace('"left_dps", width = 12', '"l", width = 16')
        .replace('"right_dps", width = 12', '"r", width = 16')
        .replace('"bump_i"', '"a"')
    )
    (tmp_path / "wall.toml").write_text((DATA / "bump_wall.toml").read_text())
    argv = ["--scenario", "wall.toml", "--design", "verilog:loopsv.sv", "--ports", "ports.toml"]
    argv += ["--duration", "0.1", "--rerun", "off", "--quiet", "--summary", "s.json"]
    # Verilator ends the process: run it in one of its own.
    done = subprocess.run(
        [sys.executable, "-m", "fpga_robotics", "run", *argv],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and "%Error" not in done.stderr + done.stdout
    assert done.stderr.startswith("fpga-robotics: error: the design stopped in Verilator: ")
    assert "a combinational loop" in done.stderr and "break the loop with a register" in done.stderr
    assert not (tmp_path / "s.json").exists()
