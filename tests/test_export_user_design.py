"""``fpga-robotics export --design REF``: a design of one's own as Verilog, each port in the
direction its signature declares (the independent expectation: Amaranth's own
``verilog.convert`` of the component, and the signature itself); a port named after the
clock and the built-in tops' options are one line, exit 2, nothing written."""

import re
import shutil
from pathlib import Path

import pytest
from amaranth.back import verilog

from fpga_robotics import cli
from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.sim.mutation import component_rtlil

DESIGNS = Path(__file__).parent / "data" / "user_designs"
PORT_CASES = DESIGNS / "port_cases.py"


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def _verilog_directions(text):
    """``{port: "input"|"output"}`` of the top module's port declarations."""
    return {
        name: direction
        for direction, name in re.findall(
            r"^\s*(input|output)\s+(?:\[[^\]]*\]\s*)?(\S+)\s*;", text, re.MULTILINE
        )
    }


def test_undriven_outputs_stay_outputs_driven_to_zero(tmp_path, capsys):
    out = tmp_path / "nothing.v"
    code, text, err = _cli(["export", "--design", f"{PORT_CASES}:Nothing", "-o", str(out)], capsys)
    assert code == 0, err
    assert text == f"wrote {out} (module Nothing, 3 ports)\n"
    exported = out.read_text()
    directions = _verilog_directions(exported)
    # As declared: go In, the wheels Out (never driven), plus the clock domain's own ports.
    assert directions == {
        "clk": "input",
        "rst": "input",
        "go": "input",
        "motor_left": "output",
        "motor_right": "output",
    }
    assert "assign motor_left = 16'h0000;" in exported
    assert "assign motor_right = 16'h0000;" in exported
    # Amaranth's own conversion of the component gives the same directions.
    component = resolve_design(f"{PORT_CASES}:Nothing").build()
    assert _verilog_directions(verilog.convert(component, name="Nothing")) == directions


def test_the_mutation_netlist_keeps_the_declared_directions():
    rtlil = component_rtlil(resolve_design(f"{PORT_CASES}:Nothing").build())
    wires = {
        name: direction
        for direction, name in re.findall(
            r"^\s*wire width \d+ (input|output) \d+ +(?:signed )?\\(\S+)$", rtlil, re.MULTILINE
        )
    }
    assert wires["motor_left"] == wires["motor_right"] == "output"
    assert wires["go"] == "input"


def test_a_port_named_clk_is_one_line(tmp_path, capsys):
    out = tmp_path / "clk.v"
    code, text, err = _cli(["export", "--design", f"{PORT_CASES}:ClkPort", "-o", str(out)], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1
    assert err == (
        "fpga-robotics export: error: design 'ClkPort' has a port named 'clk', the name of "
        "the clock domain's own clock; rename the port\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    "options, message",
    [
        (["--width", "80"], "--width: FollowTarget's options; --design REF exports a design"),
        (["--kp-num", "7", "--preset", "published"], "--preset, --kp-num: FollowTarget's options"),
        (["--us-clock-hz", "5"], "--us-clock-hz applies to --top follow_target_safe, not to"),
        (["--variant", "stuck_left"], "--variant names a seeded bug of a built-in top"),
        (["--seed", "0"], "--top, --board, --bitstream and --seed go without it"),
    ],
)
def test_options_of_the_built_in_tops_are_refused(options, message, tmp_path, capsys):
    out = tmp_path / "x.v"
    argv = ["export", "--design", f"{DESIGNS}/wall_stop.py:WallStop", *options, "-o", str(out)]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == "" and err.count("\n") == 1, err
    assert message in err
    assert not out.exists()


def test_mutate_refuses_them_with_the_same_words(capsys):
    argv = ["mutate", "--design", f"{DESIGNS}/wall_stop.py:WallStop", "--width", "80"]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == ""
    assert err == (
        "fpga-robotics mutate: error: --width: FollowTarget's options; with --design REF the "
        "mutants are judged against the unmutated design (give its parameters as --param "
        "NAME=VALUE)\n"
    )


def test_a_verilog_design_is_said_to_be_verilog_already(tmp_path, capsys):
    # Not asked for a port map first: export has no --ports.
    out = tmp_path / "x.v"
    argv = ["export", "--design", f"verilog:{DESIGNS}/WallStop.v", "-o", str(out)]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == ""
    assert err == (
        f"fpga-robotics export: error: --design verilog:{DESIGNS}/WallStop.v is Verilog "
        "already: nothing to export\n"
    )
    assert not out.exists()


def test_the_output_may_not_be_the_design_s_own_file(tmp_path, capsys, monkeypatch):
    source = tmp_path / "wall_stop.py"
    shutil.copy(DESIGNS / "wall_stop.py", source)
    monkeypatch.chdir(tmp_path)
    code, text, err = _cli(
        ["export", "--design", "./wall_stop.py:WallStop", "-o", str(source)], capsys
    )
    assert code == 2 and text == "" and err.count("\n") == 1
    assert f"-o {str(source)!r} is the same path as the input --design {str(source)!r}" in err
    assert source.read_bytes() == (DESIGNS / "wall_stop.py").read_bytes()


def test_the_output_may_not_be_a_module_the_design_imports(tmp_path, capsys, monkeypatch):
    # The design's folder is first on its path: a helper module beside it is its source too.
    (tmp_path / "speeds.py").write_text("SPEED = 200\n")
    (tmp_path / "design.py").write_text(
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import Out\n"
        "from speeds import SPEED\n\n\n"
        "class D(wiring.Component):\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += [self.motor_left.eq(SPEED), self.motor_right.eq(SPEED)]\n"
        "        return m\n"
    )
    monkeypatch.chdir(tmp_path)
    code, text, err = _cli(["export", "--design", "design.py:D", "-o", "speeds.py"], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1
    helper = str(tmp_path / "speeds.py")
    assert f"-o 'speeds.py' is the same path as the input --design's module {helper!r}" in err
    assert (tmp_path / "speeds.py").read_text() == "SPEED = 200\n"


@pytest.mark.parametrize("target", ["top.py", "parts.py", "__init__.py"])
def test_the_output_may_not_be_a_file_of_the_design_s_package(
    target, tmp_path, capsys, monkeypatch
):
    # A package.module:Name design's source is its package: its module, the modules it
    # imports from it (relatively) and its __init__.py.
    package = tmp_path / f"ud_export_pkg_{target.partition('.')[0].strip('_')}"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "parts.py").write_text("SPEED = 200\n")
    (package / "top.py").write_text(
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import Out\n"
        "from .parts import SPEED\n\n\n"
        "class D(wiring.Component):\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += [self.motor_left.eq(SPEED), self.motor_right.eq(SPEED)]\n"
        "        return m\n"
    )
    before = {f: f.read_bytes() for f in package.iterdir() if f.is_file()}
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    output = f"{package.name}/{target}"
    code, text, err = _cli(["export", "--design", f"{package.name}.top:D", "-o", output], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1
    assert f"-o {output!r} is the same path as the input --design" in err
    assert str(package / target) in err
    assert {f: f.read_bytes() for f in package.iterdir() if f.is_file()} == before


def test_the_output_may_not_be_a_module_beside_a_flat_module_design(tmp_path, capsys, monkeypatch):
    # module:Name of a module of no package (found in the current folder): the modules it
    # imports beside it are its source; a file in a folder below is not.
    (tmp_path / "ud_flat_speeds.py").write_text("SPEED = 200\n")
    (tmp_path / "ud_flat_design.py").write_text(
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import Out\n"
        "from ud_flat_speeds import SPEED\n\n\n"
        "class D(wiring.Component):\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += [self.motor_left.eq(SPEED), self.motor_right.eq(SPEED)]\n"
        "        return m\n"
    )
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    argv = ["export", "--design", "ud_flat_design:D", "-o", "ud_flat_speeds.py"]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == "" and err.count("\n") == 1
    assert f"the input --design's module {str(tmp_path / 'ud_flat_speeds.py')!r}" in err
    assert (tmp_path / "ud_flat_speeds.py").read_text() == "SPEED = 200\n"
    code, _, _ = _cli(["export", "--design", "ud_flat_design:D", "-o", "out/D.v"], capsys)
    assert code == 0 and (tmp_path / "out" / "D.v").is_file()


@pytest.mark.parametrize(
    "options",
    [
        ["--stop-mm", "250", "--resume-mm", "300"],
        ["--diff-min", "5", "--variant", "us_echo_inverted"],
    ],
)
def test_a_built_in_name_takes_its_own_options_as_top_does(options, tmp_path, capsys):
    by_design, by_top, plain = tmp_path / "d.v", tmp_path / "t.v", tmp_path / "p.v"
    for argv in (
        ["--design", "follow_target_safe", *options, "-o", str(by_design)],
        ["--top", "follow_target_safe", *options, "-o", str(by_top)],
        ["--top", "follow_target_safe", "-o", str(plain)],
    ):
        code, _, err = _cli(["export", *argv], capsys)
        assert code == 0, err
    assert by_design.read_text() == by_top.read_text() != plain.read_text()


@pytest.mark.parametrize(
    "design, params, message",
    [
        ("follow_target", ["diff_min=5"], "takes its own options instead: --diff-min 5"),
        (
            "follow_target_safe",
            ["stop_mm=200", "kp_num=2"],
            "takes its own options instead: --stop-mm 200 --kp-num 2",
        ),
        ("follow_line", ["stop_mm=200"], "follow_line has no option for stop_mm"),
    ],
)
def test_param_with_a_built_in_name_names_the_options(design, params, message, tmp_path, capsys):
    out = tmp_path / "x.v"
    argv = ["export", "--design", design, "-o", str(out)]
    argv += [item for param in params for item in ("--param", param)]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == "" and err.count("\n") == 1
    assert "--param sets a parameter of a design of your own" in err and message in err
    assert not out.exists()
