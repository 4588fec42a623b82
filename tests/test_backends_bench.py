"""The benchmark CLI: figures printed and written, bad options as clear errors."""

import json

import pytest

from fpga_robotics.bench import design as bench
from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError


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
    written = json.loads(path.read_text())
    assert written["command"] == "fpga-robotics bench design"
    data = written["figures"]
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
    # Compiled rows split the call: the C++ loop (timed in the harness) and the rest. Each
    # frame's loop is inside its call, so the medians keep that order.
    for key, r in rows.items():
        if key[0] == "cxxrtl":
            assert 0 < r["loop_ms_per_frame"] <= r["ms_per_frame"]
            assert r["python_us_per_frame"] > 0
        else:
            assert "loop_ms_per_frame" not in r
    assert "process_frame(RGB888 frame) as users call it" in out and "C++ loop" in out
    # The cycle count of a 40x16 frame is the pixel count plus the documented latency.
    assert rows[("cxxrtl", "passthrough", 40)]["cycles_per_frame"] == 40 * 16 + 1
    assert written["machine"]["cpus"] >= 1
    # FollowTarget against the trivial design, frames in alternation, per size.
    assert {(r["backend"], r["width"]) for r in data["paired"]} == {("cxxrtl", 40), ("cxxrtl", 48)}
    for r in data["paired"]:
        assert r["frames"] + r["preempted"] == 3 and 0 < r["fraction"] < 10
    assert "of the trivial design's cycle rate (alternating frames, " in out


class _FakeBackend:
    """A backend that takes a known time per frame, on a fake clock, for a known cycle count."""

    def __init__(self, clock, cycles, seconds):
        self.clock, self.cycles, self.seconds = clock, cycles, seconds

    def process_frame(self, frame):
        from types import SimpleNamespace

        self.clock.now += self.seconds
        self.clock.cpu += self.seconds
        self.calls = getattr(self, "calls", 0) + 1
        if self.calls % 3 == 0 and getattr(self, "preempt", False):
            self.clock.now += 10 * self.seconds  # waited for a core: wall time only
        return SimpleNamespace(cycles=self.cycles)


class _FakeClock:
    """Wall clock and thread CPU time; ``lost`` seconds of wall time pass without the thread
    running during every ``lose_every``-th reading pair (another job took the core)."""

    now = 0.0
    cpu = 0.0

    def perf_counter(self):
        return self.now

    def thread_time(self):
        return self.cpu


def test_summary_takes_the_fraction_from_the_paired_measurement():
    def row(design, ms, rate):
        return {
            "backend": "cxxrtl",
            "design": design,
            "width": 160,
            "height": 120,
            "ms_per_frame": ms,
            "cycles_per_second": rate,
        }

    results = [row("follow_target", 0.3, 60e6), row("passthrough", 0.1, 180e6)]
    separate = bench.summary(results)
    assert any("0.33 of the trivial" in line and "MISSED" in line for line in separate)
    paired = [{"backend": "cxxrtl", "width": 160, "height": 120, "fraction": 0.55, "frames": 9}]
    lines = bench.summary(results, paired)
    assert any(
        "0.55 of the trivial" in line and "alternation" in line and line.endswith("met")
        for line in lines
    )
    assert any("0.3" in line and "<= 0.4 ms: met" in line for line in lines)


def test_target_lines_never_round_a_figure_onto_its_limit():
    def row(design, ms, rate):
        return {
            "backend": "cxxrtl",
            "design": design,
            "width": 160,
            "height": 120,
            "ms_per_frame": ms,
            "cycles_per_second": rate,
        }

    # 0.498 of the trivial rate misses 0.5; 0.40002 ms misses 0.4 ms; 0.5 exactly meets it.
    lines = bench.summary([row("follow_target", 0.40002, 49.8e6), row("passthrough", 0.1, 100e6)])
    assert any("0.498 of the trivial" in line and line.endswith("MISSED") for line in lines)
    assert any("0.40002 ms <= 0.4 ms: MISSED" in line for line in lines)
    lines = bench.summary([row("follow_target", 0.3, 50e6), row("passthrough", 0.1, 100e6)])
    assert any("0.50 of the trivial" in line and line.endswith("met") for line in lines)


@pytest.mark.parametrize(
    "value, limit, decimals, shown",
    [
        (4.497964, 4.5, 2, "4.498"),  # under the limit: never "4.50"
        (4.5, 4.5, 2, "4.50"),  # on it
        (4.5004, 4.5, 2, "4.5004"),  # over it
        (4.43, 4.5, 2, "4.43"),  # clear of it: as asked
        (999.6, 1000.0, 0, "999.6"),
    ],
)
def test_figure_against_a_limit_keeps_its_side(value, limit, decimals, shown):
    assert scaffold.figure_against(value, limit, decimals) == shown


def test_paired_measurement_gives_the_ratio_of_cycle_rates(monkeypatch):
    # 1000 cycles in 4 ms against 1000 cycles in 2 ms: half the rate (on a fake clock, so
    # the machine's load cannot move the figure).
    clock = _FakeClock()
    monkeypatch.setattr(bench, "time", clock)
    design, trivial = _FakeBackend(clock, 1000, 0.004), _FakeBackend(clock, 1000, 0.002)
    figures = bench.measure_paired(design, trivial, frames=[None] * 5, min_seconds=0.0)
    assert figures["frames"] == 5 and figures["preempted"] == 0
    assert figures["fraction"] == pytest.approx(0.5) and figures["clock"] == "wall"


def test_paired_measurement_leaves_out_preempted_pairs(monkeypatch):
    # Every third call of the design waits for a core (10x its time, wall clock only): those
    # pairs are left out and the fraction stays the machine-independent one.
    clock = _FakeClock()
    monkeypatch.setattr(bench, "time", clock)
    design, trivial = _FakeBackend(clock, 1000, 0.004), _FakeBackend(clock, 1000, 0.002)
    design.preempt = True
    figures = bench.measure_paired(design, trivial, frames=[None] * 9, min_seconds=0.0)
    # The warm-up call is the first; calls 3, 6, 9 of the design fall in pairs 2, 5, 8.
    assert figures["preempted"] == 3 and figures["frames"] == 6
    assert figures["fraction"] == pytest.approx(0.5) and figures["clock"] == "wall"
    # When every call waits, both sides are timed by CPU time, still the same fraction.
    design.calls = trivial.calls = 0
    design.preempt = trivial.preempt = True
    monkeypatch.setattr(design, "process_frame", _always_preempted(design))
    figures = bench.measure_paired(design, trivial, frames=[None] * 4, min_seconds=0.0)
    assert figures["clock"] == "cpu" and figures["frames"] == 4
    assert figures["fraction"] == pytest.approx(0.5)


def _always_preempted(backend):
    inner = backend.process_frame

    def process_frame(frame):
        result = inner(frame)
        backend.clock.now += 5 * backend.seconds
        return result

    return process_frame


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
        (["--frames", "0"], "--frames must be 1..1000000"),
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


def test_published_needs_its_five_files(tmp_path):
    (tmp_path / "design_top.v").write_text("module design_top; endmodule\n")
    with pytest.raises(
        UsageError,
        match=r"no centroid.v, color_proc.v, frame_buffer.v, "
        r"motor_ctrl_spi.v there",
    ):
        bench.main(["--published", str(tmp_path), "--backends", "model"])
