"""The public test API (fpga_robotics.testing): a scenario run for a design reference, its
checks by name, a readable assertion message."""

import gc
import warnings
from pathlib import Path

import pytest

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.errors import UserError
from fpga_robotics.testing import run

DESIGNS = Path(__file__).parent / "data" / "user_designs"
#: The wall of wall_stop.toml (x = room width), the sensor's mount ahead of the centre.
WALL_X, SENSOR_FORWARD = 2.5, 0.1


@pytest.fixture(scope="module")
def slow_run():
    """wall_stop.toml at 450 DPS (its file says 300): the design's params from ``run``."""
    return run(DESIGNS / "wall_stop.toml", params={"speed": 450}, backend="cxxrtl")


def test_params_reach_the_design_and_the_checks_are_named(slow_run):
    traj = slow_run.trajectory
    assert traj["motor_left"][0] == 450 and traj["motor_left"][-1] == 0
    c = slow_run.check("max_wall_collisions")
    assert (c.status, c.value, c.limit) == ("pass", 0, 0)
    slow_run.assert_passes()
    # It stopped by its own rule: less than stop_mm (250) from the wall.
    assert 150 < 1000 * (WALL_X - traj["x"][-1] - SENSOR_FORWARD) < 250
    with pytest.raises(KeyError, match="its checks: max_wall_collisions"):
        slow_run.check("min_distance_min_m")


def test_a_failing_check_is_listed_in_the_assertion(tmp_path, monkeypatch):
    # A design reference relative to the current folder, a stop distance too short for the
    # braking: the robot hits the wall (0.5 m from it at 300 DPS; stop at 10 mm).
    monkeypatch.chdir(DESIGNS)
    result = run(
        "wall_stop.toml",
        design="wall_stop.py:WallStop",
        params={"stop_mm": 10, "speed": 600},
        overrides=["sim.duration=6", "robot.start=[1.8, 0.5]"],
    )
    assert result.check("max_wall_collisions").status == "fail"
    assert not result.passed
    with pytest.raises(AssertionError) as info:
        result.assert_passes()
    text = str(info.value)
    assert "1 of 1 checks not passed" in text and "[fail] max_wall_collisions" in text


def test_bad_arguments_are_one_line_errors():
    with pytest.raises(UsageError, match="takes no parameter 'nope'"):
        run(DESIGNS / "wall_stop.toml", params={"nope": 1})
    with pytest.raises(UsageError, match="needs ports="):
        run(DESIGNS / "wall_stop.toml", design="verilog:x.v")
    with pytest.raises(UsageError, match=r"got the string 'sim.duration=1'; write \['sim"):
        run(DESIGNS / "wall_stop.toml", overrides="sim.duration=1")
    # A Verilog design in place of the scenario's takes its own params: refused, not dropped.
    data = DESIGNS.parent
    with pytest.raises(UserError, match="the design bump_stop has no parameter 'speed' to set"):
        run(
            data / "bump_wall.toml",
            design=f"verilog:{data / 'bump_stop.v'}",
            ports=data / "bump_stop_ports.toml",
            params={"speed": 100},
        )


@pytest.mark.parametrize("scenario", ["red_frames.toml", "wall_stop.toml"])
def test_an_unknown_backend_is_refused_before_the_design_is_built(scenario):
    # It was a PinError (no UsageError) after the component was made, which Amaranth then
    # warned of as never elaborated.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(UsageError, match=r"unknown backend 'fast'; choose one of: auto, "):
            run(DESIGNS / scenario, backend="fast")
        gc.collect()
    assert [str(w.message) for w in caught] == []


def test_the_module_docstring_example_runs_as_written(tmp_path, monkeypatch):
    # The example an engineer copies into a test: the module's docstring, verbatim, beside the
    # wall_stop files of docs/your_design.md.
    import textwrap

    from fpga_robotics import testing

    lines = testing.__doc__.splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("    "))
    end = next(i for i in range(first, len(lines)) if lines[i] and not lines[i].startswith(" "))
    example = textwrap.dedent("\n".join(lines[first:end]))
    assert "def test_stops_before_the_wall" in example
    for name in ("wall_stop.py", "wall_stop.toml"):
        (tmp_path / name).write_text((DESIGNS / name).read_text())
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(example, "fpga_robotics.testing docstring", "exec"), namespace)  # noqa: S102
    namespace["test_stops_before_the_wall"]()


@pytest.mark.parametrize("seed", ["1", 1.5, 2.0, True, -1])
def test_a_seed_that_is_not_a_whole_number_is_refused(seed):
    # int() would have run seed 1 for "1", 1.5 and True: another run than asked for.
    with pytest.raises(ValueError, match=r"seed must be a non-negative integer, got "):
        run(DESIGNS / "wall_stop.toml", seed=seed, backend="model")


PYTHON_PARAMS = """
import enum

from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Mode(enum.Enum):
    FORWARD = 1
    REVERSE = -1


class Lim(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def __init__(self, limit=None, gains: dict = None, mode: Mode = Mode.FORWARD):
        left = 300 if limit is None else limit
        right = 100 * gains["kp"] if gains is not None else 0
        self.speeds = left * mode.value, right * mode.value
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.motor_left.eq(self.speeds[0]), self.motor_right.eq(self.speeds[1])]
        return m
"""

BARE = """
people = []
[sim]
duration = 0.1
clock_hz = 100000.0
[room]
width = 2.5
depth = 1.0
[robot]
model = "gopigo3"
start = [0.5, 0.5]
"""


def test_params_from_python_reach_the_design_as_given(tmp_path, monkeypatch):
    # None, a dict and an enum member (of the user's own import of the design's file) are
    # keyword arguments as they are: no text on the way ("null", a JSON string).
    import importlib.util

    (tmp_path / "lim.py").write_text(PYTHON_PARAMS)
    (tmp_path / "bare.toml").write_text(BARE)
    monkeypatch.chdir(tmp_path)
    spec = importlib.util.spec_from_file_location("users_lim", tmp_path / "lim.py")
    users_lim = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(users_lim)
    result = run(
        "bare.toml",
        design="lim.py:Lim",
        params={"limit": None, "gains": {"kp": 2}, "mode": users_lim.Mode.REVERSE},
        backend="pysim",
    )
    assert (result.trajectory["motor_left"][-1], result.trajectory["motor_right"][-1]) == (
        -300,
        -200,
    )
    with pytest.raises(UsageError, match=r"params must be a dict .*, got \['limit'\]"):
        run("bare.toml", design="lim.py:Lim", params=["limit"])
