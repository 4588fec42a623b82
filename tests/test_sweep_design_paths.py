"""Design files a campaign names in its grid, sets and set items are relative to the campaign
file, as its ``design`` and ``ports`` are; the campaign's ``ports`` go with every ``verilog:``
design of its runs (docs/campaigns.md)."""

import json
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fpga_robotics.cli.sweep import main
from fpga_robotics.sim.backends import available_backends
from fpga_robotics.sweep import load_campaign_file, run_campaign

DATA = Path(__file__).parent / "data"
DESIGNS = DATA / "user_designs"
LINE_FOLLOW = DATA / "line_follow_verilog"


@pytest.fixture
def tree(tmp_path, monkeypatch):
    """A scenario, designs and a campaign each in a folder of its own; the current folder is
    a fourth one, so that no path is right by chance."""
    (tmp_path / "scen").mkdir()
    shutil.copy(DATA / "bump_wall.toml", tmp_path / "scen" / "bump_wall.toml")
    (tmp_path / "designs").mkdir()
    for name in ("bump_watch.py", "bump_stop_noreset.v"):
        shutil.copy(DESIGNS / name, tmp_path / "designs" / name)
    shutil.copy(DESIGNS / "bump_stop_noreset_ports.toml", tmp_path / "designs" / "ports.toml")
    (tmp_path / "camp").mkdir()
    (tmp_path / "here").mkdir()
    monkeypatch.chdir(tmp_path / "here")
    return tmp_path


HEAD = 'scenarios = ["../scen/bump_wall.toml"]\nbackend = "cxxrtl"\nduration = 0.5\n'


def _campaign(tree, text):
    path = tree / "camp" / "c.toml"
    path.write_text(HEAD + text)
    return load_campaign_file(str(path))


def _sets(spec):
    """A run's ``--set`` items as {key: text}, and whether it has ``--ports``."""
    argv = spec.argv()
    items = [argv[i + 1] for i, a in enumerate(argv) if a == "--set"]
    return dict(item.split("=", 1) for item in items), "--ports" in argv


def test_a_design_reference_on_a_grid_axis_is_relative_to_the_campaign_file(tree):
    watch = tree / "designs" / "bump_watch.py"
    campaign = _campaign(
        tree,
        '[grid]\n"design.top" = ["../designs/bump_watch.py:BumpWatch", "follow_target"]\n'
        '[[sets]]\n"design.top" = "../designs/bump_watch.py:BumpWatch"\n"robot.mass" = 12.0\n',
    )
    tops = [dict(spec.overrides)["design.top"] for spec in campaign.runs]
    assert tops == [f"{watch}:BumpWatch", "follow_target", f"{watch}:BumpWatch"]
    # The same text as the campaign's design names the same file.
    as_design = _campaign(tree, 'design = "../designs/bump_watch.py:BumpWatch"\n')
    where = as_design.runs[0].design.rpartition(":")[0]
    assert Path(where).resolve() == watch
    # Every run loads as run loads it (the dry run checks them all).
    assert main([str(tree / "camp" / "c.toml"), "--dry-run"]) == 0


def test_a_shadow_design_reference_is_relative_to_the_campaign_file(tree):
    # It was taken from the current folder: a campaign started elsewhere found no file. (One
    # folder deeper than the current one: ../designs from here is not the campaign's.)
    watch = tree / "designs" / "bump_watch.py"
    path = tree / "camp" / "deep" / "c.toml"
    path.parent.mkdir()
    path.write_text(
        'scenarios = ["../../scen/bump_wall.toml"]\nbackend = "cxxrtl"\nduration = 0.5\n'
        'design = "../../designs/bump_watch.py:BumpWatch"\n'
        'shadow = "../../designs/bump_watch.py:BumpWatch"\n'
    )
    shadow = load_campaign_file(str(path)).runs[0].shadow
    assert Path(shadow.rpartition(":")[0]).resolve() == watch
    assert main([str(path), "--dry-run"]) == 0


def test_the_campaign_ports_go_with_every_verilog_design_of_a_grid_axis(tree):
    verilog = tree / "designs" / "bump_stop_noreset.v"
    ports = tree / "designs" / "ports.toml"
    campaign = _campaign(
        tree,
        'ports = "../designs/ports.toml"\n[grid]\n'
        '"design.top" = ["verilog:../designs/bump_stop_noreset.v", '
        '"../designs/bump_watch.py:BumpWatch"]\n',
    )
    verilog_run, watch_run = (_sets(spec) for spec in campaign.runs)
    assert verilog_run == (
        {"design.top": json.dumps(f"verilog:{verilog}"), "design.ports": json.dumps(str(ports))},
        False,
    )
    # A design of one's own has no port map: it takes none.
    assert watch_run[0].keys() == {"design.top"} and watch_run[1] is False
    assert main([str(tree / "camp" / "c.toml"), "--dry-run"]) == 0


def test_design_files_in_set_items_and_sets_are_relative_to_the_campaign_file(tree):
    verilog = tree / "designs" / "bump_stop_noreset.v"
    ports = tree / "designs" / "ports.toml"
    campaign = _campaign(
        tree,
        'set = ["design.ports=../designs/ports.toml"]\n'
        '[[sets]]\n"design.top" = "verilog:../designs/bump_stop_noreset.v"\n',
    )
    assert _sets(campaign.runs[0]) == (
        {"design.ports": json.dumps(str(ports)), "design.top": json.dumps(f"verilog:{verilog}")},
        False,
    )
    assert main([str(tree / "camp" / "c.toml"), "--dry-run"]) == 0


def test_a_run_that_gives_its_own_port_map_takes_not_the_campaigns(tree):
    # The scenario's own Verilog design: the campaign's ports replace its map (run --ports),
    # but not in a run that sets design.ports itself (--ports would replace that too, and its
    # row name a map it did not run).
    ports = tree / "designs" / "ports.toml"
    campaign = _campaign(
        tree,
        'ports = "../designs/ports.toml"\n[[sets]]\n"design.ports" = "other.toml"\n'
        '[[sets]]\n"robot.mass" = 1.0\n',
    )
    own, other = campaign.runs
    assert _sets(own) == ({"design.ports": json.dumps(str(tree / "camp" / "other.toml"))}, False)
    assert _sets(other)[1] and other.ports == os.path.relpath(ports)


def test_backend_auto_takes_what_run_takes_for_each_design(tree):
    from fpga_robotics.sim.backends import fastest_backend_name
    from fpga_robotics.sweep.plan import make_plan

    def backends(text):
        path = tree / "camp" / "auto.toml"
        path.write_text(HEAD.replace('"cxxrtl"', '"auto"') + text)
        return [spec.backend for spec in make_plan(load_campaign_file(str(path))).runs]

    # run --backend auto puts a design of one's own on the fastest compiled backend (its pins
    # on CXXRTL, else Verilator), as the campaign's design or as a design.top ...
    fastest = fastest_backend_name()
    assert backends('design = "../designs/bump_watch.py:BumpWatch"\n') == [fastest]
    # ... and leaves a Verilog design to the foreign choice, design by design (Verilator for
    # one CXXRTL cannot run): its runs stay on auto.
    assert backends(
        'ports = "../designs/ports.toml"\n[grid]\n"design.top" = '
        '["verilog:../designs/bump_stop_noreset.v", "../designs/bump_watch.py:BumpWatch"]\n'
    ) == ["auto", fastest]


def test_a_known_limit_names_a_design_as_the_grid_does(tree):
    # `when` matches the rows' values: its design reference is read as the grid's is.
    campaign = _campaign(
        tree,
        '[grid]\n"design.top" = ["../designs/bump_watch.py:BumpWatch", "follow_target"]\n'
        '[[known_limits]]\ncheck = "max_wall_collisions"\nreason = "it has no wheels"\n'
        'when = {"design.top" = "../designs/bump_watch.py:BumpWatch"}\n',
    )
    watched = dict(campaign.runs[0].overrides)["design.top"]
    assert campaign.known_limits[0]["when"] == {"design.top": watched}


@pytest.mark.slow
@pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no CXXRTL toolchain")
def test_a_verilog_grid_value_runs_as_run_design_ports(tmp_path, monkeypatch):
    """A line follower in Verilog as a design.top axis of line_track (whose follow_line has
    a [design.line] table), with the campaign's ports: the row is run --design --ports."""
    monkeypatch.chdir(tmp_path)
    rel = os.path.relpath(LINE_FOLLOW, tmp_path / "camp")
    (tmp_path / "camp").mkdir()
    (tmp_path / "camp" / "lf.toml").write_text(
        'scenarios = ["line_track"]\nbackend = "cxxrtl"\nduration = 0.5\n'
        'set = ["sim.clock_hz=100000"]\n'
        f'ports = "{rel}/lf_ports.toml"\n'
        f'[grid]\n"design.top" = ["verilog:{rel}/lf_top.v,{rel}/lf_core.v"]\n'
    )
    campaign = load_campaign_file(str(tmp_path / "camp" / "lf.toml"))
    (row,) = run_campaign(campaign, tmp_path / "out", workers=1, record="none")
    assert row["status"] in ("pass", "fail"), row["message"]
    summary = tmp_path / "run.json"
    files = f"{LINE_FOLLOW / 'lf_top.v'},{LINE_FOLLOW / 'lf_core.v'}"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics.run",
            *shlex.split(
                f"--scenario line_track --backend cxxrtl --duration 0.5 "
                f"--set sim.clock_hz=100000 --design verilog:{files} "
                f"--ports {LINE_FOLLOW / 'lf_ports.toml'} --rerun off --quiet"
            ),
            "--summary",
            str(summary),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode in (0, 1), done.stderr
    by_run = json.loads(summary.read_text())
    for key in ("path_length_m", "sim_cycles", "verdict", "extra_outputs"):
        assert row[key] == (
            json.dumps(by_run[key], sort_keys=True)
            if isinstance(by_run[key], dict)
            else by_run[key]
        ), key


def test_max_runs_builds_only_the_designs_of_the_runs_it_keeps(tree, capsys):
    from fpga_robotics.sweep.plan import make_plan

    campaign = _campaign(
        tree, '[grid]\n"design.top" = ["../designs/bump_watch.py:BumpWatch", "follow_target"]\n'
    )
    path = str(tree / "camp" / "c.toml")
    assert main([path, "--dry-run"]) == 0
    assert ": 2 runs (2 design parameter set(s) to build)" in capsys.readouterr().out
    assert main([path, "--dry-run", "--max-runs", "1"]) == 0
    assert ": 1 runs (1 design parameter set(s) to build)" in capsys.readouterr().out
    plan = make_plan(campaign)
    plan.keep_first(1)
    # The one build left is the kept run's design, BumpWatch.
    (argv,) = plan.builds.values()
    assert any(a.endswith('bump_watch.py:BumpWatch"') for a in argv), argv
