"""Mutants from Yosys's ``mutate`` pass (sim/mutation.py): the list is fixed by the seed, each
mutant names its component and Python line, and the one netlist holding all of them is the
design itself with ``mutsel = 0`` (bit for bit against the model) and a mutant with
``mutsel = k``."""

import re

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim import mutation
from fpga_robotics.sim.backends import get_backend

PARAMS = FollowTargetParams(width=80, height=60)
MODULES = {
    "",
    "color_filter",
    "motor",
    "tracker",
    "tracker.counter",
    "tracker.results",
    "tracker.results.divider",
}

try:
    mutation.find_yosys()
    NO_YOSYS = None
except mutation.MutationError as exc:  # pragma: no cover - depends on the machine
    NO_YOSYS = str(exc)
pytestmark = pytest.mark.skipif(NO_YOSYS is not None, reason=str(NO_YOSYS))


@pytest.fixture(scope="module")
def mutants():
    return mutation.list_mutants(PARAMS, 40, seed=7)


@pytest.fixture(scope="module")
def netlist(mutants):
    return mutation.mutant_netlist(PARAMS, mutants)


def test_the_seed_fixes_the_list(mutants):
    again = mutation.list_mutants(PARAMS, 40, seed=7)
    assert [m.command for m in again] == [m.command for m in mutants]
    other = mutation.list_mutants(PARAMS, 40, seed=8)
    assert [m.command for m in other] != [m.command for m in mutants]
    assert [m.index for m in mutants] == list(range(1, 41))


def test_each_mutant_names_its_component_and_python_line(mutants):
    assert {m.mode for m in mutants} <= {"inv", "const0", "const1", "cnot0", "cnot1"}
    assert {m.module for m in mutants} <= MODULES
    assert len({m.module for m in mutants}) >= 3  # spread over the design
    # Cells that Yosys made itself (process multiplexers) carry no source line.
    assert sum(bool(m.sources) for m in mutants) >= 0.8 * len(mutants)
    for m in mutants:
        assert all(":" in s and not s.startswith("/") for s in m.sources), m.sources
        if m.mode.startswith("cnot"):
            assert m.ctrlbit is not None
        text = m.describe()
        assert text.startswith(f"#{m.index} ") and (m.module or "top") in text
    # Most places are in this project's gateware, named as in the repository.
    ours = [m for m in mutants if any(s.startswith("hw/") for s in m.sources)]
    assert len(ours) >= 30


def test_parse_a_known_line():
    line = (
        "mutate -mode cnot1 -module follow_target -cell $flatten\\tracker.\\results.$331 "
        "-port Y -portbit 3 -ctrlbit 7 -wire \\tracker.results.quotient -wirebit 2 "
        "-src /x/fpga_robotics/hw/tracker.py:226 -src /x/fpga_robotics/hw/tracker.py:226"
    )
    m = mutation._parse(5, line)
    assert (m.index, m.mode, m.module, m.port, m.portbit, m.ctrlbit) == (
        5,
        "cnot1",
        "tracker.results",
        "Y",
        3,
        7,
    )
    assert (m.signal, m.bit) == ("tracker.results.quotient", 2)
    assert m.describe() == (
        "#5 tracker.results: tracker.results.quotient[2] XOR Y[7] "
        "(/x/fpga_robotics/hw/tracker.py:226)"
    )
    assert mutation.select_width(1) == 1 and mutation.select_width(40) == 6
    assert mutation.select_width(63) == 6 and mutation.select_width(64) == 7


def test_a_cnot_mutant_is_described_as_the_gate_yosys_puts_in(mutants, netlist):
    """The netlist's watch bit of mutant k is ``own ^ faulty``; the faulty value is the own
    bit XNORed (``~^``, Yosys's cnot0) or XORed (``^``, cnot1) with the control bit: the
    description must name that gate."""
    cnots = [m for m in mutants if m.mode.startswith("cnot")]
    assert {m.mode for m in cnots} == {"cnot0", "cnot1"}
    for m in cnots:
        watch = re.search(rf"assign mutinf\[{m.index - 1}\] = (.+) \^ (\S+);", netlist)
        own, faulty = watch.groups()
        gate = re.search(rf"assign {re.escape(faulty)} = {re.escape(own)} (~\^|\^) ", netlist)
        name = {"~^": "XNOR", "^": "XOR"}[gate.group(1)]
        assert f" {name} {m.port}[{m.ctrlbit}] " in m.describe(), (m.command, gate.group(0))


def test_the_netlist_has_a_select_input_per_mutant(netlist):
    assert "module follow_target(" in netlist
    assert "input [5:0] mutsel;" in netlist
    # One comparison of mutsel per mutant (mutate -ctrl).
    assert sum(f"mutsel == 6'h{k:02x}" in netlist for k in range(1, 41)) == 40


def _toolchain():
    from fpga_robotics.sim.backends import BackendError
    from fpga_robotics.sim.backends import toolchain as tc

    try:
        tc.find_compiler(), tc.find_make(), tc.verilator_root()
    except BackendError as exc:  # pragma: no cover - depends on the machine
        return str(exc)
    return None


def test_no_mutant_sits_on_a_clock_input():
    """Yosys lists places on flip-flops' clocks (seed 2 at 80x60: #34, the clock of
    tracker.counter.active inverted); the list leaves them out, the rest in Yosys's order."""
    design = {
        "rtlil_text": None,
        "verilog": None,
        "top": mutation.TOP_NAME,
        "includes": None,
        "overrides": None,
    }
    lines, _, _ = mutation._mutate_list(PARAMS, 40, 2, design)
    clocked = [k for k, line in enumerate(lines) if " -port CLK " in line]
    assert clocked, "seed 2's first 40 places have a clock"
    listed = mutation.list_mutants(PARAMS, 40, seed=2)
    assert len(listed) == 40 and not any(m.port == "CLK" for m in listed)
    others = [line for line in lines if " -port CLK " not in line]
    assert [m.command for m in listed][: len(others)] == others


@pytest.mark.skipif(_toolchain() is not None, reason="no Verilator toolchain")
@pytest.mark.slow
def test_the_netlist_of_a_seed_with_a_clock_place_is_the_design_at_mutsel_0(tmp_path):
    """With a clock place among them, the mutants' select mux delayed that flip-flop's clock
    at every mutsel: the netlist at mutsel 0 timed out on the first unit frame, and every
    mutant was caught."""
    from fpga_robotics.loop.shadow import differing_outputs
    from fpga_robotics.mutation.design import open_mutant_design, write_mutant_design
    from fpga_robotics.mutation.unit_judge import golden_results, judge_frames, reference_results

    netlist, ports = write_mutant_design(PARAMS, mutation.list_mutants(PARAMS, 40, 2), tmp_path)
    frames = judge_frames(PARAMS)[:12]
    design = open_mutant_design(PARAMS, netlist, ports)
    try:
        got = reference_results(design, frames)
    finally:
        design.close()
    for k, (g, w) in enumerate(zip(got, golden_results(PARAMS, frames), strict=True)):
        assert not differing_outputs(w, g), k


@pytest.mark.skipif(_toolchain() is not None, reason="no Verilator toolchain")
@pytest.mark.slow
def test_one_build_runs_the_design_and_each_mutant(tmp_path):
    """``mutsel`` as a ``[runtime]`` input of the port map: one compiled model, the mutant
    chosen between runs. Select 0 is the design bit for bit; a stuck-at-1 on the filtered
    payload shows exactly as computed by hand; back at 0 it is the design again."""
    from fpga_robotics.sim.backends import BackendError
    from fpga_robotics.sim.backends.foreign import ForeignVerilatorBackend
    from fpga_robotics.sim.backends.port_map import follow_target_port_map

    listed = mutation.list_mutants(PARAMS, 400, seed=1)
    stuck = next(
        (m for m in listed if m.signal == "filtered__payload" and m.mode == "const1"), None
    )
    assert stuck is not None, "no stuck-at-1 on the filtered payload among 400 mutants"
    others = [m for m in listed if m is not stuck][:5]
    (tmp_path / "m.v").write_text(mutation.mutant_netlist(PARAMS, [stuck, *others]))
    (tmp_path / "pm.toml").write_text(follow_target_port_map(PARAMS) + "\n[runtime]\nmutsel = 0\n")
    rng = np.random.default_rng(3)
    frames = [rng.integers(0, 256, (60, 80, 3), dtype=np.uint8) for _ in range(2)]
    red = np.zeros((60, 80, 3), np.uint8)
    red[10:40, 20:45] = (220, 30, 30)
    frames.append(red)
    model = get_backend("model", PARAMS)
    want = [model.process_frame(f) for f in frames]
    design = ForeignVerilatorBackend(
        PARAMS, files=[tmp_path / "m.v"], port_map=tmp_path / "pm.toml"
    )

    def run(select):
        design.set_runtime("mutsel", select)
        design.reset()
        return [design.process_frame(f) for f in frames]

    try:
        assert run(0) == want
        # The mutant, by hand: every pixel of the filtered stream (the pixel where it matched,
        # 0 elsewhere) has its payload bit forced to 1; the tracker's outputs are untouched.
        assert (want[2].filtered != 0).any()
        for g, w in zip(run(stuck.index), want):
            np.testing.assert_array_equal(g.filtered, w.filtered | (1 << stuck.bit))
            assert g.outputs() == w.outputs()
        assert run(0) == want
        # The unit judge on the same build: the design itself is not "caught", the stuck
        # payload bit is, on the first frame (every filtered pixel changes).
        from fpga_robotics.mutation.unit_judge import golden_results, judge_frames, judge_mutant

        unit_frames = judge_frames(PARAMS)
        golden = golden_results(PARAMS, unit_frames)
        assert not judge_mutant(design, 0, unit_frames, golden).caught
        v = judge_mutant(design, stuck.index, unit_frames, golden)
        assert v.caught and v.first_frame == 0 and v.differing["filtered"] == len(unit_frames)
        assert v.differing["found"] == 0 and "filtered" in v.effect()
        with pytest.raises(BackendError, match="the value must be 0..7"):
            design.set_runtime("mutsel", 8)
        with pytest.raises(BackendError, match="no \\[runtime\\] input 'mode'"):
            design.set_runtime("mode", 1)
    finally:
        design.close()


# The judges and the scores --------------------------------------------------------------------


def test_scores_by_hand():
    from fpga_robotics.mutation.scores import blind_spots, by_module, robot_score, unit_score

    # Six mutants: the unit judge catches 1, 2, 3, 5; the robot judge ran 1, 2, 3, 4 and
    # caught 1 and 4 (4 is not unit-caught: it does not count in the robot score).
    unit = {1: True, 2: True, 3: True, 4: False, 5: True, 6: False}
    robot = {1: True, 2: False, 3: False, 4: True}
    assert unit_score(unit) == {"total": 6, "caught": 4, "equivalent": 2, "score": 4 / 6}
    assert robot_score(unit, robot) == {"judged": 3, "caught": 1, "score": 1 / 3}
    assert blind_spots(unit, robot) == [2, 3]
    assert unit_score({}) == {"total": 0, "caught": 0, "equivalent": 0, "score": None}

    def m(i, module):
        return mutation.Mutant(i, "inv", module, "$1", "Y", 0, None, None, None, (), "")

    mods = by_module([m(1, "motor"), m(2, "motor"), m(3, ""), m(5, "motor")], unit, robot)
    assert mods == {
        "motor": {"total": 3, "unit_caught": 3, "robot_caught": 1},
        "top": {"total": 1, "unit_caught": 1, "robot_caught": 0},
    }


def test_the_closest_run_is_the_one_nearest_a_limit_either_way():
    from fpga_robotics.checks.registry import register_check, unregister_check
    from fpga_robotics.mutation.robot_judge import closest_to_failing, run_margin

    def run(**checks):
        rows = [
            {"name": n, "passed": True, "value": v, "limit": limit}
            for n, (v, limit) in checks.items()
        ]
        return {"status": "pass", "summary": {"checks": rows}}

    # At least the limit: 0.95 of 0.8 is 0.15/0.8 from failing, 0.81 is 0.01/0.8.
    far = run(camera_target_centred_min_fraction=(0.95, 0.8), max_wall_collisions=(0, 1))
    near = run(camera_target_centred_min_fraction=(0.81, 0.8), max_wall_collisions=(0, 1))
    assert run_margin(far["summary"]) == pytest.approx(0.15 / 0.8)
    assert run_margin(near["summary"]) == pytest.approx(0.01 / 0.8)
    assert closest_to_failing([far, near]) == 1
    # At most the limit: 2 collisions of 3 allowed is 1/3 from failing.
    assert run_margin(run(max_wall_collisions=(2, 3))["summary"]) == pytest.approx(1 / 3)
    # A check of the user's own, and one of a name no longer registered (no direction).
    register_check(
        name="min_user_laps", metric="laps", compare="min", meaning="m", message=lambda *a: ""
    )
    try:
        assert run_margin(run(min_user_laps=(12, 10))["summary"]) == pytest.approx(0.2)
    finally:
        unregister_check("min_user_laps")
    assert run_margin(run(min_user_laps=(12, 10))["summary"]) is None


def test_bad_arguments_are_one_line_errors(tmp_path, monkeypatch):
    import subprocess
    import sys

    def run(*argv, env=None):
        return subprocess.run(
            [sys.executable, "-m", "fpga_robotics.mutation", *argv],
            check=False,
            capture_output=True,
            text=True,
            timeout=120,
            env=env,
        )

    for argv, message in (
        (["--mutants", "0"], "--mutants must be 1..4000, got 0"),
        (["--seed", "-1"], "--seed must be 0..2147483647, got -1"),
        # Yosys reads the seed into a C int: 2**32 + 1 would give seed 1's mutants.
        (["--seed", "4294967297"], "--seed must be 0..2147483647, got 4294967297"),
        (["--width", "33"], "bad design parameter"),
    ):
        r = run(*argv, "--out", str(tmp_path / "o"))
        assert r.returncode == 2 and message in r.stderr and "Traceback" not in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1
    import os

    r = run(
        "--mutants", "3", "--out", str(tmp_path / "o"), env={**os.environ, "YOSYS": "no-such-yosys"}
    )
    assert r.returncode == 2 and "YOSYS='no-such-yosys' is not an executable" in r.stderr
    assert not (tmp_path / "o" / "mutants.json").exists()


@pytest.mark.skipif(_toolchain() is not None, reason="no Verilator toolchain")
@pytest.mark.slow
def test_a_mutant_runs_in_closed_loop_from_the_command_line(tmp_path, capsys):
    """``run --design verilog:mutants.v --ports mutants_ports.toml --runtime mutsel=K``: the
    select 0 is the design (the same run as the built-in Verilator backend); the stuck filtered
    bit changes no output the robot acts on, so the robot's run is the same too: a mutant that
    only the unit judge sees."""
    import json

    from fpga_robotics.cli import run
    from fpga_robotics.mutation.design import write_mutant_design

    listed = mutation.list_mutants(PARAMS, 400, seed=1)
    stuck = next(m for m in listed if m.signal == "filtered__payload" and m.mode == "const1")
    netlist, ports = write_mutant_design(
        PARAMS, [stuck, *[m for m in listed if m is not stuck][:5]], tmp_path
    )
    common = [
        "--scenario",
        "follow_person",
        "--resolution",
        "80x60",
        "--duration",
        "2",
        "--rerun",
        "off",
        "--quiet",
    ]
    summaries = {}
    for name, extra in (
        ("builtin", ["--backend", "verilator"]),
        ("select0", ["--design", f"verilog:{netlist}", "--ports", ports, "--runtime", "mutsel=0"]),
        (
            "stuck",
            [
                "--design",
                f"verilog:{netlist}",
                "--ports",
                ports,
                "--runtime",
                f"mutsel={stuck.index}",
            ],
        ),
    ):
        path = tmp_path / f"{name}.json"
        assert run.main([*common, *extra, "--summary", str(path)]) in (0, 1)
        summaries[name] = json.loads(path.read_text())
    capsys.readouterr()
    keys = (
        "frames",
        "min_distance_m",
        "mean_distance_m",
        "found_fraction",
        "path_length_m",
        "collisions",
        "verdict",
        "max_wheel_command_step_dps",
    )
    for name in ("select0", "stuck"):
        assert summaries[name]["backend"] == "verilator-foreign"
        assert {k: summaries[name][k] for k in keys} == {k: summaries["builtin"][k] for k in keys}


@pytest.mark.skipif(_toolchain() is not None, reason="no Verilator toolchain")
@pytest.mark.slow
def test_the_robot_judge_catches_a_wheel_bug_and_not_a_filtered_image_bug(tmp_path):
    """Two mutants judged by hand: the filtered stream's bit stuck at 1 changes nothing the
    robot acts on (a blind spot: the unit judge alone sees it); bit 12 of the left wheel's
    command inverted adds 4096 DPS to it (clamped to the motor's top speed): the robot spins
    and the runs fail. One Dask worker; resumed, nothing runs again."""
    import json

    from fpga_robotics.mutation.design import write_mutant_design
    from fpga_robotics.mutation.robot_judge import robot_judge
    from fpga_robotics.mutation.scores import blind_spots, robot_score
    from fpga_robotics.sweep import load_campaign

    listed = mutation.list_mutants(PARAMS, 3000, seed=1)
    stuck = next(m for m in listed if m.signal == "filtered__payload" and m.mode == "const1")
    wheel = next(m for m in listed if (m.signal, m.bit, m.mode) == ("motor_left", 12, "inv"))
    chosen = [mutation.Mutant(**{**m.__dict__, "index": i}) for i, m in ((1, stuck), (2, wheel))]
    netlist, ports = write_mutant_design(PARAMS, chosen, tmp_path)
    campaign = load_campaign(
        {"name": "tiny", "scenarios": ["follow_person"], "seeds": "0-1", "duration": 4.0}
    )
    baseline, verdicts = robot_judge(
        campaign, netlist, ports, "80x60", [1, 2], str(tmp_path), workers=1, say=lambda text: None
    )
    assert baseline["passing"] == [0, 1] and len(baseline["runs"]) == 2
    assert baseline["judged_here"] == 2
    assert "--runtime mutsel=0" in " ".join(baseline["runs"][0])
    assert verdicts[1]["caught"] is False and verdicts[1]["runs"] == 2
    assert verdicts[2]["caught"] is True and verdicts[2]["run"] == 0
    assert verdicts[2]["status"] == "fail" and verdicts[2]["failed_checks"]
    assert verdicts[2]["replay"].endswith("--runtime mutsel=2")
    unit = {1: True, 2: True}
    robot = {k: v["caught"] for k, v in verdicts.items()}
    assert robot_score(unit, robot) == {"judged": 2, "caught": 1, "score": 0.5}
    assert blind_spots(unit, robot) == [1]
    lines = (tmp_path / "robot.jsonl").read_text().splitlines()
    assert sorted(json.loads(line)["index"] for line in lines) == [1, 2]
    _again, resumed = robot_judge(
        campaign,
        netlist,
        ports,
        "80x60",
        [1, 2],
        str(tmp_path),
        workers=1,
        resume=True,
        say=lambda text: None,
    )
    assert {k: v["caught"] for k, v in resumed.items()} == robot
    assert _again["judged_here"] == 0
    assert (tmp_path / "robot.jsonl").read_text().splitlines() == lines
