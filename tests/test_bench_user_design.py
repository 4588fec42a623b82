"""``fpga-robotics bench user_verilog --design REF``: a design of one's own timed in
real-clock timing on each compiled backend, in closed loop and alone over the same cycles."""

import json
from pathlib import Path

import pytest

from fpga_robotics import cli

DATA = Path(__file__).parent / "data"
WALL_STOP = f"{DATA}/user_designs/wall_stop.py:WallStop"
BUMP_STOP = ["--design", f"verilog:{DATA}/bump_stop.v", "--ports", f"{DATA}/bump_stop_ports.toml"]


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def _bench(argv, tmp_path, capsys):
    figures = tmp_path / "figures.json"
    argv = ["bench", "user_verilog", *argv, "--seconds", "0.1", "--repeats", "1"]
    code, out, err = _cli([*argv, "--json", str(figures)], capsys)
    assert code == 0, err
    return out, json.loads(figures.read_text())["figures"]


def _check_rates(out, figures, cycles):
    """Each backend's printed rates are the figures' cycles over their times."""
    backends = [b for b in ("cxxrtl", "verilator") if f"{b}_run_ms" in figures]
    assert backends
    for b in backends:
        row = next(line.split() for line in out.splitlines() if line.startswith(b + " "))
        run_s, alone_s = figures[f"{b}_run_ms"] / 1e3, figures[f"{b}_alone_ms"] / 1e3
        assert float(row[1]) == pytest.approx(cycles / run_s / 1e6, abs=0.006)
        assert float(row[3]) == pytest.approx(cycles / alone_s / 1e6, abs=0.006)
        assert float(row[4]) == pytest.approx(run_s / alone_s, abs=0.006)


@pytest.mark.slow  # compiled pin models of the design
def test_an_amaranth_design_in_the_default_wall_room(tmp_path, capsys):
    out, figures = _bench(["--design", WALL_STOP], tmp_path, capsys)
    # 0.1 s at the default 50 MHz
    assert "in real-clock timing (user_verilog_bench), 0.1 s at 50 MHz (5.0 M cycles)" in out
    _check_rates(out, figures, 5_000_000)


@pytest.mark.slow  # compiled pin models of the design
def test_a_verilog_design_in_its_own_scenario(tmp_path, capsys):
    argv = [*BUMP_STOP, "--scenario", str(DATA / "bump_wall.toml"), "--clock-hz", "1e6"]
    out, figures = _bench(argv, tmp_path, capsys)
    assert "verilog:" in out and "(bump_wall), 0.1 s at 1 MHz (0.1 M cycles)" in out
    _check_rates(out, figures, 100_000)


@pytest.mark.slow  # compiled pin models of the design
def test_a_camera_design_whose_scenario_runs_in_compressed_timing(tmp_path, capsys):
    # red_frames raises frame_done: its scenario's "auto" is compressed timing; the bench
    # times it in real-clock timing (it raised a TypeError about pin backends).
    frames = DATA / "user_designs"
    argv = ["--design", f"{frames}/red_frames.py:RedFrames"]
    argv += ["--scenario", str(frames / "red_frames.toml"), "--clock-hz", "2e5"]
    out, figures = _bench(argv, tmp_path, capsys)
    assert "in real-clock timing (red_frames), 0.1 s at 0.2 MHz (0.0 M cycles)" in out
    _check_rates(out, figures, 20_000)


@pytest.mark.slow  # compiled pin models of the design
def test_relative_verilog_files_are_taken_from_the_current_folder(tmp_path, monkeypatch, capsys):
    # The files in the current folder only, the scenario in another (docs/your_design.md).
    (tmp_path / "mine.v").write_text((DATA / "bump_stop.v").read_text())
    (tmp_path / "mine_ports.toml").write_text((DATA / "bump_stop_ports.toml").read_text())
    monkeypatch.chdir(tmp_path)
    argv = ["--design", "verilog:mine.v", "--ports", "mine_ports.toml"]
    argv += ["--scenario", str(DATA / "bump_wall.toml"), "--clock-hz", "1e6"]
    out, figures = _bench(argv, tmp_path, capsys)
    assert "(bump_wall), 0.1 s at 1 MHz (0.1 M cycles)" in out
    _check_rates(out, figures, 100_000)


@pytest.mark.parametrize(
    "argv, message",
    [
        # bump_stop has a bumper, the default wall room an ultrasound
        (BUMP_STOP, "design 'verilog:bump_stop' has no port for its pin 'trig'"),
        (["--design", f"verilog:{DATA}/bump_stop.v"], "needs its port map: --ports"),
        (["--ports", f"{DATA}/bump_stop_ports.toml"], "--ports goes with --design REF"),
        (["--design", WALL_STOP, "--ports", "x.toml"], "--ports is the port map of a Verilog"),
        (["--design", "nowhere.py:X"], "nowhere.py"),
    ],
)
def test_designs_the_benchmark_cannot_run_are_one_line(argv, message, tmp_path, capsys):
    code, out, err = _cli(["bench", "user_verilog", *argv, "--seconds", "0.1"], capsys)
    assert out == ""
    assert code == 2 and err.count("\n") == 1, err
    assert message in err


@pytest.mark.parametrize("subject", ["loop", "pins"])
def test_the_follow_target_subjects_point_a_design_of_ones_own_to_user_verilog(subject, capsys):
    code, out, err = _cli(["bench", subject, "--design", WALL_STOP], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert f"({WALL_STOP}) is timed by fpga-robotics bench user_verilog --design REF" in err
