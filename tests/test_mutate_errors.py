"""``mutate``'s failures: one line that says what is wrong, and nothing half-written."""

import json
import os

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.mutate import _one_line, _removed_on_error, main
from fpga_robotics.sim.backends.base import BackendError

ZERO = '''
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Zero(wiring.Component):
    """Wheels tied to 0 and a register nothing reads: no logic left for Yosys to mutate."""

    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        unread = Signal()
        m.d.sync += unread.eq(~unread)
        m.d.comb += [self.motor_left.eq(0), self.motor_right.eq(0)]
        return m
'''


def test_a_design_without_logic_has_nothing_to_mutate(tmp_path, capsys, monkeypatch):
    (tmp_path / "zero.py").write_text(ZERO)
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "m"
    with pytest.raises(SystemExit) as exc:
        run_cli(main, ["--design", "zero.py:Zero", "--mutants", "4", "--out", str(out)], "mutate")
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "nothing to mutate" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_tool_failure_names_its_error_line():
    exc = BackendError(
        "verilator: building the Verilator pin model (make, /usr/bin/g++) failed (exit 1):\n"
        "  make: entering\n  %Error-PINNOTFOUND: mutants.v:3: Pin not found: 'mutsel'\n"
    )
    assert _one_line(exc) == (
        "verilator: building the Verilator pin model (make, /usr/bin/g++) failed (exit 1): "
        "%Error-PINNOTFOUND: mutants.v:3: Pin not found: 'mutsel'"
    )
    assert _one_line(BackendError("one line\nmore")) == "one line"


@pytest.mark.parametrize("failure", [RuntimeError, KeyboardInterrupt])
@pytest.mark.parametrize(
    ("existed", "journal", "kept"),
    [(False, False, False), (True, False, True), (False, True, True)],
)
def test_a_failed_command_removes_only_the_folder_it_made(
    tmp_path, failure, existed, journal, kept
):
    out = tmp_path / "m"
    if existed:
        out.mkdir()
    with pytest.raises(failure), _removed_on_error(str(out), None):
        out.mkdir(exist_ok=True)
        (out / "mutants.v").write_text("module m; endmodule\n")
        if journal:  # a verdict journaled for --resume is worth keeping
            (out / "robot.jsonl").write_text("{}\n")
        raise failure("the build failed")
    assert os.path.exists(out) == kept


@pytest.mark.parametrize("failure", [BackendError, KeyboardInterrupt])
def test_a_failed_command_removes_the_parent_folders_it_made_too(tmp_path, failure):
    # The default --out is runs/mutation/n<N>-s<S>: in a fresh folder runs/ and
    # runs/mutation/ are made for it, and go with it; a folder that was there stays.
    (tmp_path / "kept").mkdir()
    for made, out in (("runs", "runs/mutation/n1-s1"), ("kept/a", "kept/a/b")):
        with pytest.raises(failure), _removed_on_error(str(tmp_path / out), None):
            os.makedirs(tmp_path / out)
            raise failure("the build failed")
        assert not (tmp_path / made).exists()
    assert sorted(os.listdir(tmp_path)) == ["kept"] and not os.listdir(tmp_path / "kept")


def test_an_interrupted_robot_judge_says_what_it_kept(tmp_path, capsys):
    out = tmp_path / "m"
    rows = [{"index": 2, "caught": True}, {"index": 5, "caught": False}]
    with pytest.raises(KeyboardInterrupt), _removed_on_error(str(out), "mutation"):
        out.mkdir()
        text = "".join(json.dumps(row) + "\n" for row in rows)
        (out / "robot.jsonl").write_text(text + '{"index": 7, "cau')  # the third one torn
        raise KeyboardInterrupt
    err = capsys.readouterr().err
    assert err == (
        f"interrupted: 2 robot judge verdict(s) kept in {out / 'robot.jsonl'}; "
        "continue with --resume\n"
    )


@pytest.mark.parametrize(
    ("more", "message"),
    [
        (
            ["--scheduler", "tcp://127.0.0.1:8786", "--workers", "3"],
            "--workers sizes the embedded cluster; with --scheduler the cluster has the workers",
        ),
        (["--scheduler", "foo"], "--scheduler must be a Dask scheduler address tcp://HOST:PORT"),
    ],
)
def test_scheduler_options_are_refused_before_anything_runs(tmp_path, capsys, more, message):
    # Not a slow test: a mutant build here would fail it (tests/fast_tier/slow_builds.py).
    out = tmp_path / "m"
    argv = ["--mutants", "4", "--campaign", "mutation", "--out", str(out), *more]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, argv, "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_an_unreachable_scheduler_is_refused_before_the_build(tmp_path, capsys, monkeypatch):
    from fpga_robotics.cli import mutate
    from fpga_robotics.hw.errors import UsageError

    dialled = []

    def unreachable(scheduler=None, workers=None):
        dialled.append(scheduler)
        raise UsageError(f"cannot reach the Dask scheduler at {scheduler!r}")

    monkeypatch.setattr(mutate, "open_client", unreachable)
    out = tmp_path / "m"
    argv = ["--mutants", "4", "--campaign", "mutation", "--out", str(out)]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--scheduler", "tcp://127.0.0.1:1"], "mutate")
    assert exc.value.code == 2 and dialled == ["tcp://127.0.0.1:1"]
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize(
    "asks",
    [
        'resolution = "80x60"',
        "set = ['camera.resolution=\"80x60\"']",
        '[grid]\n"camera.resolution" = ["160x120", "80x60"]',
    ],
)
def test_a_campaign_resolution_other_than_the_netlist_s_is_refused(tmp_path, capsys, asks):
    # FollowTarget's netlist is built for --width x --height (160x120): its runs all take it.
    campaign = tmp_path / "c.toml"
    campaign.write_text(f'scenarios = ["follow_person"]\nseeds = "0"\n{asks}\n')
    out = tmp_path / "m"
    with pytest.raises(SystemExit) as exc:
        run_cli(main, ["--mutants", "4", "--campaign", str(campaign), "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "the mutation campaign asks for resolution 80x60 (follow_person)" in err
    assert "the mutant netlist is built for 160x120" in err and "--width, --height" in err
    assert not out.exists()


def test_a_campaign_resolution_is_the_one_its_runs_take(tmp_path):
    from fpga_robotics.mutation.robot_judge import check_campaign, mutant_argv
    from fpga_robotics.sweep import load_campaign_file

    campaign = tmp_path / "c.toml"
    campaign.write_text('scenarios = ["follow_person"]\nseeds = "0"\nresolution = "80x60"\n')
    plan = check_campaign(load_campaign_file(str(campaign)), "80x60")  # the netlist's: kept
    (argv,) = [spec.argv() for spec in plan.runs]
    # FollowTarget's netlist sets the resolution; a design of one's own runs at the campaign's.
    ft = mutant_argv(argv, "mutants.v", "ports.toml", 1, "160x120")
    own = mutant_argv(argv, "mutants.v", "ports.toml", 1, None)
    assert ft[ft.index("--resolution") :][:2] == ["--resolution", "160x120"]
    assert ft.count("--resolution") == 1
    assert own[own.index("--resolution") :][:2] == ["--resolution", "80x60"]
    assert own.count("--resolution") == 1


@pytest.mark.parametrize(
    "asks", ["set = [\"camera.resolution = '80x60'\"]", '[grid]\n"camera.resolution" = ["80x60"]']
)
def test_a_campaign_that_sets_the_netlist_s_resolution_runs_at_it(tmp_path, asks):
    # run refuses --resolution beside a --set camera.resolution: the runs take the set alone.
    from fpga_robotics.mutation.robot_judge import check_campaign, mutant_argv
    from fpga_robotics.sweep import load_campaign_file, runner

    campaign = tmp_path / "c.toml"
    campaign.write_text(f'scenarios = ["follow_person"]\nseeds = "0"\n{asks}\n')
    plan = check_campaign(load_campaign_file(str(campaign)), "80x60")
    (argv,) = [spec.argv() for spec in plan.runs]
    _, scenario, _ = runner.load_run(mutant_argv(argv, "mutants.v", "ports.toml", 1, "80x60"))
    assert (scenario.camera.width, scenario.camera.height) == (80, 60)


def test_an_interrupted_rerun_leaves_no_earlier_results_beside_its_netlist(tmp_path, monkeypatch):
    # An earlier run's mutants.json, report and recordings describe its own mutants: beside
    # the new netlist their replay commands would run other mutants.
    from fpga_robotics.mutation import design_run

    designs = os.path.join(os.path.dirname(__file__), "data", "user_designs")
    out = tmp_path / "m"
    (out / "recordings").mkdir(parents=True)
    earlier = ["mutants.json", "report.html", "robot.jsonl", "recordings/mutant1.rrd"]
    for name in [*earlier, "mutants.v"]:
        (out / name).write_text("the earlier run's\n")

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(design_run, "_prebuild", interrupted)  # right after the netlist
    argv = ["--design", f"verilog:{designs}/bump_stop_noreset.v"]
    argv += ["--ports", f"{designs}/bump_stop_noreset_ports.toml", "--mutants", "3"]
    with pytest.raises((SystemExit, KeyboardInterrupt)):
        run_cli(main, [*argv, "--out", str(out), "--quiet"], "mutate")
    assert (out / "mutants.v").read_text() != "the earlier run's\n"
    assert [name for name in earlier if (out / name).exists()] == []


def test_a_mutant_s_failed_run_says_what_failed_not_the_exception_or_netlist_name():
    # The run's own error, as `run` would print it for the mutant netlist; the verdict drops
    # the exception's class (nothing was a usage error) and follow_target (not the
    # user's design's name: the generated netlist's top).
    from fpga_robotics.hw.errors import UsageError
    from fpga_robotics.mutation.robot_judge import judge_runs
    from fpga_robotics.sweep.runner import RunOutcome

    timeout = "frame 0: timeout: the result strobe 'frame_done' never rose within 9 cycles"

    def execute(i, argv, limit):
        with RunOutcome() as run:
            raise UsageError(f"--design: follow_target: {timeout}")
        return run.out

    verdict = judge_runs([["run"]], execute=execute)
    assert verdict["caught"] and verdict["status"] == "error"
    assert verdict["message"] == timeout


DATA = os.path.join(os.path.dirname(__file__), "data")


def test_a_campaign_that_cannot_drive_the_design_is_refused_before_the_build(tmp_path, capsys):
    # bump_stop.v declares a bumper on bump_i; follow_person has no bumper table, so run
    # refuses it with exit 2: mutate says the same before building any mutant.
    campaign = tmp_path / "c.toml"
    campaign.write_text('scenarios = ["follow_person"]\nseeds = "0"\n')
    out = tmp_path / "m"
    argv = ["--design", f"verilog:{DATA}/bump_stop.v", "--ports", f"{DATA}/bump_stop_ports.toml"]
    argv += ["--mutants", "4", "--campaign", str(campaign), "--out", str(out)]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, argv, "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "the campaign's run of follow_person" in err
    assert "nothing drives its input 'bump_i'" in err and 'kind = "bumper"' in err
    assert not out.exists()


def test_a_campaign_of_another_design_is_refused_before_follow_target_s_build(
    tmp_path, capsys, monkeypatch
):
    # line_track runs FollowLine on line sensors FollowTarget has no pins for: refused with
    # run's message before the mutants are listed (it was, after the build and unit judge).
    from fpga_robotics.cli import mutate

    def listed(*args, **kwargs):
        raise AssertionError("the mutants were listed before the campaign was checked")

    monkeypatch.setattr(mutate, "list_mutants", listed)
    campaign = tmp_path / "c.toml"
    campaign.write_text('scenarios = ["approach", "line_track"]\nseeds = "0"\n')
    out = tmp_path / "m"
    with pytest.raises(SystemExit) as exc:
        run_cli(main, ["--mutants", "2", "--campaign", str(campaign), "--out", str(out)], "m")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1, err
    assert "the campaign's run of line_track: the line_sensors connector 'line'" in err
    assert "design 'follow_target' has no port for its pin 'line'" in err
    assert not out.exists()


def test_a_usage_error_of_an_unmutated_run_refuses_the_campaign():
    from fpga_robotics.hw.errors import UsageError
    from fpga_robotics.mutation.robot_judge import _refuse_usage_errors
    from fpga_robotics.sweep.runner import RunOutcome

    outcomes = []
    for exc in (None, RuntimeError("the design stopped"), UsageError("no port 'x'")):
        with RunOutcome() as outcome:
            if exc is not None:
                raise exc
            outcome.out["status"] = "pass"
        outcomes.append(outcome.out)
    assert [o.get("usage_error", False) for o in outcomes] == [False, False, True]
    argvs = [["--scenario", name] for name in ("a", "b", "c")]
    # A run that fails on its own (b) is left to the judge; a usage error (c) is the user's.
    _refuse_usage_errors(argvs[:2], outcomes[:2])
    with pytest.raises(UsageError, match=r"^the campaign's run of c: no port 'x'$"):
        _refuse_usage_errors(argvs, outcomes)


@pytest.mark.parametrize(
    "options",
    [
        ["--lost-frames", "5", "--search-dps", "120", "--kp-num", "2"],
        ["--preset", "published", "--diff-min", "5"],
        [],
    ],
)
def test_the_robot_judge_s_runs_take_the_mutated_design_s_values(tmp_path, options):
    # The runs' behaviour envelopes read their scenario's design values: they must be the
    # values the netlist is built with (they were the defaults, whatever mutate was given).
    from fpga_robotics.cli.mutate import build_parser
    from fpga_robotics.cli.param_options import params_from_args
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.mutation.robot_judge import (
        check_campaign,
        check_design_values,
        design_sets,
        mutant_argv,
    )
    from fpga_robotics.sweep import load_campaign_file, runner

    params = params_from_args(
        build_parser("m").parse_args([*options, "--width", "80", "--height", "60"])
    )
    campaign = tmp_path / "c.toml"
    campaign.write_text('scenarios = ["lost_target", "follow_person"]\nseeds = [0, 3]\n')
    plan = check_campaign(load_campaign_file(str(campaign)), "80x60")
    check_design_values(plan, params)  # no scenario of its own values: taken
    for spec in plan.runs:
        argv = mutant_argv(spec.argv(), "m.v", "p.toml", 1, "80x60", design_sets(params))
        _, scenario, _ = runner.load_run(argv)
        assert scenario.params == params
    expected = FollowTargetParams.preset("published", width=80, height=60, diff_min=5)
    assert ("published" not in options) or params == expected


def test_a_scenario_with_design_values_of_its_own_is_refused_before_the_build(
    tmp_path, capsys, monkeypatch
):
    from fpga_robotics.cli import mutate

    def listed(*args, **kwargs):
        raise AssertionError("the mutants were listed before the campaign was checked")

    monkeypatch.setattr(mutate, "list_mutants", listed)
    (tmp_path / "own.toml").write_text(
        'name = "own"\n[sim]\nduration = 2.0\n[design]\nlost_frames = 4\n'
    )
    campaign = tmp_path / "c.toml"
    campaign.write_text('scenarios = ["own.toml"]\n')
    out = tmp_path / "m"
    argv = ["--mutants", "4", "--lost-frames", "6", "--campaign", str(campaign)]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "the campaign's run of " in err and "own.toml: its scenario's design values" in err
    assert "(lost_frames = 4) are not the mutated design's (lost_frames = 6)" in err
    assert not out.exists()


def test_a_scenario_that_builds_another_design_of_one_s_own_is_refused_before_the_build(
    tmp_path, capsys, monkeypatch
):
    # near_red.toml builds NearRed with speed = 400, near_pixels = 300; the mutant netlist
    # takes no parameters, so its runs would drive NearRed's defaults (200, 60) in it.
    from fpga_robotics.cli import mutate
    from fpga_robotics.designs.reference import resolve_design
    from fpga_robotics.mutation.robot_judge import check_campaign, check_design_params
    from fpga_robotics.sweep import load_campaign_file

    def built(*args, **kwargs):
        raise AssertionError("the mutants were built before the campaign was checked")

    monkeypatch.setattr(mutate, "mutate_design", built)
    designs = os.path.join(DATA, "user_designs")
    campaign = tmp_path / "c.toml"
    campaign.write_text(f'scenarios = ["{designs}/near_red.toml"]\n')
    out = tmp_path / "m"
    argv = ["--design", f"{designs}/near_red.py:NearRed", "--campaign", str(campaign)]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--mutants", "4", "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "near_red.toml: its [design.params] (speed = 400, near_pixels = 300)" in err
    assert "another NearRed than the one mutated (no --param;" in err
    assert not out.exists()
    # The same values as --param are the same design; so are a design's defaults spelled
    # out (wall_stop.toml gives WallStop's speed = 300, stop_mm = 250).
    for toml, ref, params in [
        ("near_red.toml", "near_red.py:NearRed", {"speed": 400, "near_pixels": 300}),
        ("wall_stop.toml", "wall_stop.py:WallStop", {}),
    ]:
        campaign.write_text(f'scenarios = ["{designs}/{toml}"]\n')
        design = f"{designs}/{ref}"
        plan = check_campaign(load_campaign_file(str(campaign)))
        check_design_params(plan, ["--design", design], resolve_design(design, params))


def test_a_failed_build_of_follow_target_s_netlist_is_one_line(tmp_path, capsys, monkeypatch):
    # As --design says it (and run): the tool's first error line, exit 2, no traceback.
    from fpga_robotics.cli import mutate

    def build(*args, **kwargs):
        raise BackendError(
            "building the Verilator model of follow_target failed (exit 2):\n"
            "make: Entering directory 'obj'\ng++: error: Vfollow_target__pch.h.fast: not found\n"
        )

    monkeypatch.setattr(mutate, "list_mutants", lambda *args: [])  # no Yosys: the build fails
    monkeypatch.setattr(mutate, "write_mutant_design", lambda *args: ("m.v", "p.toml"))
    monkeypatch.setattr(mutate, "open_mutant_design", build)
    out = tmp_path / "m"
    with pytest.raises(SystemExit) as exc:
        run_cli(main, ["--mutants", "2", "--width", "80", "--height", "60", "--out", str(out)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "failed (exit 2): g++: error: Vfollow_target__pch.h.fast" in err


COUNTER = """
from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Counter(wiring.Component):
    count: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.count.eq(self.count + 1)
        return m
"""


@pytest.mark.parametrize(
    ("design", "message"),
    [
        # Its inputs up and clear bound to no connector: nothing in a run drives them.
        ("counters.py:Saturating", "no connector pin drives Saturating's input 'up'"),
        # No input, outputs no run acts on or checks: every mutant would be a blind spot.
        ("counter.py:Counter", "no run can catch a mutant of Counter: it binds no wheels"),
    ],
)
def test_a_design_no_campaign_run_can_judge_is_refused_before_the_build(
    tmp_path, capsys, monkeypatch, design, message
):
    def listed(*args, **kwargs):
        raise AssertionError("the mutants were listed before the design was checked")

    monkeypatch.setattr("fpga_robotics.mutation.design_run.list_mutants", listed)
    (tmp_path / "counter.py").write_text(COUNTER)
    folder = tmp_path if design.startswith("counter.py") else f"{DATA}/user_designs"
    out = tmp_path / "m"
    argv = ["--design", f"{folder}/{design}", "--mutants", "2"]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--campaign", "mutation", "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert message in err and "leave out --campaign" in err
    assert not out.exists()


class _HungDesign:
    """A mutant netlist whose unmutated design never raises ``frame_done``."""

    def set_runtime(self, name, value):
        pass

    def reset(self):
        pass

    def process_frame(self, frame, color):
        raise BackendError("follow_target: frame 0: timeout: frame_done never rose")

    def close(self):
        pass


def test_against_design_with_a_broken_unmutated_design_is_one_line(tmp_path, capsys, monkeypatch):
    at = "fpga_robotics.cli.mutate."
    monkeypatch.setattr(at + "list_mutants", lambda *a, **k: [])
    monkeypatch.setattr(at + "write_mutant_design", lambda p, m, out: ("mutants.v", "ports.toml"))
    monkeypatch.setattr(at + "open_mutant_design", lambda *a, **k: _HungDesign())
    out = tmp_path / "m"
    with pytest.raises(SystemExit) as exc:
        run_cli(main, ["--mutants", "2", "--against", "design", "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "--against design: the unmutated design fails" in err and "frame_done never" in err
    assert not out.exists()


NAMED = '''
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class Named(wiring.Component):
    """A port named as the mutant netlist's select or watch."""

    {name}: {direction}(4)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.motor_left.eq(self.{name} + 1)
        m.d.comb += self.motor_right.eq(self.motor_left)
        return m
'''


@pytest.mark.parametrize(("name", "direction"), [("mutsel", "In"), ("mutinf", "Out")])
def test_a_design_with_a_port_named_as_the_mutant_select_is_one_clear_line(
    tmp_path, capsys, name, direction
):
    # Yosys failed on them: an assertion in mutate.cc, a redefinition of wire \mutinf.
    (tmp_path / "named.py").write_text(NAMED.format(name=name, direction=direction))
    out = tmp_path / "m"
    argv = ["--design", f"{tmp_path}/named.py:Named", "--mutants", "2", "--out", str(out)]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, argv, "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert f"the design has a signal named {name!r}, a name the mutant netlist adds" in err
    assert "rename it" in err and not out.exists()


def test_a_verilog_design_no_campaign_run_can_judge_is_refused_before_the_build(
    tmp_path, capsys, monkeypatch
):
    def listed(*args, **kwargs):
        raise AssertionError("the mutants were listed before the design was checked")

    monkeypatch.setattr("fpga_robotics.mutation.design_run.list_mutants", listed)
    (tmp_path / "cnt.v").write_text(
        "module cnt(input clk, input rst, output reg [7:0] count);\n"
        "  always @(posedge clk) if (rst) count <= 0; else count <= count + 1;\n"
        "endmodule\n"
    )
    (tmp_path / "cnt.toml").write_text(
        'top = "cnt"\nclock = { port = "clk" }\nreset = { port = "rst" }\n'
        '[extra_outputs]\ncount = "count"\n'
    )
    out = tmp_path / "m"
    argv = ["--design", f"verilog:{tmp_path}/cnt.v", "--ports", str(tmp_path / "cnt.toml")]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--campaign", "mutation", "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1
    assert "no run can catch a mutant of cnt: it binds no wheels, servo or camera" in err
    assert not out.exists()


def test_verilog_yosys_cannot_read_is_one_line_naming_the_users_file(tmp_path, capsys):
    # `inside` (SystemVerilog Verilator takes, Yosys does not): the line names the file as
    # the user has it, not as mutate copied it (fr_design/...), and says what runs it.
    (tmp_path / "sv.v").write_text(
        "module sv (input clk, input rst, input bump_i, input [2:0] line,\n"
        "           output reg signed [11:0] left_dps, output signed [11:0] right_dps);\n"
        "  always @(posedge clk)\n"
        "    if (rst || bump_i) left_dps <= 12'sd0;\n"
        "    else if (line inside {3'b001, 3'b100}) left_dps <= 12'sd100;\n"
        "  assign right_dps = left_dps;\n"
        "endmodule\n"
    )
    (tmp_path / "sv.toml").write_text(
        'top = "sv"\nclock = { port = "clk" }\nreset = { port = "rst" }\n[outputs]\n'
        'motor_left = { port = "left_dps", width = 12, signed = true }\n'
        'motor_right = { port = "right_dps", width = 12, signed = true }\n'
        '[connectors.bumper]\npressed = "bump_i"\n[connectors.line_sensors]\nline = "line"\n'
    )
    out = tmp_path / "m"
    argv = ["--design", f"verilog:{tmp_path}/sv.v", "--ports", str(tmp_path / "sv.toml")]
    with pytest.raises(SystemExit) as exc:
        run_cli(main, [*argv, "--mutants", "3", "--out", str(out)], "mutate")
    err = capsys.readouterr().err
    assert exc.value.code == 2 and err.count("\n") == 1, err
    assert "Yosys cannot read the design to mutate it: sv.v:5: ERROR: syntax error" in err
    assert "fr_design" not in err and not out.exists()
