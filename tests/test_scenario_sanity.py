"""Scenario warnings: placements and checks that make a run meaningless, found at load time.

Every expectation is worked out by hand from the geometry in the file: the desk spans
x 2.4..3.6, y 0.4..1.2; a person's radius is 0.2 m, the TurtleBot2's 0.177 m.
"""

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.cli.sweep import main as sweep_main
from fpga_robotics.scenario.load import load_scenario, shipped_scenarios

DESK = """
[[room.furniture]]
name = "desk"
center = [3.0, 0.8]
size = [1.2, 0.8]
"""


def _scenario(tmp_path, body, name="odd"):
    path = tmp_path / f"{name}.toml"
    path.write_text(f'name = "{name}"\n' + body)
    return path


def _person(waypoints, target=True, extra=""):
    points = ", ".join(f"[{x}, {y}]" for x, y in waypoints)
    return (
        f'[[people]]\nname = "p"\ntarget = {str(target).lower()}\n'
        f"waypoints = [{points}]\nloop = false\n{extra}"
    )


def _warnings(tmp_path, body):
    return list(load_scenario(_scenario(tmp_path, body)).warnings)


def test_a_waypoint_inside_furniture(tmp_path):
    body = DESK + _person([(5.0, 2.0), (3.1, 0.9)])
    assert _warnings(tmp_path, body) == [
        "people[0].waypoints[1] [3.1, 0.9] lies inside furniture 'desk'"
    ]


def test_a_waypoint_that_puts_the_person_into_furniture(tmp_path):
    # 0.15 m above the desk's far edge (y 1.2): closer than the person's radius.
    body = DESK + _person([(5.0, 2.0), (3.1, 1.35)])
    assert _warnings(tmp_path, body) == [
        ("people[0].waypoints[1] [3.1, 1.35] puts the person (radius 0.2 m) into furniture 'desk'")
    ]
    # 0.25 m away: clear.
    assert _warnings(tmp_path, DESK + _person([(5.0, 2.0), (3.1, 1.45)])) == []


def test_a_path_through_furniture(tmp_path):
    body = DESK + _person([(1.0, 0.8), (5.0, 0.8)])
    assert _warnings(tmp_path, body) == [
        "people[0].waypoints[0] -> [1] walks through furniture 'desk'"
    ]
    # Passing 0.3 m from the desk's edge (y 1.2 + 0.3): clear of it.
    assert _warnings(tmp_path, DESK + _person([(1.0, 1.5), (5.0, 1.5)])) == []


def test_a_looping_path_is_checked_on_its_way_back(tmp_path):
    # Out along y 2.0 and back diagonally from (5, 0.3) to (1, 2.0): the return leg crosses
    # the desk (at x 3.6 it is at y 0.3 + 1.7 * 0.35 = 0.9).
    body = DESK + _person([(1.0, 2.0), (5.0, 2.0), (5.0, 0.3)]).replace(
        "loop = false", "loop = true"
    )
    assert _warnings(tmp_path, body) == [
        "people[0].waypoints[2] -> [0] walks through furniture 'desk'"
    ]


def test_furniture_that_leaves_the_room_is_not_an_obstacle_to_paths(tmp_path):
    body = DESK + "present_until = 5.0\n" + _person([(1.0, 0.8), (5.0, 0.8)])
    assert _warnings(tmp_path, body) == []


def test_a_path_across_the_robots_start(tmp_path):
    robot = "[robot]\nstart = [1.5, 3.0]\n"
    # 0.3 m from the start: less than 0.2 + 0.177 m, the bodies would touch.
    assert _warnings(tmp_path, robot + _person([(0.5, 3.3), (4.0, 3.3)])) == [
        (
            "people[0].waypoints[0] -> [1] passes 0.30 m from robot.start [1.5, 3]: the person "
            "(radius 0.2 m) walks into the robot (radius 0.177 m) where it starts"
        )
    ]
    # 0.4 m: they pass clear of it.
    assert _warnings(tmp_path, robot + _person([(0.5, 3.4), (4.0, 3.4)])) == []
    # The same start by default: the warning says it is the default, which the file lacks.
    assert _warnings(tmp_path, _person([(0.5, 3.3), (4.0, 3.3)])) == [
        (
            "people[0].waypoints[0] -> [1] passes 0.30 m from the default robot.start (the "
            "scenario sets none) [1.5, 3]: the person (radius 0.2 m) walks into the robot "
            "(radius 0.177 m) where it starts"
        )
    ]
    # With yield_gap 0.3 the person stops 0.3 m short: 0.4 < 0.377 + 0.3 blocks them.
    yielding = _person([(0.5, 3.4), (4.0, 3.4)], extra="yield_gap = 0.3\n")
    assert _warnings(tmp_path, robot + yielding) == [
        (
            "people[0].waypoints[0] -> [1] passes 0.40 m from robot.start [1.5, 3]: the person "
            "(radius 0.2 m) is blocked by the robot (radius 0.177 m) where it starts: they wait "
            "(yield_gap 0.3 m) until it moves out of the way"
        )
    ]


def test_distance_checks_without_a_target(tmp_path):
    body = _person([(5.0, 3.0)], target=False) + (
        "[checks]\nmean_distance_max_m = 2.0\ntarget_in_view_min_fraction = 0.5\n"
    )
    assert _warnings(tmp_path, body) == [
        (
            "checks.mean_distance_max_m = 2 needs a target person (people[].target = true); the "
            "scenario has none: it always fails"
        ),
        (
            "checks.target_in_view_min_fraction = 0.5 needs a target person (people[].target = "
            "true); the scenario has none: it always fails"
        ),
    ]


def test_distance_checks_decided_by_the_bodies_and_the_room(tmp_path):
    person = _person([(5.0, 3.0)])
    # The centres touch at 0.2 + 0.177 = 0.377 m and are at most
    # hypot(8 - 0.377, 6 - 0.377) = 9.47 m apart in the default 8 m x 6 m room.
    assert _warnings(tmp_path, person + "[checks]\nmean_distance_max_m = 0.3\n") == [
        (
            "checks.mean_distance_max_m = 0.3 m is below 0.377 m, the robot's and the target's "
            "centres when they touch: it always fails"
        )
    ]
    assert _warnings(tmp_path, person + "[checks]\nmin_distance_min_m = 0.2\n") == [
        (
            "checks.min_distance_min_m = 0.2 m is below 0.377 m, the robot's and the target's "
            "centres when they touch: it always passes (use max_person_collisions for contact)"
        )
    ]
    assert _warnings(tmp_path, person + "[checks]\nmin_distance_min_m = 9.5\n") == [
        (
            "checks.min_distance_min_m = 9.5 m is beyond 9.47 m, the farthest the centres can be "
            "apart in the room: it always fails"
        )
    ]
    # Frame 0 is fixed by the file: the target stands at [5, 3], 3.5 m from the default start.
    assert _warnings(tmp_path, person + "[checks]\nmin_distance_min_m = 3.6\n") == [
        (
            "checks.min_distance_min_m = 3.6 m is beyond 3.50 m, the target's first waypoint "
            "from the default robot.start (the scenario sets none): it always fails"
        )
    ]
    assert (
        _warnings(
            tmp_path, person + "[checks]\nmin_distance_min_m = 3.4\nmean_distance_max_m = 0.4\n"
        )
        == []
    )


def test_an_override_is_checked_too(tmp_path):
    path = _scenario(tmp_path, DESK + _person([(5.0, 2.0), (5.0, 3.0)]))
    assert load_scenario(path).warnings == ()
    moved = load_scenario(path, ["people.0.waypoints=[[5.0, 2.0], [3.0, 1.0]]"])
    assert moved.warnings == ("people[0].waypoints[1] [3, 1] lies inside furniture 'desk'",)


@pytest.mark.parametrize("name", sorted(shipped_scenarios()))
def test_shipped_scenarios_load_without_warnings(name):
    assert load_scenario(name).warnings == ()


def _cli(main, argv, capsys, prog):
    with pytest.raises(SystemExit) as info:
        run_cli(main, argv, prog=prog)
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_run_prints_the_warnings_and_strict_refuses(tmp_path, capsys):
    path = _scenario(tmp_path, DESK + _person([(5.0, 2.0), (3.1, 0.9)]))
    code, out, err = _cli(
        run_main,
        ["--scenario", str(path), "--strict", "--rerun", "off", "--backend", "model"],
        capsys,
        "fpga-robotics run",
    )
    assert code == 2
    assert err == (
        "fpga-robotics run: error: scenario 'odd': people[0].waypoints[1] [3.1, 0.9] "
        "lies inside furniture 'desk' (--strict)\n"
    )
    assert out == ""
    code, out, err = _cli(
        run_main,
        [
            "--scenario",
            str(path),
            "--rerun",
            "off",
            "--quiet",
            "--backend",
            "model",
            "--duration",
            "0.2",
        ],
        capsys,
        "fpga-robotics run",
    )
    assert code in (0, 1)  # it ran
    assert err.splitlines()[0] == (
        "warning: scenario 'odd': people[0].waypoints[1] [3.1, 0.9] lies inside furniture 'desk'"
    )
    assert "verdict:" in out


def test_sweep_strict_refuses_before_any_run(tmp_path, capsys):
    path = _scenario(tmp_path, DESK + _person([(1.0, 0.8), (5.0, 0.8)]))
    code, out, err = _cli(
        sweep_main,
        ["--scenarios", str(path), "--seeds", "0-3", "--dry-run", "--strict"],
        capsys,
        "fpga-robotics sweep",
    )
    assert code == 2
    assert err == (
        "fpga-robotics sweep: error: scenario 'odd': people[0].waypoints[0] -> [1] "
        "walks through furniture 'desk' (--strict)\n"
    )
    code, out, err = _cli(
        sweep_main,
        ["--scenarios", str(path), "--seeds", "0-3", "--dry-run"],
        capsys,
        "fpga-robotics sweep",
    )
    assert code == 0
    # Four runs of one scenario: the warning once.
    assert err == (
        "warning: scenario 'odd': people[0].waypoints[0] -> [1] walks through furniture 'desk'\n"
    )
    assert "4 runs" in out
