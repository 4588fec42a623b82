"""A foreign Verilog design as a scenario's ``[design]`` entry: ``verilog = [...]`` and
``ports = "..."`` (paths from the scenario file's folder), checked at load with one-line
errors; ``--design`` and ``--ports`` override them (docs/foreign.md)."""

import argparse
import json
from pathlib import Path

import pytest

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.run import _design_files, _with_design_files
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.scenario.load import ForeignDesignFiles, ScenarioError, load_scenario
from fpga_robotics.sim.backends.port_map import follow_target_port_map

PARAMS = FollowTargetParams(width=80, height=60)

SCENARIO = """\
[camera]
resolution = "80x60"

[design]
verilog = ["rtl/follow_target.v"]
ports = "rtl/ft.toml"
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from fpga_robotics.hw.verilog import generate_verilog

    d = tmp_path_factory.mktemp("scenario_foreign")
    (d / "rtl").mkdir()
    (d / "rtl" / "follow_target.v").write_text(generate_verilog(PARAMS))
    (d / "rtl" / "ft.toml").write_text(follow_target_port_map(PARAMS))
    (d / "foreign.toml").write_text(SCENARIO)
    (d / "plain.toml").write_text(SCENARIO.split("[design]")[0])
    return d


def test_paths_are_relative_to_the_scenario_file(files, monkeypatch):
    monkeypatch.chdir(files / "rtl")  # not where the paths start from
    s = load_scenario(str(files / "foreign.toml"))
    assert s.foreign.verilog == (str(files / "rtl" / "follow_target.v"),)
    assert s.foreign.ports == str(files / "rtl" / "ft.toml")
    assert s.params == PARAMS  # the design keys are not FollowTarget's parameters
    assert load_scenario(str(files / "plain.toml")).foreign is None
    assert load_scenario("follow_person").foreign is None
    # A single file may be a string; an override keeps the design.
    s = load_scenario(str(files / "foreign.toml"), ["design.verilog=rtl/follow_target.v"])
    assert s.foreign.verilog == (str(files / "rtl" / "follow_target.v"),)
    assert s.with_overrides(["design.kp_num=5"]).foreign == s.foreign


@pytest.mark.parametrize(
    "text, message",
    [
        (
            '[design]\nverilog = ["rtl/missing.v"]\nports = "rtl/ft.toml"\n',
            "design.verilog: no file 'rtl/missing.v' (looked for ",
        ),
        (
            '[design]\nverilog = ["rtl/follow_target.v"]\nports = "nope.toml"\n',
            "design.ports: no file 'nope.toml'",
        ),
        ('[design]\nverilog = ["rtl/follow_target.v"]\n', "design.verilog needs design.ports"),
        ('[design]\nports = "rtl/ft.toml"\n', "design.ports goes with design.verilog"),
        (
            '[design]\nverilog = []\nports = "rtl/ft.toml"\n',
            "design.verilog must be an array of Verilog file paths, got []",
        ),
        (
            '[design]\nverilog = [3]\nports = "rtl/ft.toml"\n',
            "design.verilog must be an array of Verilog file paths",
        ),
        (
            '[design]\nverilog = ["rtl/follow_target.v"]\nports = 7\n',
            "design.ports must be the path of a port map (.toml), got 7",
        ),
        ('[design]\nverilogg = ["a.v"]\n', "unknown key design.verilogg"),
        (
            (
                '[design]\nverilog = ["rtl/follow_target.v"]\nports = "rtl/ft.toml"\n'
                "[design.params]\ngain = [4]\n"
            ),
            "design.params.gain: give a number, a boolean, a literal such as 8'hff or a text",
        ),
        (  # two designs: the Verilog one ran, or the Amaranth one, without a word
            (
                '[design]\ntop = "follow_target"\nverilog = ["rtl/follow_target.v"]\n'
                'ports = "rtl/ft.toml"\n'
            ),
            "design.top = 'follow_target' and design.verilog name two designs: give one",
        ),
        (
            '[design]\ntop = "follow_target"\n[design.defines]\nFAST = true\n',
            "design.defines sets `define macros of a Verilog design (design.verilog)",
        ),
    ],
)
def test_bad_entries_are_one_line_errors_at_load(files, text, message):
    path = files / "bad.toml"
    path.write_text(text)
    with pytest.raises(
        ScenarioError,
        match=message.replace("(", r"\(")
        .replace(")", r"\)")
        .replace("[", r"\[")
        .replace("]", r"\]"),
    ) as info:
        load_scenario(str(path))
    assert "\n" not in str(info.value)


def _args(**kw):
    base = {"design": None, "ports": None, "backend": "auto"}
    return argparse.Namespace(**{**base, **kw})


def test_the_command_line_overrides_the_scenario(files):
    foreign = load_scenario(str(files / "foreign.toml")).foreign
    v, p = list(foreign.verilog), foreign.ports
    assert _design_files(_args(), foreign) == (v, p)
    assert _design_files(_args(design="verilog:x.v,y.v"), foreign) == (["x.v", "y.v"], p)
    assert _design_files(_args(ports="other.toml"), foreign) == (v, "other.toml")
    assert _design_files(_args(design="verilog:x.v", ports="o.toml"), foreign) == (
        ["x.v"],
        "o.toml",
    )
    assert _design_files(_args(), None) is None
    with pytest.raises(
        UsageError,
        match="the scenario's design.verilog runs on the cxxrtl or verilator backend, not 'model'",
    ):
        _design_files(_args(backend="model"), foreign)
    with pytest.raises(UsageError, match="--ports goes with --design"):
        _design_files(_args(ports="o.toml"), None)


#: A user's line follower in Verilog (its port map binds the line sensors).
LINE_FOLLOW = Path(__file__).parent / "data" / "line_follow_verilog"


def test_a_verilog_design_top_replaces_a_built_in_design_and_its_tables(tmp_path):
    # line_track runs follow_line with a [design.line] table; design.top = "verilog:..."
    # with design.ports replaces that design as run --design/--ports does.
    files = [str(LINE_FOLLOW / "lf_top.v"), str(LINE_FOLLOW / "lf_core.v")]
    ports = str(LINE_FOLLOW / "lf_ports.toml")
    top = f"verilog:{','.join(files)}"
    by_set = load_scenario("line_track", [f'design.top="{top}"', f'design.ports="{ports}"'])
    assert by_set.foreign == ForeignDesignFiles(tuple(files), ports)
    assert by_set.design_tables == {}
    by_option = _with_design_files(
        _args(design=top, ports=ports, backend="cxxrtl"), load_scenario("line_track")
    )
    assert by_set.foreign == by_option.foreign
    assert by_set.sim == by_option.sim and by_set.sim.timing == "real_clock"
    # The same in a scenario file that keeps the table.
    text = Path(by_set.source).read_text()
    assert "[design.line]" in text
    path = tmp_path / "my_line.toml"
    path.write_text(text.replace('top = "follow_line"', f'top = "{top}"\nports = "{ports}"'))
    in_file = load_scenario(str(path))
    assert in_file.foreign == by_set.foreign and in_file.design_tables == {}


def _toolchain():
    """Why the foreign backend cannot build here, or None."""
    from fpga_robotics.sim.backends import BackendError

    try:
        from fpga_robotics.sim.backends import foreign  # noqa: F401
        from fpga_robotics.sim.backends import toolchain as tc

        tc.find_compiler(), tc.find_make(), tc.verilator_root()
    except (BackendError, ImportError) as exc:  # pragma: no cover - depends on the machine
        return str(exc)
    return None


@pytest.mark.skipif(_toolchain() is not None, reason="no Verilator toolchain")
@pytest.mark.slow
def test_a_scenario_runs_its_foreign_design_in_closed_loop(files, capsys):
    from fpga_robotics.cli import run

    argv = ["--duration", "1", "--rerun", "off", "--quiet"]
    code = run.main(
        ["--scenario", str(files / "foreign.toml"), *argv, "--summary", str(files / "foreign.json")]
    )
    assert code == 0, capsys.readouterr().out
    run.main(
        [
            "--scenario",
            str(files / "plain.toml"),
            "--backend",
            "model",
            *argv,
            "--summary",
            str(files / "plain.json"),
        ]
    )
    got, want = (json.loads((files / n).read_text()) for n in ("foreign.json", "plain.json"))
    assert got["backend"] == "cxxrtl-foreign" and want["backend"] == "model"
    # The exported FollowTarget with its full port map: the same run, figure for figure.
    for key in (
        "frames",
        "min_distance_m",
        "mean_distance_m",
        "found_fraction",
        "target_in_view_fraction",
        "path_length_m",
        "collisions",
        "verdict",
    ):
        assert got[key] == want[key], key


def test_run_design_verilog_replaces_the_scenarios_own_design(tmp_path):
    """``run --design verilog:FILES --ports MAP`` on a scenario whose design is one's own
    (with [design.params]): the Verilog design is the scenario's (its files, no parameters of
    the design it replaces); a --set design.params is the Verilog design's own."""
    from fpga_robotics.cli import run

    data = Path(__file__).parent / "data"
    lf = data / "line_follow_verilog"
    args = argparse.Namespace(
        scenario=None,
        overrides=[],
        design=f"verilog:{lf / 'lf_top.v'},{lf / 'lf_core.v'}",
        ports=str(lf / "lf_ports.toml"),
        backend="cxxrtl",
        resolution=None,
        duration=None,
        color=None,
    )
    own = data / "user_designs" / "wall_stop.toml"
    assert load_scenario(str(own)).design_params == {"speed": 300, "stop_mm": 250}
    args.scenario = str(own)
    scenario = run.load_run_scenario(args)
    assert scenario.design_params == {}
    assert scenario.foreign.verilog == (str(lf / "lf_top.v"), str(lf / "lf_core.v"))
    assert scenario.foreign.ports == str(lf / "lf_ports.toml")
    assert not scenario.foreign.overrides
    args.overrides = ["design.params.speed=100"]
    scenario = run.load_run_scenario(args)
    assert scenario.foreign.overrides.parameters == (("speed", "100"),)
