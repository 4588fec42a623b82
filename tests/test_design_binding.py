"""How a design of one's own meets the connectors (docs/your_design.md): wheel ports narrower
than the connector's 16 bits are read sign-extended, wider or unsigned ones are refused in
one line; a camera stream declared under the design's own port name is streamed to it."""

import json
import re
import tomllib
from pathlib import Path

import pytest

from fpga_robotics import cli
from fpga_robotics.designs.reference import DesignError, resolve_design, stream_ports
from fpga_robotics.loop.pin_frames import SETTLE_EDGES
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.mutation.design import design_mutant_port_map
from fpga_robotics.mutation.design_run import design_ports
from fpga_robotics.mutation.pin_judge import pin_stimulus, streams_frames
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.frames import to_rgb444

DESIGNS = Path(__file__).parent / "data" / "user_designs"
NARROW = f"{DESIGNS / 'narrow_wheels.py'}:NarrowWheels"

#: A room to stand in; the design drives constant wheel commands.
STRAIGHT = """
name = "narrow"
people = []
[sim]
duration = 0.5
clock_hz = 10000.0
[design]
top = "{top}"
[room]
width = 4.0
depth = 2.0
[robot]
model = "gopigo3"
start = [2.0, 1.0]
"""


def test_narrow_signed_wheels_are_read_sign_extended(tmp_path):
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=NARROW))
    result = run_scenario(load_scenario(str(tmp_path / "s.toml")), backend="pysim")
    traj = result.trajectory
    # -100 in 8 bits is 0x9C: read unsigned it would be 156.
    assert (traj["motor_left"][1:] == -100).all() and (traj["motor_right"][1:] == 60).all()
    # The left wheel backwards, the right forwards: the robot turns left (heading grows).
    assert traj["heading"][-1] > traj["heading"][0]


@pytest.mark.parametrize(
    "params, message",
    [
        (
            {"width": 17},
            "port 'motor_left' (the wheels' motor_left pin) is an output of signed(17)",
        ),
        (
            {"width": 16, "signed_wheels": False},
            "is an output of unsigned(16); the wheels take a signed output of at most 16 bits",
        ),
    ],
)
def test_wide_or_unsigned_wheels_are_one_line_errors(params, message, tmp_path, capsys):
    with pytest.raises(DesignError, match=message.replace("(", r"\(").replace(")", r"\)")):
        resolve_design(NARROW, params)
    # Every command that resolves the design says the same: designs, run.
    argv = [NARROW] + [f"--param={k}={str(v).lower()}" for k, v in params.items()]
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=NARROW))
    sets = [a for k, v in params.items() for a in ("--set", f"design.params.{k}={str(v).lower()}")]
    for command in (
        ["designs", *argv],
        ["run", "--scenario", str(tmp_path / "s.toml"), "--rerun", "off", *sets],
    ):
        with pytest.raises(SystemExit) as info:
            cli.main(command)
        err = capsys.readouterr().err
        assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
        assert message in err


# A camera under the design's own port names ----------------------------------------------

NEAR_RED_CAM = f"{DESIGNS / 'near_red_cam.py'}:NearRedCam"


def test_a_camera_declared_under_its_own_port_name_is_streamed_to(tmp_path):
    frames = []
    scenario = load_scenario(
        str(DESIGNS / "near_red.toml"), [f'design.top="{NEAR_RED_CAM}"', "sim.duration=3.0"]
    )
    result = run_scenario(
        scenario, backend="cxxrtl", on_frame=lambda r: frames.append(r.camera_rgb)
    )
    traj = result.trajectory
    # red_count in row k is frame k-1's, counted here from the camera's own frames:
    # strongly red RGB444 pixels (as near_red.py's, whose ports have the default names).
    w, h = scenario.camera.width, scenario.camera.height
    packed = [to_rgb444(f, w, h) for f in frames]
    counts = [int(((p >> 8 >= 8) & ((p >> 4) & 15 < 5) & (p & 15 < 5)).sum()) for p in packed]
    assert max(counts) > 0
    assert list(traj["design.red_count"][1:]) == counts[:-1]
    # The wheels declared as wheel_l/wheel_r: 400 DPS (design.params.speed) until near.
    assert set(traj["motor_left"][1:]) <= {0.0, 400.0} and traj["motor_left"][1] == 400
    assert set(result.summary["extra_outputs"]) == {"near", "red_count"}


STREAM_ONLY = """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature


class StreamOnly(wiring.Component):
    connectors = {"camera": {"pixels": "cam"}}
    cam: In(pixel_stream_signature())
    color_sel: In(3)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    seen: Out(3)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.seen.eq(self.color_sel)
        return m
"""


def test_a_camera_declared_by_its_stream_only_takes_color_sel_by_name(tmp_path):
    # As docs/your_design.md reads: the run refused it ("nothing drives its input
    # 'color_sel'"), though a shadow of it ran.
    (tmp_path / "stream_only.py").write_text(STREAM_ONLY)
    reference = f"{tmp_path / 'stream_only.py'}:StreamOnly"
    assert resolve_design(reference).bindings["camera"] == {
        "pixels": "cam",
        "color_sel": "color_sel",
    }
    items = [f'design.top="{reference}"', "design.params={}", 'color.initial="green"']
    scenario = load_scenario(str(DESIGNS / "near_red.toml"), [*items, "sim.duration=0.3"])
    traj = run_scenario(scenario, backend="pysim").trajectory
    # Green is colour select code 0b010 (docs/contract.md).
    assert list(traj["design.seen"][1:]) == [2] * (len(traj["design.seen"]) - 1)


def test_a_declared_stream_that_is_no_stream_input_is_one_line_error(capsys):
    message = "connectors['camera']['pixels']: 'wheel_l' is no pixel stream input of NearRedCam"
    with pytest.raises(DesignError, match=re.escape(message)):
        resolve_design(NEAR_RED_CAM, {"stream": "wheel_l"})
    with pytest.raises(SystemExit) as info:
        cli.main(["designs", NEAR_RED_CAM, '--param=stream="wheel_l"'])
    err = capsys.readouterr().err
    assert info.value.code == 2 and len(err.strip().splitlines()) == 1 and message in err


def test_mutate_streams_frames_on_the_declared_stream():
    spec = resolve_design(NEAR_RED_CAM)
    ports = design_ports(spec)
    stream = stream_ports(spec.bindings)
    assert stream == ("cam__valid", "cam__payload") and streams_frames(ports, stream)
    stimulus = pin_stimulus(ports, 40, seed=3, frame=(4, 3), stream=stream)
    # Frames of 12 pixels from edge 1, a line (4 edges) between them: valid rises at 1, 17
    # and 33 and falls after each frame's last pixel; never a random change.
    valid = [(e, v) for e, p, v in stimulus if p == "cam__valid"]
    assert valid == [(1, 1), (13, 0), (17, 1), (29, 0), (33, 1)]
    payload = [e for e, p, _ in stimulus if p == "cam__payload"]
    assert payload == [*range(1, 13), *range(17, 29), *range(33, 41)]
    # The robot judge's port map streams the camera's frames on the same ports.
    text = design_mutant_port_map(spec, ports)
    assert tomllib.loads(text)["pixels"] == {"valid": "cam__valid", "payload": "cam__payload"}


def test_a_shadow_with_its_own_stream_name_is_streamed_the_same_frames(tmp_path, capsys):
    # NearRed (the stream named pixels) with NearRedCam (cam) as its shadow: the same logic,
    # so its red counts match frame for frame only if it is streamed the frames too.
    summary = tmp_path / "s.json"
    argv = ["run", "--scenario", str(DESIGNS / "near_red.toml"), "--shadow", NEAR_RED_CAM]
    argv += ["--backend", "cxxrtl", "--set", "sim.duration=2.0", "--rerun", "off", "--quiet"]
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "--summary", str(summary)])
    assert info.value.code == 0, capsys.readouterr().err
    trajectory_counts = json.loads(summary.read_text())["extra_outputs"]["red_count"]
    assert trajectory_counts["max"] > 0
    shadow = json.loads(summary.read_text())["shadow"]
    assert shadow["frames"] == 20 and shadow["first_divergence"] is None
    assert shadow["differing_frames"] == {
        "motor_left": 0,
        "motor_right": 0,
        "near": 0,
        "red_count": 0,
    }


def test_a_shadow_s_wheels_under_other_port_names_are_compared_as_the_wheels(tmp_path, capsys):
    # NearRedCam drives wheel_l/wheel_r, NearRed motor_left/motor_right: at 300 DPS against
    # 400 they differ on every row the robot drives, and only there.
    summary = tmp_path / "s.json"
    argv = ["run", "--scenario", str(DESIGNS / "near_red.toml"), "--shadow", NEAR_RED_CAM]
    argv += ["--shadow-param", "speed=300", "--set", "robot.start=[2.2, 1.5]"]
    argv += ["--backend", "cxxrtl", "--duration", "2", "--rerun", "off", "--quiet"]
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "--summary", str(summary)])
    assert info.value.code == 0, capsys.readouterr().err
    result = json.loads(summary.read_text())
    first = result["shadow"]["first_divergence"]
    assert first["frame"] == 0
    assert first["outputs"] == {
        "motor_left": {"primary": 400, "shadow": 300},
        "motor_right": {"primary": 400, "shadow": 300},
    }
    driving = result["shadow"]["differing_frames"]["motor_left"]
    assert 0 < driving < 20 and result["extra_outputs"]["near"]["last"] == 1
    assert result["shadow"]["differing_frames"]["near"] == 0


# Part of a connector by name ----------------------------------------------------------------

PARTIAL = """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature

WHEELS = {"motor_left": Out(signed(16)), "motor_right": Out(signed(16))}


class Ports(wiring.Component):
    def __init__(self, ports):
        super().__init__(ports)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.motor_left.eq(1)
        return m


def one_wheel():
    return Ports({"motor_left": Out(signed(16))})


def misspelt_wheel():
    return Ports({"motor_left": Out(signed(16)), "motor_rigth": Out(signed(16))})


def trig_alone():
    return Ports({**WHEELS, "trig": Out(1)})


def color_sel_alone():
    return Ports({**WHEELS, "color_sel": In(3)})


def plain_pixels():
    return Ports({**WHEELS, "pixels": In(14)})


def outputs_named_as_input_pins():
    return Ports({**WHEELS, "echo": Out(1), "valid": Out(1), "pixels": Out(14)})


def misnamed_stream():
    return Ports({**WHEELS, "pixel": In(pixel_stream_signature()), "frame_done": Out(1)})


def output_pixel_stream():
    # The camera's stream with its direction turned: the run passed, the design seeing nothing.
    return Ports({**WHEELS, "pixels": Out(pixel_stream_signature()), "frame_done": Out(1)})


def narrow_pixel_stream():
    from amaranth.lib import stream

    return Ports({**WHEELS, "pixels": In(stream.Signature(8, always_ready=True))})


def stallable_pixel_stream():
    from amaranth.lib import stream

    from fpga_robotics.hw.pixel import FramedPixel

    return Ports({**WHEELS, "pixels": In(stream.Signature(FramedPixel)), "frame_done": Out(1)})


def narrow_color_sel():
    return Ports({**WHEELS, "pixels": In(pixel_stream_signature()), "color_sel": In(2)})


def stallable_output_stream():
    from amaranth.lib import stream

    return Ports({**WHEELS, "events": Out(stream.Signature(8))})
"""


@pytest.mark.parametrize(
    "name, message",
    [
        (
            "one_wheel",
            (
                "design Ports has motor_left but no motor_right: the wheels connector binds by "
                "name only when the design has motor_left and motor_right; add motor_right: "
                "Out(signed(16))"
            ),
        ),
        ("misspelt_wheel", "design Ports has motor_left but no motor_right"),
        (
            "trig_alone",
            (
                "design Ports has trig but no echo: the ultrasound connector binds by name only "
                "when the design has trig and echo; add echo: In(1)"
            ),
        ),
        (
            "color_sel_alone",
            (
                "design Ports has color_sel but no pixels: the camera connector binds by name "
                "only when the design has pixels; add pixels: "
                "In(fpga_robotics.hw.pixel.pixel_stream_signature())"
            ),
        ),
        (
            "plain_pixels",
            (
                "design Ports: port 'pixels' is not the camera's pixel stream (ports "
                "pixels__valid of 1 bit and pixels__payload of 14 bits, "
                "In(fpga_robotics.hw.pixel.pixel_stream_signature())); its ports: motor_left, "
                "motor_right, pixels"
            ),
        ),
        (
            # A stream of another payload: bound, it was refused only by a run's backend.
            "narrow_pixel_stream",
            (
                "design Ports: port 'pixels' is not the camera's pixel stream (ports "
                "pixels__valid of 1 bit and pixels__payload of 14 bits, "
                "In(fpga_robotics.hw.pixel.pixel_stream_signature())); its ports: motor_left, "
                "motor_right, pixels__payload, pixels__valid"
            ),
        ),
        (
            # A stream with ready: the camera streamed on, the pixels not taken were lost.
            "stallable_pixel_stream",
            (
                "design Ports: port 'pixels' is not the camera's pixel stream: it has a ready "
                "output, pixels__ready, and a camera does not wait; declare it "
                "In(fpga_robotics.hw.pixel.pixel_stream_signature()), a stream always ready"
            ),
        ),
        (
            # Red (4) did not fit: a run stopped at its first frame, green ran as green.
            "narrow_color_sel",
            (
                "design Ports: port 'color_sel' (the camera's color_sel) is input of 2 bits; "
                "the colour select is 3 bits: In(3) or In(fpga_robotics.hw.pixel.TargetColor)"
            ),
        ),
        (
            "output_pixel_stream",
            (
                "design Ports: port 'pixels' is an output stream; the camera streams its frames "
                "into an input, pixels: In(fpga_robotics.hw.pixel.pixel_stream_signature())"
            ),
        ),
    ],
)
def test_part_of_a_connector_by_name_is_a_one_line_error(name, message, tmp_path, capsys):
    # Bound by name only as a whole, the connector would silently bind none of its pins:
    # a robot without wheels, a camera streaming to nothing.
    (tmp_path / "partial.py").write_text(PARTIAL)
    reference = f"{tmp_path / 'partial.py'}:{name}"
    with pytest.raises(DesignError, match=re.escape(message)):
        resolve_design(reference)
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=reference))
    for command in (
        ["designs", reference],
        ["run", "--scenario", str(tmp_path / "s.toml"), "--rerun", "off"],
    ):
        with pytest.raises(SystemExit) as info:
            cli.main(command)
        err = capsys.readouterr().err
        assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
        assert message in err


def test_a_misnamed_pixel_stream_is_told_how_the_camera_streams_to_it(tmp_path, capsys):
    # It said "bind a connector pin to it with ports = {...}", the way of a sensor's pin.
    (tmp_path / "partial.py").write_text(PARTIAL)
    reference = f"{tmp_path / 'partial.py'}:misnamed_stream"
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=reference))
    argv = ["run", "--scenario", str(tmp_path / "s.toml"), "--backend", "pysim", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
    assert (
        "nothing drives its input 'pixel__payload'; to stream the camera to it, name it "
        'pixels or declare connectors = {"camera": {"pixels": "pixel"}}'
    ) in err


def test_an_output_stream_s_ready_is_told_to_go(tmp_path, capsys):
    # Nothing takes a stream from the design: its ready input, undriven, was told to be
    # bound to a connector pin, which no connector has.
    (tmp_path / "partial.py").write_text(PARTIAL)
    reference = f"{tmp_path / 'partial.py'}:stallable_output_stream"
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=reference))
    argv = ["run", "--scenario", str(tmp_path / "s.toml"), "--backend", "pysim", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
    assert (
        "nothing drives its input 'events__ready'; it is the ready of its output stream "
        "'events', which nothing here takes (its valid and payload are recorded); declare it "
        "stream.Signature(..., always_ready=True)"
    ) in err


def test_an_output_named_as_an_input_pin_is_an_output_of_its_own(tmp_path):
    (tmp_path / "partial.py").write_text(PARTIAL)
    spec = resolve_design(f"{tmp_path / 'partial.py'}:outputs_named_as_input_pins")
    assert list(spec.bindings) == ["wheels"]
    assert spec.extra_outputs == ("echo", "valid", "pixels")


def test_the_mutant_map_reads_the_wheels_when_run_reads_them():
    # `run` reads a camera design's wheels SETTLE_EDGES edges after frame_done (and counts a
    # filtered pixel shown with it); a strobe with latency 0 ended the frame at frame_done,
    # so a registered stream's last pixel was lost and the unmutated design failed its runs.
    spec = resolve_design(f"{DESIGNS / 'red_frames.py'}:RedFrames")
    result = tomllib.loads(design_mutant_port_map(spec, design_ports(spec)))["result"]
    assert result["strobe"] == "frame_done" and result["latency"] == SETTLE_EDGES


# FollowTarget's per-frame outputs in a camera design ------------------------------------

FRAME_OUTPUTS = """
from amaranth import signed
from amaranth.lib.wiring import In, Out

from fpga_robotics.hw.pixel import pixel_stream_signature
from partial import WHEELS, Ports

CAMERA = {**WHEELS, "pixels": In(pixel_stream_signature()), "frame_done": Out(1)}


def two_bit_found():
    return Ports({**CAMERA, "found": Out(2)})


def wide_proximity():
    return Ports({**CAMERA, "proximity": Out(5)})


def wide_leds():
    return Ports({**CAMERA, "centroid_leds": Out(12)})


def signed_centroid():
    return Ports({**CAMERA, "centroid_x": Out(signed(9))})


def contract_shapes():
    shapes = {"found": Out(1), "proximity": Out(3), "centroid_x": Out(10), "centroid_leds": Out(8)}
    return Ports({**CAMERA, **shapes})


def no_camera():
    return Ports({**WHEELS, "found": Out(2)})


def two_bit_strobe():
    return Ports({**CAMERA, "frame_done": Out(2), "found": Out(1)})


def no_strobe():
    # frame_done misspelt: found and centroid_x were never read, and the run passed.
    shapes = {"frame_dne": Out(1), "found": Out(1), "centroid_x": Out(8)}
    return Ports({**WHEELS, "pixels": In(pixel_stream_signature()), **shapes})
"""


@pytest.mark.parametrize(
    "name, message",
    [
        ("two_bit_found", "port 'found' is unsigned(2); the per-frame output found is Out(1)"),
        (
            "wide_proximity",
            "port 'proximity' is unsigned(5); the per-frame output proximity is Out(3)",
        ),
        (
            "wide_leds",
            "port 'centroid_leds' is unsigned(12); the per-frame output centroid_leds is Out(8)",
        ),
        (
            "signed_centroid",
            "port 'centroid_x' is signed(9); the per-frame output centroid_x is unsigned",
        ),
        (
            "two_bit_strobe",
            "port 'frame_done' is unsigned(2); the frame strobe frame_done is Out(1)",
        ),
        (
            "no_strobe",
            (
                "it has found, centroid_x but no frame_done output: the runs read the per-frame "
                "outputs when it rises; add frame_done: Out(1)"
            ),
        ),
    ],
)
def test_frame_outputs_of_another_shape_are_one_line_errors(name, message, tmp_path, capsys):
    # The runs read them by name as the contract's numbers: a 2-bit found of 3 was "found",
    # a centroid_x of -5 a column left of the image, judged by the checks.
    (tmp_path / "partial.py").write_text(PARTIAL)
    (tmp_path / "frames.py").write_text(FRAME_OUTPUTS)
    reference = f"{tmp_path / 'frames.py'}:{name}"
    with pytest.raises(DesignError, match=re.escape(f"design Ports: {message}")):
        resolve_design(reference)
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=reference))
    for command in (
        ["designs", reference],
        ["run", "--scenario", str(tmp_path / "s.toml"), "--rerun", "off"],
    ):
        with pytest.raises(SystemExit) as info:
            cli.main(command)
        err = capsys.readouterr().err
        assert info.value.code == 2 and len(err.strip().splitlines()) == 1, err
        assert message in err


def test_frame_outputs_of_the_contract_shapes_or_without_a_camera_are_taken(tmp_path):
    (tmp_path / "partial.py").write_text(PARTIAL)
    (tmp_path / "frames.py").write_text(FRAME_OUTPUTS)
    spec = resolve_design(f"{tmp_path / 'frames.py'}:contract_shapes")
    assert spec.camera and spec.extra_outputs == ()
    # Without a camera a 2-bit found is no per-frame output: an output of its own.
    spec = resolve_design(f"{tmp_path / 'frames.py'}:no_camera")
    assert not spec.camera and spec.extra_outputs == ("found",)


WIDE_OUTPUTS = """
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Wide(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    big: Out(60)
    neg: Out(signed(64))

    def elaborate(self, platform):
        m = Module()
        tick = Signal()
        m.d.sync += tick.eq(~tick)
        m.d.comb += [self.big.eq((1 << 59) + 1), self.neg.eq(-(1 << 62) - 1)]
        return m
"""


def test_outputs_wider_than_a_float_s_53_bits_are_summarised_exactly(tmp_path):
    # The summary's last/min/max came from the float64 trajectory column, rounded.
    (tmp_path / "wide.py").write_text(WIDE_OUTPUTS)
    (tmp_path / "s.toml").write_text(STRAIGHT.format(top=f"{tmp_path / 'wide.py'}:Wide"))
    scenario = load_scenario(str(tmp_path / "s.toml"), ["sim.duration=0.2"])
    extra = run_scenario(scenario, backend="cxxrtl").summary["extra_outputs"]
    big, neg = 2**59 + 1, -(2**62) - 1
    assert extra["big"] == {"last": big, "min": big, "max": big}
    assert extra["neg"] == {"last": neg, "min": neg, "max": neg}


# Inputs no connector drives ----------------------------------------------------------------

MODEY = """\
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Modey(wiring.Component):
    pressed: In(1)
    mode: In(2)
    cam: In(2)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        hit = Signal()
        with m.If(self.pressed):
            m.d.sync += hit.eq(1)
        m.d.comb += [self.motor_left.eq(300 - 100 * self.mode), self.motor_right.eq(self.cam)]
        return m
"""


def test_designs_names_the_inputs_no_connector_drives(tmp_path, capsys):
    """designs lists an input no connector binds (a run refuses it: nothing drives it), and
    none of a design whose connectors drive every input."""
    (tmp_path / "modey.py").write_text(MODEY)
    with pytest.raises(SystemExit) as info:
        cli.main(["designs", f"{tmp_path / 'modey.py'}:Modey"])
    out = capsys.readouterr().out
    assert info.value.code == 0
    undriven = [line for line in out.splitlines() if "undriven inputs" in line]
    assert len(undriven) == 1 and undriven[0].startswith("  undriven inputs: mode, cam (no "), out
    with pytest.raises(SystemExit) as info:
        cli.main(["designs", "follow_target"])
    assert info.value.code == 0 and "undriven" not in capsys.readouterr().out
