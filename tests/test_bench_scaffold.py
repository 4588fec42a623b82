"""The benchmarks' shared scaffold: options, checks, spreads, JSON and the calibration."""

import json

import pytest

from fpga_robotics.bench import calibrate, scaffold
from fpga_robotics.cli.errors import UsageError


def test_spread_is_median_min_max():
    s = scaffold.Spread.of([3.0, 1.0, 2.0, 10.0])
    assert (s.median, s.min, s.max, s.n) == (2.5, 1.0, 10.0, 4)
    assert f"{s:.1f}" == "2.5 (1.0-10.0)"
    assert s.scaled(2).median == 5.0
    with pytest.raises(ValueError):
        scaffold.Spread.of([])


@pytest.mark.parametrize(
    "text, message",
    [
        ("160by120", "WIDTHxHEIGHT"),
        ("0x120", "1..4096"),
        ("160x5000", "1..4096"),
        ("", "empty"),
    ],
)
def test_bad_sizes_are_usage_errors(text, message):
    with pytest.raises(UsageError, match=message):
        scaffold.parse_sizes(text)


def test_sizes():
    assert scaffold.parse_sizes("160x120, 640X480") == [(160, 120), (640, 480)]


def test_sizes_too_tall_for_the_cameras_hfov_are_usage_errors():
    # At hfov 1.047 the rows stay 0.02 rad off vertical while H/W <= cot(0.02) / tan(1.047/2)
    # = 49.9933 / 0.57711 = 86.6: 1x86 is drawn, 1x87 and 4x1000 (250 times) are not.
    assert scaffold.parse_sizes("1x86,160x120", hfov=1.047) == [(1, 86), (160, 120)]
    for text in ("1x87", "160x120,4x1000"):
        with pytest.raises(UsageError, match=r"too tall for the camera's hfov 1.047 rad.* 86.6 "):
            scaffold.parse_sizes(text, hfov=1.047)
    assert scaffold.parse_sizes("4x1000") == [(4, 1000)]  # no camera: any shape


def test_the_render3d_benchmark_refuses_a_size_its_camera_cannot_draw():
    from fpga_robotics.bench.render3d import main

    with pytest.raises(UsageError, match="a size 4x1000 is too tall"):
        main(["--sizes", "4x1000", "--frames", "1", "--repeats", "1", "--seconds", "0"])


def test_absolute_times_and_their_ratios():
    figures = {
        "results": [
            {
                "backend": "cxxrtl",
                "width": 160,
                "height": 120,
                "ms_per_frame": 0.5,
                "cycles_per_second": 4e7,
                "frames": 30,
            }
        ],
        "steps_ms": {"render": 0.25, "physics": 0.125},
        "frame_ms": scaffold.Spread.of([1.0, 2.0, 3.0]),
        "startup_s": 3.0,
        "found": True,
    }
    assert scaffold.absolute_times(figures) == [
        ("results.cxxrtl 160x120.ms_per_frame", 0.5),
        ("steps_ms.render", 0.25),
        ("steps_ms.physics", 0.125),
        ("frame_ms", 2.0),
    ]
    assert [r for _, _, r in scaffold.ratios_to(figures, 0.25)] == [2.0, 1.0, 0.5, 8.0]
    cpu = {"wall_ms": 1.0, "cpu_ms": 1.0}
    assert [r for _, _, r in scaffold.ratios_to(cpu, 0.5, 0.25)] == [2.0, 4.0]


def _command(runs, **kwargs):
    def run(args):
        runs.append(args)
        return {"frame_ms": 0.5, "size": "160x120"}

    return scaffold.command(run, "A test benchmark.\n\nMore.", name="test", **kwargs)


def test_common_options_and_their_checks(tmp_path):
    runs = []
    main = _command(runs, repeats=3, frames=10, min_seconds=1.0)
    assert main([]) == 0
    args = runs[-1]
    assert (args.repeats, args.frames, args.min_seconds, args.json) == (3, 10, 1.0, None)
    for argv, message in [
        (["--repeats", "0"], "--repeats must be 1..1000"),
        (["--frames", "0"], "--frames must be 1..1000000"),
        (["--min-seconds", "nan"], "--min-seconds"),
        (["--bogus"], "unrecognized arguments: --bogus"),
        (["--json", str(tmp_path / "no" / "f.json")], "no directory"),
    ]:
        with pytest.raises(UsageError, match=message):
            main(argv)
    assert len(runs) == 1  # a bad option is refused before any measuring
    # A subject without frames has no --frames.
    with pytest.raises(UsageError, match="unrecognized arguments: --frames"):
        _command([])(["--frames", "3"])


def test_options_given_on_the_command_line_are_told_from_defaults():
    runs = []
    main = _command(runs, repeats=3, frames=10)
    main(["--frames", "10", "--json", "f.json"])
    main([])
    assert runs[0].given == {"frames", "json"} and runs[1].given == set()
    args = runs[0]
    with pytest.raises(UsageError, match=r"^--frames does not apply with --x \(why\)$"):
        scaffold.check_not_given(args, ("repeats", "frames"), "with --x (why)")
    scaffold.check_not_given(args, ("repeats", "calibrate"), "with --x (why)")


def test_a_calibration_with_no_times_to_convert_promises_none(capsys):
    reference = {
        "what": "test",
        "frame_ms": scaffold.Spread.of([0.25]),
        "cpu_ms": scaffold.Spread.of([0.125]),
    }
    scaffold.print_calibrated({"ratio": 2.0, "size": "160x120"}, reference)
    out = capsys.readouterr().out
    line = (
        "calibration (test): 0.2500 (0.2500-0.2500) ms/frame, CPU 0.1250 (0.1250-0.1250) "
        "(median, min-max of 1)"
    )
    assert out.splitlines() == [line]


def test_json_holds_the_figures_and_the_machine(tmp_path, capsys):
    path = tmp_path / "f.json"
    assert _command([])(["--json", str(path)], prog="fpga-robotics bench test") == 0
    data = json.loads(path.read_text())
    assert data["command"] == "fpga-robotics bench test"
    assert data["figures"] == {"frame_ms": 0.5, "size": "160x120"}
    assert data["machine"]["cpus"] >= 1 and "calibration" not in data
    assert [p.name for p in tmp_path.iterdir()] == ["f.json"]  # no temporary file left


def test_calibrate_option_prints_each_time_in_calibration_frames(monkeypatch, tmp_path, capsys):
    reference = {
        "what": "published preset, test, 160x120",
        "backend": "test",
        "frame_ms": scaffold.Spread.of([0.25, 0.2, 0.3]),
        "cpu_ms": scaffold.Spread.of([0.125]),
    }
    monkeypatch.setattr(scaffold, "measure_calibration", lambda **_: reference)
    path = tmp_path / "f.json"
    assert _command([])(["--calibrate", "--json", str(path)]) == 0
    out = capsys.readouterr().out
    assert (
        "calibration (published preset, test, 160x120): 0.2500 (0.2000-0.3000) ms/frame, "
        "CPU 0.1250 (0.1250-0.1250)"
    ) in out
    lines = out.splitlines()
    assert lines[-3].split() == ["figure", "time", "x", "calibration"]
    assert lines[-2].split() == ["frame_ms", "0.5", "ms", "2x"]  # 0.5 ms / 0.25 ms
    data = json.loads(path.read_text())
    assert data["calibration"]["frame_ms"] == {"median": 0.25, "min": 0.2, "max": 0.3, "n": 3}


def test_calibration_on_the_model_backend(tmp_path, capsys):
    path = tmp_path / "c.json"
    assert (
        calibrate.main(
            ["--backend", "model", "--frames", "2", "--repeats", "3", "--json", str(path)]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "calibration: published preset, model, 160x120, 2 frames x 3 repeats" in out
    cal = json.loads(path.read_text())["figures"]["calibration"]
    frame = cal["frame_ms"]
    assert frame["n"] == 3 and 0 < frame["min"] <= frame["median"] <= frame["max"]
    # It is the calibration: no --calibrate.
    with pytest.raises(UsageError, match="unrecognized arguments: --calibrate"):
        calibrate.main(["--calibrate"])
    with pytest.raises(UsageError, match="unknown backend 'gpu'"):
        calibrate.main(["--backend", "gpu"])


def test_every_benchmark_is_a_subcommand_on_the_scaffold(capsys):
    import importlib
    from pathlib import Path

    from fpga_robotics.cli import BENCHMARKS

    for what, (module_name, _help) in BENCHMARKS.items():
        module = importlib.import_module(module_name)
        with pytest.raises(SystemExit) as exit_:
            module.main(["--help"], prog=f"fpga-robotics bench {what}")
        out = capsys.readouterr().out
        assert exit_.value.code == 0 and f"usage: fpga-robotics bench {what}" in out
        assert "--json PATH" in out, what
        # --calibrate where the figures hold times: not on the calibration, not on fork's.
        assert ("--calibrate" in out) == (what not in ("calibrate", "fork")), what
    # The ways in are fpga-robotics bench and python -m fpga_robotics.bench, nothing else.
    folder = Path(scaffold.__file__).parent
    own = [
        p.name
        for p in folder.glob("*.py")
        if p.name != "__main__.py" and "if __name__ ==" in p.read_text()
    ]
    assert not own, f"benchmark modules with a command line of their own: {own}"
