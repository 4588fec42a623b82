"""Bad campaign files and options: one line saying what is wrong, exit code 2, nothing run
and nothing written."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.cli.sweep import main
from fpga_robotics.sim.backends import available_backends

SWEEP = [sys.executable, "-m", "fpga_robotics.sweep"]

GOOD = """scenarios = ["approach"]
seeds = "0-1"
backend = "model"
resolution = "40x24"
duration = 1.0
"""

CASES = {
    "unknown key": (GOOD + 'sceanrio = "x"\n', "unknown key 'sceanrio'"),
    "empty grid": (GOOD + "[grid]\n", "grid is empty"),
    "empty grid axis": (GOOD + '[grid]\n"design.diff_min" = []\n', "has no values"),
    "bad seed range": (GOOD.replace('"0-1"', '"9-3"'), "range '9-3' is empty"),
    "seed not a number": (GOOD.replace('"0-1"', '"a-b"'), "seeds must be"),
    "negative seed": (GOOD.replace('"0-1"', "[-4]"), "out of range"),
    "unknown scenario": (GOOD.replace('"approach"', '"aproach"'), "unknown scenario 'aproach'"),
    # A bad override value: named as the file gives it, with the run.
    "unknown override key": (
        GOOD + '[grid]\n"design.dif_min" = [4]\n',
        (
            "c.toml: the [grid] axis design.dif_min, in the run of approach with design.dif_min=4: "
            "unknown scenario key 'design.dif_min'"
        ),
    ),
    "bad override value": (
        GOOD + '[grid]\n"design.diff_min" = [4, -3]\n',
        "c.toml: the [grid] axis design.diff_min, in the run of approach with design.diff_min=-3: ",
    ),
    "a bad value in a set": (
        GOOD + '[[sets]]\n"robot.mass" = 10.0\n[[sets]]\n"robot.mass" = -1.0\n',
        "c.toml: sets[1], in the run of approach with robot.mass=-1.0: robot.mass must be >= ",
    ),
    "a bad set item": (
        GOOD + 'set = ["robot.mass=-1.0"]\n',
        'c.toml: set item "robot.mass=-1.0", in the run of approach with robot.mass=-1.0: ',
    ),
    "a bad resolution": (
        GOOD.replace('"40x24"', '"0x0"'),
        'c.toml: resolution = "0x0", in the run of approach: resolution must look like W',
    ),
    "bad backend": (
        GOOD.replace('"model"', '"fpga"'),
        'c.toml: backend = "fpga": the backend must be one of',
    ),
    "a bad shadow": (
        GOOD + 'shadow = "frob=1"\n',
        "c.toml: shadow = \"frob=1\", in the run of approach: unknown scenario key 'design.frob'",
    ),
    "an endless timeout": (GOOD + "timeout = inf\n", "timeout must be a finite number"),
    "malformed toml": (GOOD + "grid = [\n", "malformed TOML"),
    "description not a string": (GOOD + "description = 5\n", "description must be a string, got 5"),
    "not a list": (GOOD + '[grid]\n"design.diff_min" = 4\n', "must be a list of values"),
    "a parameter shadow in real-clock timing": (
        'scenarios = ["line_track"]\nduration = 1.0\nshadow = "published"\n',
        "scenario 'line_track' runs in real-clock timing, where --shadow takes a design reference",
    ),
    # A value for every run that the runs' overrides give too: a run would take one of them
    # and its row be labelled with the other.
    "a set item on a grid axis": (
        GOOD + 'set = ["design.diff_min=5"]\n[grid]\n"design.diff_min" = [4, 6]\n',
        (
            'c.toml: set item "design.diff_min=5" gives every run its design.diff_min, and the '
            "[grid] axis design.diff_min varies it: give it in one of them"
        ),
    ),
    "a set item in a set": (
        GOOD + 'set = ["robot.mass=12"]\n[[sets]]\n"robot.mass" = 10.0\n',
        'set item "robot.mass=12" gives every run its robot.mass, and sets[0] varies it',
    ),
    # A run given twice: the results would hold one row of it.
    "a grid value twice": (
        GOOD + '[grid]\n"design.diff_min" = [4, 6, 4]\n',
        "c.toml: the [grid] axis design.diff_min lists 4 twice: give each value once",
    ),
    "a set equal to a grid run": (
        GOOD + '[grid]\n"design.diff_min" = [4, 6]\n[[sets]]\n"design.diff_min" = 6\n',
        "c.toml: sets[0] repeats the grid run design.diff_min=6: give each run once",
    ),
    "two equal sets": (
        GOOD
        + '[[sets]]\n"design.diff_min" = 6\n"robot.mass" = 10.0\n'
        + '[[sets]]\n"robot.mass" = 10.0\n"design.diff_min" = 6\n',
        "c.toml: sets[1] repeats sets[0]: give each run once",
    ),
    "a scenario twice": (
        GOOD.replace('["approach"]', '["approach", "divider", "approach"]'),
        "c.toml: scenarios lists approach twice: give each scenario once",
    ),
    # run's --duration and --resolution: set items of these keys after the runs' own.
    "duration on a sim.duration axis": (
        GOOD + '[grid]\n"sim.duration" = [0.5, 2.0]\n',
        (
            "c.toml: duration = 1.0 gives every run its sim.duration, and the [grid] axis "
            "sim.duration varies it"
        ),
    ),
    "resolution in a set": (
        GOOD + '[[sets]]\n"camera.resolution" = "80x60"\n',
        'resolution = "40x24" gives every run its camera.resolution, and sets[0] varies it',
    ),
    "duration and a sim.duration set item": (
        GOOD + 'set = ["sim.duration=2.0"]\n',
        'duration = 1.0 gives every run its sim.duration, and set item "sim.duration=2.0"',
    ),
    # run's --seed, which the campaign's seeds give every run, wins over a seed override.
    "a seed axis": (
        GOOD + "[grid]\nseed = [1, 2]\n",
        (
            "c.toml: the [grid] axis seed sets the scenario's seed, which the campaign's seeds "
            "give every run: list the seeds there"
        ),
    ),
    "a seed in a set": (GOOD + "[[sets]]\nseed = 3\n", "sets[0] sets the scenario's seed"),
    "a seed set item": (GOOD + 'set = ["seed=3"]\n', 'set item "seed=3" sets the scenario'),
    "a design and a design.top axis": (
        GOOD + 'design = "mine.py:Mine"\n[grid]\n"design.top" = ["follow_target"]\n',
        (
            'design = "mine.py:Mine" gives every run its design.top, and the [grid] axis '
            "design.top varies it"
        ),
    ),
    "a design and a design.top set item": (
        GOOD + 'design = "mine.py:Mine"\nset = [\'design.top="follow_line"\']\n',
        (
            'design = "mine.py:Mine" gives every run its design.top, and set item '
            '"design.top=\\"follow_line\\"" gives it too'
        ),
    ),
    "a design on pins on the model backend": (
        GOOD.replace('"approach"', '"line_track"'),
        "run of line_track: the model backend runs whole frames",
    ),
    "a Verilog design without its port map": (
        GOOD + 'design = "verilog:top.v"\n',
        'run of approach: design = "verilog:top.v" needs ports = "PORTS.toml" (its port map)',
    ),
    # An empty key reached every run as "unknown scenario key ''".
    "an empty grid key": (
        GOOD + '[grid]\n"" = [1, 2]\n',
        "c.toml: grid key '' is empty: name a scenario key (e.g. robot.mass)",
    ),
    "a port map without a Verilog design": (
        GOOD + 'ports = "top_ports.toml"\n',
        (
            'run of approach: ports = "top_ports.toml" is the port map of a Verilog design, and '
            'the run has none: give design = "verilog:FILE.v" with it, or leave ports out'
        ),
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_campaign_file_is_one_line_and_exit_2(case, tmp_path, monkeypatch, capsys):
    # In this process, through the command's own wrapper (the options below go through a
    # fresh interpreter).
    text, message = CASES[case]
    (tmp_path / "c.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["c.toml", "--out", "out", "--quiet"], prog="fpga-robotics sweep")
    assert exit_info.value.code == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fpga-robotics sweep: error: "), lines
    assert message in lines[0] and captured.out == ""
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--workers", "0"], "--workers must be 1..256, got 0"),
        # as mutate's: not a process per run of a large campaign
        (["--workers", "100000", "--dry-run"], "--workers must be 1..256, got 100000"),
        (["--grid", "design.diff_min=4"], "--grid needs KEY=[V1, V2, ...]"),
        (["--seeds", "5-1"], "is empty"),
        (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "--workers sizes"),
        (["nonexistent_campaign"], "unknown campaign"),
        (["--record", "none", "--log-every", "3"], "--log-every shapes the recordings"),
        # --dry-run checks what the run would check.
        (["--record", "none", "--bag", "--dry-run"], "--bag writes the recorded runs"),
        (["--record", "none", "--log-every", "3", "--dry-run"], "--log-every shapes"),
        (["--resume", "--out", "c.toml", "--dry-run"], "--out 'c.toml' exists and is not a"),
        # A scenario in real-clock timing on a backend that runs whole frames.
        (
            ["--scenarios", "line_track", "--dry-run"],
            "run of line_track: the model backend runs whole frames",
        ),
    ],
)
def test_bad_options_are_one_line_and_exit_2(argv, message, tmp_path):
    (tmp_path / "c.toml").write_text(GOOD)
    if argv[0] != "nonexistent_campaign":
        argv = ["c.toml", *argv]
    proc = subprocess.run(
        SWEEP + argv + ["--quiet"],
        cwd=tmp_path,
        check=False,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines


#: ``--bench`` measures runs of its own: what it would ignore is refused (each case would run
#: a short benchmark if it were not).
SHORT_BENCH = ["--bench-runs", "1", "--bench-repeats", "1", "--duration", "0.1", "--workers", "1"]
BENCH_MISUSE = {
    "a campaign": (["c.toml", "--bench", *SHORT_BENCH], "not a campaign: leave out c.toml"),
    "--dry-run": (["--bench", "--dry-run", *SHORT_BENCH], "--dry-run does not apply to it"),
    "--set": (["--bench", "--set", "robot.mass=12", *SHORT_BENCH], "--set does not apply"),
    "--out": (["--bench", "--out", "out", *SHORT_BENCH], "--out does not apply to it"),
    "two scenarios": (
        ["--bench", "--scenarios", "approach,divider", *SHORT_BENCH],
        "--bench measures one scenario, got --scenarios approach,divider",
    ),
    "--bench-runs without --bench": (["c.toml", "--bench-runs", "5"], "goes with --bench"),
    "--bench-repeats without --bench": (["c.toml", "--bench-repeats", "2"], "goes with --bench"),
}


#: ``--bench`` values checked as a campaign's are, before the first line: none is replaced
#: by its default (each case would run a short benchmark if it were).
BENCH_BAD_VALUES = {
    "zero duration": (["--duration", "0"], "--duration must be a finite number of seconds > 0"),
    "empty scenario": (["--scenarios", ""], "scenarios must be a non-empty list"),
    "empty backend": (["--backend", ""], 'backend = "": the backend must be one of'),
    "empty resolution": (["--resolution", ""], "resolution must look like WIDTHxHEIGHT"),
}


@pytest.mark.parametrize("case", sorted(BENCH_BAD_VALUES))
def test_bench_values_are_checked_not_replaced_by_defaults(case, tmp_path, monkeypatch, capsys):
    argv, message = BENCH_BAD_VALUES[case]
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["--bench", *SHORT_BENCH, *argv], prog="x")
    assert exit_info.value.code == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert captured.out == "" and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("case", sorted(BENCH_MISUSE))
def test_what_bench_would_ignore_is_refused(case, tmp_path, monkeypatch, capsys):
    argv, message = BENCH_MISUSE[case]
    (tmp_path / "c.toml").write_text(GOOD)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, [*argv, "--dry-run"] if "--bench" not in argv else argv, prog="x")
    assert exit_info.value.code == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert captured.out == "" and sorted(p.name for p in tmp_path.iterdir()) == ["c.toml"]


def test_dry_run_counts_and_shows_commands(tmp_path):
    (tmp_path / "c.toml").write_text(GOOD + '[grid]\n"design.diff_min" = [4, 5, 6]\n')
    proc = subprocess.run(
        SWEEP + ["c.toml", "--dry-run"],
        cwd=tmp_path,
        check=False,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("campaign c: 6 runs")
    assert len(lines) == 4
    assert all(
        line.strip().startswith("python -m fpga_robotics.run --scenario approach")
        for line in lines[1:]
    )


def test_report_of_a_folder_without_results_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "empty").mkdir()
    # A results table cut short (a full disk, a copy stopped) or not Parquet at all.
    for name, data in (("torn", b""), ("text", b"run_id,status\n")):
        (tmp_path / name).mkdir()
        (tmp_path / name / "results.parquet").write_bytes(data)
    for folder, message in (
        ("empty", "holds no campaign results"),
        ("missing", "is not a folder of campaign results"),
        ("torn", "torn/results.parquet is not a readable results table"),
        ("text", "text/results.parquet is not a readable results table"),
    ):
        proc = subprocess.run(
            SWEEP + ["report", folder],
            cwd=tmp_path,
            check=False,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert proc.returncode == 2
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and message in lines[0], lines


#: A command-line value that is wrong: the error names the option, not the campaign file.
BAD_OPTION_VALUES = {
    "--seeds": (["--seeds", "x"], "--seeds must be A-B (e.g. 0-19) or A,B,C, got 'x'"),
    "--seeds range": (["--seeds", "5-1"], "--seeds range '5-1' is empty"),
    "--set": (["--set", "robot.mass"], "--set needs KEY=VALUE (e.g. robot.mass=12)"),
    "--grid": (["--grid", "design.diff_min=[]"], "--grid needs KEY=[V1, V2, ...]"),
    "--grid twice": (
        ["--grid", "design.diff_min=[4]", "--grid", " design.diff_min=[5, 6]"],
        "--grid design.diff_min is given twice: give all its values in one list",
    ),
    "--duration": (["--duration", "-1"], "--duration must be a finite number of seconds > 0"),
    "--timeout": (
        ["--timeout", "inf"],
        "--timeout must be a finite number of seconds > 0, got inf",
    ),
    "--backend": (["--backend", "cxxrt"], "--backend cxxrt: the backend must be one of"),
    # An empty value is checked, never taken for the default (auto).
    "--backend empty": (["--backend", ""], "--backend : the backend must be one of"),
    "--shadow": (
        ["--shadow", "frob=1"],
        "run of approach: --shadow frob=1: unknown scenario key 'design.frob'",
    ),
    "--scenarios": (["--scenarios", ","], "--scenarios needs scenario names"),
    "--set value": (
        ["--set", "robot.mass=-3"],
        "--set robot.mass=-3, in the run of approach with robot.mass=-3: robot.mass must be >= ",
    ),
    "--grid value": (
        ["--grid", "design.nokey=[1]"],
        "--grid design.nokey, in the run of approach with design.nokey=1: unknown scenario key",
    ),
    "--resolution": (
        ["--resolution", "0x0"],
        "--resolution 0x0, in the run of approach: resolution must look like WIDTHxHEIGHT",
    ),
    "--scheduler": (
        ["--scheduler", "notaurl"],
        "--scheduler must be a Dask scheduler address tcp://HOST:PORT",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_OPTION_VALUES))
def test_a_bad_option_value_is_blamed_on_the_option(case, tmp_path, monkeypatch, capsys):
    argv, message = BAD_OPTION_VALUES[case]
    (tmp_path / "c.toml").write_text(GOOD)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["c.toml", *argv, "--out", "out", "--quiet"], prog="fpga-robotics sweep")
    assert exit_info.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"fpga-robotics sweep: error: {message}"), lines
    assert not (tmp_path / "out").exists()


#: Values the command line gives every run, or a design, that the file's runs vary: the error
#: names the option.
GIVEN_TWICE = {
    "--set on a grid axis": (
        '[grid]\n"design.diff_min" = [4, 6]\n',
        ["--set", "design.diff_min=5"],
        (
            "--set design.diff_min=5 gives every run its design.diff_min, and the [grid] axis "
            "design.diff_min varies it"
        ),
    ),
    "--grid on a set item": (
        'set = ["design.diff_min=5"]\n',
        ["--grid", "design.diff_min=[4, 6]"],
        (
            'set item "design.diff_min=5" gives every run its design.diff_min, and --grid '
            "design.diff_min varies it"
        ),
    ),
    "--resolution on a camera.resolution set": (
        '[[sets]]\n"camera.resolution" = "80x60"\n',
        ["--resolution", "320x240"],
        "--resolution 320x240 gives every run its camera.resolution, and sets[0] varies it",
    ),
    "--duration on a sim.duration axis": (
        "",
        ["--duration", "3", "--grid", "sim.duration=[1.0, 2.0]"],
        "--duration 3.0 gives every run its sim.duration, and --grid sim.duration varies it",
    ),
    "--scenarios naming one twice": (
        "",
        ["--scenarios", "approach,approach"],
        "--scenarios lists approach twice: give each scenario once",
    ),
    "--grid listing a value twice": (
        "",
        ["--grid", "design.diff_min=[5, 5]"],
        "--grid design.diff_min lists 5 twice: give each value once",
    ),
    "--design on a design.top axis": (
        '[grid]\n"design.top" = ["follow_target", "follow_line"]\n',
        ["--design", "mine.py:Mine"],
        (
            "--design mine.py:Mine gives every run its design.top, and the [grid] axis "
            "design.top varies it"
        ),
    ),
    "--design verilog without --ports": (
        "",
        ["--design", "verilog:top.v"],
        "run of approach: --design needs --ports PORTS.toml (the design's port map)",
    ),
}


@pytest.mark.parametrize("case", sorted(GIVEN_TWICE))
def test_a_value_given_twice_is_refused_naming_the_option(case, tmp_path, monkeypatch, capsys):
    text, argv, message = GIVEN_TWICE[case]
    (tmp_path / "c.toml").write_text(GOOD + text)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["c.toml", *argv, "--dry-run"], prog="fpga-robotics sweep")
    assert exit_info.value.code == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert captured.out == ""


LIMIT = '[[known_limits]]\ncheck = "found_min_fraction"\nreason = "x"\n'


def test_a_known_limit_of_a_scenario_not_run_is_an_error_unless_scenarios_is_given(
    tmp_path, monkeypatch, capsys
):
    (tmp_path / "c.toml").write_text(GOOD + LIMIT + 'scenarios = ["aproach"]\n')
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["c.toml", "--out", "out", "--quiet"], prog="fpga-robotics sweep")
    assert exit_info.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "fpga-robotics sweep: error: c.toml: known_limits[0]: scenarios names 'aproach', "
        "which the campaign does not run"
    ), lines
    assert not (tmp_path / "out").exists()
    # The file's own scenario is accepted; with --scenarios choosing others, an entry for a
    # scenario of the file that is not run just does not apply.
    (tmp_path / "c.toml").write_text(GOOD + LIMIT + 'scenarios = ["approach"]\n')
    assert main(["c.toml", "--dry-run"]) == 0
    assert main(["c.toml", "--scenarios", "divider", "--dry-run"]) == 0


def test_one_scenario_by_two_paths_or_two_copies_is_an_error_naming_both(
    tmp_path, monkeypatch, capsys
):
    # Rows go by the run's identity (the scenario's content): these runs would be one row.
    (tmp_path / "s.toml").write_text('[sim]\nduration = 1.0\n[camera]\nresolution = "40x24"\n')
    (tmp_path / "copy.toml").write_text((tmp_path / "s.toml").read_text())
    (tmp_path / "c.toml").write_text('backend = "model"\nscenarios = ["s.toml"]\n')
    monkeypatch.chdir(tmp_path)
    for scenarios, second in (("s.toml,./s.toml", "./s.toml"), ("s.toml,copy.toml", "copy.toml")):
        with pytest.raises(SystemExit) as exit_info:
            argv = ["c.toml", "--scenarios", scenarios, "--dry-run"]
            run_cli(main, argv, prog="fpga-robotics sweep")
        assert exit_info.value.code == 2
        captured = capsys.readouterr()
        assert captured.err.strip() == (
            f"fpga-robotics sweep: error: c.toml: run of s.toml and run of {second} (seed 0) "
            "are one run (the same scenario content, seed and overrides): give each run once"
        )
        assert captured.out == ""


def test_two_scenario_files_of_one_name_are_an_error_naming_both(tmp_path, monkeypatch, capsys):
    from fpga_robotics.scenario.load import load_scenario

    # A copy of the shipped `approach` elsewhere: another file, the same name.
    shipped = load_scenario("approach").source
    (tmp_path / "mine.toml").write_text(Path(shipped).read_text())
    (tmp_path / "c.toml").write_text(GOOD.replace('["approach"]', '["approach", "mine.toml"]'))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(main, ["c.toml", "--out", "out", "--quiet"], prog="fpga-robotics sweep")
    assert exit_info.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0] == (
        f"fpga-robotics sweep: error: c.toml: scenarios approach ({shipped}) and mine.toml "
        "are two files with the same name 'approach' (results are grouped by name): give "
        'one of them another name = "..."'
    )
    assert not (tmp_path / "out").exists()
    # The same file twice (by name and by path) is not two files of one name: it is each of
    # its runs given twice.
    (tmp_path / "c.toml").write_text(GOOD.replace('["approach"]', f'["approach", "{shipped}"]'))
    with pytest.raises(UsageError, match=r"^c.toml: run of approach and run of .* are one run"):
        main(["c.toml", "--dry-run"])


#: A port nothing listens on: Dask gives up on it after its 10 s connect timeout.
NOBODY = "tcp://127.0.0.1:1"


def test_an_unreachable_scheduler_writes_no_results_folder(tmp_path, monkeypatch, capsys):
    (tmp_path / "c.toml").write_text(GOOD)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main,
            ["c.toml", "--scheduler", NOBODY, "--out", "new/out", "--quiet"],
            prog="fpga-robotics sweep",
        )
    assert exit_info.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "cannot reach the Dask scheduler" in lines[0], lines
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.toml"]


def test_an_unreachable_scheduler_leaves_earlier_results_as_they_were(tmp_path, monkeypatch):
    # A results folder a later --resume could use: a row of a run of another campaign, which
    # a resumed campaign would drop from the journal once it opened the folder.
    out = tmp_path / "out"
    out.mkdir()
    journal = json.dumps({"run_id": "0123abcd", "status": "pass", "seed": 0}) + "\n"
    (out / "results.jsonl").write_text(journal)
    (tmp_path / "c.toml").write_text(GOOD)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UsageError, match="cannot reach the Dask scheduler"):
        main(["c.toml", "--scheduler", NOBODY, "--out", "out", "--resume", "--quiet"])
    assert [p.name for p in out.iterdir()] == ["results.jsonl"]
    assert (out / "results.jsonl").read_text() == journal


def _campaign_that_does_not_build(folder):
    """c.toml in ``folder``: a Verilog design that loads (its port map fits line_track) and
    does not build (a syntax error)."""
    (folder / "top.v").write_text(
        "module top(input clock, input [2:0] sens, output [15:0] wl, output [15:0] wr);\n"
        "wire oops = ;\nendmodule\n"
    )
    (folder / "ports.toml").write_text(
        'top = "top"\nclock = { port = "clock" }\n[outputs]\n'
        'motor_left = { port = "wl", width = 16, signed = true }\n'
        'motor_right = { port = "wr", width = 16, signed = true }\n'
        '[connectors.line_sensors]\nline = "sens"\n'
    )
    (folder / "c.toml").write_text(
        'scenarios = ["line_track"]\nbackend = "cxxrtl"\nduration = 0.1\n'
        'design = "verilog:top.v"\nports = "ports.toml"\n'
    )


@pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no CXXRTL toolchain")
def test_a_design_that_does_not_build_leaves_no_results_folder(tmp_path, monkeypatch, capsys):
    # The build fails before any run: the folder is never made.
    _campaign_that_does_not_build(tmp_path)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main,
            ["c.toml", "--workers", "1", "--out", "new/out", "--quiet"],
            prog="fpga-robotics sweep",
        )
    assert exit_info.value.code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "building the design of" in lines[0], lines
    assert not (tmp_path / "new").exists()


@pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no CXXRTL toolchain")
def test_a_design_that_does_not_build_leaves_earlier_results_as_they_were(
    tmp_path, monkeypatch, capsys
):
    # An earlier campaign's results, recording and report: a campaign refused at its build
    # step ran nothing, so it must not replace them (nor describe itself in campaign.json).
    _campaign_that_does_not_build(tmp_path)
    out = tmp_path / "out"
    (out / "recordings").mkdir(parents=True)
    earlier = {
        "results.jsonl": json.dumps({"run_id": "0123abcd", "status": "fail", "seed": 0}) + "\n",
        "campaign.json": json.dumps({"name": "earlier", "runs": 1, "missing": 0}),
        "report.html": "<html>earlier</html>",
        "recordings/0123abcd.rrd": "rrd",
    }
    for name, text in earlier.items():
        (out / name).write_text(text)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        run_cli(
            main,
            ["c.toml", "--workers", "1", "--out", "out", "--quiet"],
            prog="fpga-robotics sweep",
        )
    assert exit_info.value.code == 2
    assert "building the design of" in capsys.readouterr().err
    now = {str(p.relative_to(out)): p.read_text() for p in out.rglob("*") if p.is_file()}
    assert now == earlier
