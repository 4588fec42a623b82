"""The benchmark CLI: figures printed and written, bad options as clear errors."""

import json

import pytest

from fpga_robotics import bench
from fpga_robotics.errors import UsageError


def test_bench_prints_and_writes_figures(tmp_path, capsys):
    path = tmp_path / "bench.json"
    code = bench.main(
        [
            "--backends",
            "model,cxxrtl",
            "--resolutions",
            "40x16,48x24",
            "--frames",
            "3",
            "--min-seconds",
            "0",
            "--json",
            str(path),
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "ms/frame" in out and "cxxrtl (trivial)" in out
    data = json.loads(path.read_text())
    rows = {(r["backend"], r["design"], r["width"]): r for r in data["results"]}
    assert set(rows) == {
        ("model", "follow_target", 40),
        ("model", "follow_target", 48),
        ("cxxrtl", "follow_target", 40),
        ("cxxrtl", "follow_target", 48),
        ("cxxrtl", "passthrough", 40),
        ("cxxrtl", "passthrough", 48),
    }
    for r in data["results"]:
        assert r["frames"] == 3 and r["ms_per_frame"] > 0
        # cycles per second is consistent with the frame's cycle count and time.
        assert r["cycles_per_second"] == pytest.approx(
            r["cycles_per_frame"] / (r["ms_per_frame"] / 1e3), rel=0.5
        )
    # The cycle count of a 40x16 frame is the pixel count plus the documented latency.
    assert rows[("cxxrtl", "passthrough", 40)]["cycles_per_frame"] == 40 * 16 + 1
    assert data["machine"]["cpus"] >= 1


def test_pysim_is_skipped_above_its_size_limit_with_a_note(capsys):
    bench.main(
        [
            "--backends",
            "pysim",
            "--resolutions",
            "48x24",
            "--frames",
            "1",
            "--pysim-max-pixels",
            "100",
            "--no-trivial",
        ]
    )
    assert "pysim skipped at 48x24" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--resolutions", "160by120"], "WIDTHxHEIGHT"),
        (["--backends", "iverilog"], "unknown backend"),
        (["--frames", "0"], "at least 1"),
        (["--backends", "model", "--resolutions", "44x16"], "divisible by 8"),
        (
            [
                "--backends",
                "model",
                "--resolutions",
                "40x16",
                "--json",
                "/nonexistent/b.json",
                "--frames",
                "1",
            ],
            "no directory",
        ),
    ],
)
def test_bad_options_are_usage_errors(argv, message):
    with pytest.raises(UsageError, match=message):
        bench.main(argv)
