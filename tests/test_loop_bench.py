"""The closed-loop breakdown: every step timed, the parts adding up to the whole run."""

import pytest

from fpga_robotics.bench import loop as loop_bench
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.scenario.load import load_scenario


@pytest.mark.parametrize("backend", ["model", "cxxrtl"])
def test_the_steps_add_up_to_the_whole_loop(backend):
    scenario = load_scenario("follow_person", ["sim.duration=1.0"])
    with make_backend(backend, scenario.params) as design:
        m = loop_bench.measure(scenario, design, repeats=1)
    steps = m["steps_ms"]
    assert set(steps) == set(loop_bench.STEPS)
    assert m["frames"] == 30
    # Each median is one run's: the parts are that run's whole, to rounding.
    assert sum(steps.values()) == pytest.approx(m["loop_ms"], rel=1e-9)
    for key in ("loop", "render", "physics", "measure", "record", "other"):
        assert steps[key] > 0, key
    assert steps["finish"] >= 0
    # The harness backends split the design's time; the model has no C++ loop to split.
    split = steps["handover"] > 0 and steps["results"] > 0
    assert split == (backend == "cxxrtl")
    # One simulated second: the real-time factor is 1000 / the milliseconds of 30 frames.
    assert m["realtime"] == pytest.approx(1.0 / (m["plain_ms"] * 30 / 1e3), rel=1e-9)
    assert 0 < m["plain_cpu_ms"] <= m["plain_ms"] * 1.05
    assert m["cpu_realtime"] == pytest.approx(1.0 / (m["plain_cpu_ms"] * 30 / 1e3), rel=1e-9)
    assert 0 < m["design_alone_ms"] < m["plain_ms"]
    assert 0 < m["design_alone_cpu_ms"] < m["plain_cpu_ms"]


def test_the_command_prints_the_breakdown_and_a_profile(capsys):
    assert (
        loop_bench.main(
            [
                "--backend",
                "model",
                "--resolutions",
                "160x120",
                "--duration",
                "0.5",
                "--repeats",
                "1",
                "--profile",
                "5",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    for label in loop_bench.STEPS.values():
        assert label in out
    assert "the loop as users run it (no timers, no records)" in out
    for what in (
        "the timed run against the design's time in it",
        "the loop against the design alone, wall clock",
        "the loop against the design alone, CPU time",
    ):
        assert f"{what}: whole " in out and "(target 160x120: <= 2.2x, <= 1.2x)" in out
    assert "function calls" in out and "tottime" in out


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--repeats", "0"], "--repeats"),
        (["--duration", "nan"], "--duration"),
        (["--profile", "-1"], "--profile"),
        (["--resolutions", "160by120"], "WIDTHxHEIGHT"),
    ],
)
def test_bad_options_are_usage_errors(argv, message):
    with pytest.raises(UsageError, match=message):
        loop_bench.main(argv)


def test_the_shadow_bench_names_the_backend_that_ran(monkeypatch, capsys):
    from fpga_robotics.bench import shadow as shadow_bench

    # "auto" is the fastest backend here: the header names it, not "auto".
    monkeypatch.setattr(shadow_bench, "fastest_backend_name", lambda: "model")
    assert shadow_bench.main(["--backend", "auto", "--duration", "0.2", "--repeats", "1"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("follow_person, model backend, shadow diff_min=5"), first
