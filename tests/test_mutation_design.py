"""Mutation coverage of a design of one's own (``fpga-robotics mutate --design REF``): each
Yosys mutant against the unmutated design on seeded random pin stimulus, cycle by cycle.

The independent expectation is a Python model of ``Saturating`` (tests/data/user_designs/
counters.py): the unmutated netlist's trace must be the model's, and a mutant is caught
exactly when its trace differs from the model's."""

import html
import json
import re
from pathlib import Path

import pytest
from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from fpga_robotics import cli
from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.mutation.design_run import design_ports
from fpga_robotics.mutation.pin_judge import (
    MutantPinSource,
    judge_pin_mutant,
    open_pin_mutants,
    pin_stimulus,
    pin_trace,
)
from fpga_robotics.sim.mutation import component_rtlil, list_mutants

DESIGNS = Path(__file__).parent / "data" / "user_designs"
LIMIT, CYCLES = 10, 3000


def model_trace(stimulus, cycles, limit=LIMIT):
    """Saturating by hand: ``{output: [(cycle, value), ...]}`` as ``pin_trace`` records it.
    An input scheduled for edge e is what the design samples at edge e."""
    by_edge = {}
    for edge, name, value in stimulus:
        by_edge.setdefault(edge, {})[name] = value
    inputs, count = {"up": 0, "clear": 0}, 0
    trace = {"count": [(0, 0)], "full": [(0, 0)]}
    for edge in range(1, cycles + 1):
        inputs.update(by_edge.get(edge, {}))
        if inputs["clear"]:
            count = 0
        elif inputs["up"] and count < limit:
            count += 1
        for name, value in (("count", count), ("full", int(count == limit))):
            if trace[name][-1][1] != value:
                trace[name].append((edge, value))
    return trace


@pytest.fixture(scope="module")
def saturating():
    spec = resolve_design(f"{DESIGNS}/counters.py:Saturating")
    ports = design_ports(spec)
    rtlil_text = component_rtlil(spec.build())
    mutants = list_mutants(None, 40, 3, rtlil_text=rtlil_text)
    backend = open_pin_mutants(MutantPinSource(rtlil_text, ports, mutants, "Saturating"))
    yield ports, mutants, backend
    backend.close()


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_the_unmutated_netlist_runs_as_the_model(saturating):
    ports, _, backend = saturating
    stimulus = pin_stimulus(ports, CYCLES, seed=0)
    assert {name for _, name, _ in stimulus} == {"up", "clear"}
    assert stimulus == pin_stimulus(ports, CYCLES, seed=0)  # seeded
    want = model_trace(stimulus, CYCLES)
    assert len(want["full"]) > 4  # the stimulus fills the counter and clears it, repeatedly
    assert pin_trace(backend, 0, stimulus, CYCLES, ["count", "full"]) == want


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_mutant_is_caught_exactly_when_it_departs_from_the_model(saturating):
    ports, mutants, backend = saturating
    stimulus = pin_stimulus(ports, CYCLES, seed=1)
    model = model_trace(stimulus, CYCLES)
    reference = pin_trace(backend, 0, stimulus, CYCLES, ["count", "full"])
    caught = 0
    for m in mutants:
        verdict = judge_pin_mutant(backend, m.index, stimulus, CYCLES, reference)
        departs = pin_trace(backend, m.index, stimulus, CYCLES, ["count", "full"]) != model
        assert verdict.caught == departs, m.describe()
        caught += verdict.caught
        if verdict.caught:  # the first difference is where the mutant's values part
            for was, now in verdict.first_difference.values():
                assert was != now
    assert caught > 0


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_mutate_design_prints_the_scores_of_a_users_design(tmp_path, capsys):
    out = tmp_path / "m"
    code, text, _ = _cli(
        [
            "mutate",
            "--design",
            f"{DESIGNS}/wall_stop.py:WallStop",
            "--param",
            "clock_hz=100000",
            "--mutants",
            "20",
            "--cycles",
            "20000",
            "--out",
            str(out),
            "--quiet",
        ],
        capsys,
    )
    assert code == 0
    result = json.loads((out / "mutants.json").read_text())
    caught = sum(m["unit"]["caught"] for m in result["mutants"])
    assert result["unit"] == {
        "total": 20,
        "caught": caught,
        "equivalent": 20 - caught,
        "score": caught / 20,
    }
    assert result["design"]["params"] == {"clock_hz": 100000}
    lines = text.splitlines()
    assert lines[0].startswith("20 mutants of WallStop (seed 1), 20000 cycles of random inputs")
    assert lines[1] == (
        f"unit judge (against the unmutated design): {caught} caught, "
        f"{20 - caught} equivalent on these inputs: score "
        f"{100 * caught / 20:.1f}%"
    )
    assert {m["module"] or "top" for m in result["mutants"]} <= {"top", "us"}


@pytest.mark.slow  # a Verilator build of the mutant netlist, closed-loop runs of its mutants
def test_robot_judge_of_a_users_design_matches_its_runs(tmp_path, capsys):
    """``mutate --design REF --campaign C``: each unit-caught mutant of WallStop runs the
    campaign in closed loop; its verdict must be the one its replayed run gives, and the
    unmutated design (``mutsel = 0``) passes the same run."""
    from fpga_robotics.sweep import runner

    campaign = tmp_path / "wall.toml"
    campaign.write_text(
        f'description = "wall_stop at its wall"\nscenarios = ["{DESIGNS}/wall_stop.toml"]\n'
        'seeds = "0"\nbackend = "auto"\n'
    )
    out = tmp_path / "m"
    code, text, _ = _cli(
        [
            "mutate",
            "--design",
            f"{DESIGNS}/wall_stop.py:WallStop",
            "--mutants",
            "8",
            "--cycles",
            "20000",
            "--campaign",
            str(campaign),
            "--workers",
            "1",
            "--out",
            str(out),
            "--quiet",
        ],
        capsys,
    )
    assert code == 0
    result = json.loads((out / "mutants.json").read_text())
    assert result["baseline"]["statuses"] == ["pass"]
    unit_caught = {m["index"] for m in result["mutants"] if m["unit"]["caught"]}
    judged = {m["index"]: m["robot"] for m in result["mutants"] if m["robot"] is not None}
    assert set(judged) == unit_caught and unit_caught
    robot_caught = sum(v["caught"] for v in judged.values())
    assert result["robot"] == {
        "judged": len(judged),
        "caught": robot_caught,
        "score": robot_caught / len(judged),
    }
    assert f"{robot_caught} of {len(judged)} unit-caught mutants caught" in text
    # Each blind spot says why, from its unit data: the share of the cycles it differs in.
    for m in result["mutants"]:
        if m["robot"] is not None and not m["robot"]["caught"]:
            share = 100 * m["unit"]["cycles_differing"] / 20000
            cls = m["blind_spot_reason"].split(":")[0]
            assert cls in ("recorded only", "rare state", "other")
            assert share <= 5 if cls == "rare state" else cls == "recorded only" or share > 5
        else:
            assert m["blind_spot_reason"] is None
    # The runs again, one by one, outside the judge: the same verdicts.
    base = runner.execute(result["baseline"]["runs"][0])
    assert base["status"] == "pass"
    for index, v in judged.items():
        if v["status"] == "timeout":  # a mutant that slows the loop down: caught by its time
            continue
        again = runner.execute(v["argv"])
        assert again["status"] == v["status"], index
        assert [c["name"] for c in again["summary"]["checks"] if c["passed"] is False] == (
            v["failed_checks"]
        )
    # A mutant that stops WallStop from ever stopping is caught: it drives into the wall.
    never_stops = [
        m
        for m in result["mutants"]
        if m["unit"]["caught"] and m["unit"]["effect"].count("stopped 1 -> 0")
    ]
    for m in never_stops:
        assert judged[m["index"]]["failed_checks"] == ["max_wall_collisions"]


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--design", "verilog:x.v"], "no file 'x.v'"),
        (["--design", "bump_stop_noreset.v"], "unknown design 'bump_stop_noreset.v'"),
        (
            ["--design", "verilog:bump_stop_noreset.v"],
            "needs its port map: --ports PORTS.toml",
        ),
        (["--design", "wall_stop.py:WallStop", "--ports", "x.toml"], "--ports is the port map"),
        (
            ["--design", "wall_stop.py:WallStop", "--campaign", "nosuch"],
            "unknown campaign 'nosuch'",
        ),
        (["--design", "wall_stop.py:WallStop", "--param", "nope"], "--param must be NAME=VALUE"),
        (
            ["--cycles", "5"],
            "--param, --define, --ports, --cycles and --resolution go with --design REF",
        ),
        (
            ["--design", "follow_target", "--param", "x=1"],
            "not FollowTarget (the default, and --design follow_target)",
        ),
        (
            ["--design", "wall_stop.py:WallStop", "--width", "80", "--kp-num", "5"],
            "--width, --kp-num: FollowTarget's options",
        ),
        (["--design", "wall_stop.py:WallStop", "--against", "model"], "--against: FollowTarget"),
        (["--design", "wall_stop.py:WallStop", "--preset", "published"], "--preset: FollowTarget"),
        (
            ["--design", "wall_stop.py:WallStop", "--resolution", "40"],
            "--resolution must be WIDTHxHEIGHT such as 160x120, got '40'",
        ),
    ],
)
def test_bad_design_arguments_are_one_line(argv, message, capsys, monkeypatch):
    monkeypatch.chdir(DESIGNS)
    code, _, err = _cli(["mutate", *argv], capsys)
    assert code == 2 and message in err and err.count("\n") == 1


@pytest.mark.slow  # a Verilator build of FollowTarget's mutant netlist
def test_follow_target_against_itself_scores_as_against_the_model(tmp_path, capsys):
    # The unmutated design gives the golden model's results on the unit frames, so each
    # mutant's verdict is the same whichever it is compared with.
    runs = {}
    for against in ("model", "design"):
        out = tmp_path / against
        code, text, _ = _cli(
            [
                "mutate",
                "--mutants",
                "12",
                "--width",
                "80",
                "--height",
                "60",
                "--quiet",
                "--against",
                against,
                "--out",
                str(out),
            ],
            capsys,
        )
        assert code == 0
        runs[against] = json.loads((out / "mutants.json").read_text())
        assert runs[against]["against"] == against
    assert "unit judge (against the unmutated design): " in text
    assert [m["unit"] for m in runs["model"]["mutants"]] == [
        m["unit"] for m in runs["design"]["mutants"]
    ]
    assert runs["model"]["unit"] == runs["design"]["unit"]


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_design_with_only_wheels_is_mutated(tmp_path, capsys):
    # Toggler has neither a camera nor a connector: its mutant netlist's port map binds the
    # wheels alone. It drives 200 and 400 DPS in turn, so a wheel bit's mutant is caught
    # exactly when it changes the bit in one of them (an inverted bit always does).
    out = tmp_path / "m"
    argv = ["mutate", "--design", f"{DESIGNS}/toggler.py:Toggler", "--mutants", "6"]
    code, _, err = _cli([*argv, "--cycles", "200", "--out", str(out), "--quiet"], capsys)
    assert code == 0, err
    result = json.loads((out / "mutants.json").read_text())
    assert result["unit"]["total"] == 6
    on_wheels = [m for m in result["mutants"] if m["signal"] in ("motor_left", "motor_right")]
    assert on_wheels
    for m in on_wheels:
        bits = [(value >> m["bit"]) & 1 for value in (200, 400)]
        expected = {"inv": True, "const0": 1 in bits, "const1": 0 in bits}[m["mode"]]
        assert m["unit"]["caught"] == expected, m["describe"]


def bump_stop_trace(stimulus, cycles):
    """tests/data/bump_stop.v by hand: ``hit`` latches at the first edge ``bump_i`` is 1; the
    wheels run at 300 DPS until then, 0 after (``{output: [(cycle, value), ...]}``)."""
    levels = {}
    for edge, name, value in stimulus:
        if name == "bump_i":
            levels[edge] = value
    hit_at, level = None, 0
    for edge in range(1, cycles + 1):
        level = levels.get(edge, level)
        if level:
            hit_at = edge
            break
    trace = {"motor_left": [(0, 300)], "motor_right": [(0, 300)]}
    if hit_at is not None:
        trace["motor_left"].append((hit_at, 0))
        trace["motor_right"].append((hit_at, 0))
    return trace


@pytest.mark.slow  # Verilator builds of the Verilog design's mutant netlist
def test_mutants_of_a_verilog_design_against_a_hand_model(tmp_path, capsys):
    """``mutate --design verilog:FILE --ports MAP``: Yosys reads the Verilog, the unmutated
    netlist (``mutsel = 0``) behaves as the hand model of bump_stop.v, and a mutant is caught
    exactly when its outputs differ from the model's."""
    from fpga_robotics.designs.builtin import connector_kinds
    from fpga_robotics.sim.backends.foreign import ForeignDesign
    from fpga_robotics.sim.pins.compiled import VerilatorPins
    from fpga_robotics.sim.pins.verilog import VerilogPinSource

    data = Path(__file__).parent / "data"
    out, cycles = tmp_path / "m", 2000
    code, text, _ = _cli(
        [
            "mutate",
            "--design",
            f"verilog:{data / 'bump_stop.v'}",
            "--port-map",
            str(data / "bump_stop_ports.toml"),
            "--mutants",
            "10",
            "--cycles",
            str(cycles),
            "--out",
            str(out),
            "--quiet",
        ],
        capsys,
    )
    assert code == 0
    result = json.loads((out / "mutants.json").read_text())
    assert text.splitlines()[0].startswith("10 mutants of bump_stop (seed 1)")
    source = VerilogPinSource(
        ForeignDesign(
            [out / "mutants.v"],
            out / "mutants_ports.toml",
            pins=True,
            connector_kinds=connector_kinds(),
        )
    )
    backend = VerilatorPins(source)
    try:
        ports = {p: port for p, port in backend.ports.items() if p in ("bump_i", "mutsel")}
        stimulus = pin_stimulus(ports, cycles, 0)
        outputs = ["motor_left", "motor_right"]  # hit_o: no output of the port map
        model = bump_stop_trace(stimulus, cycles)
        assert pin_trace(backend, 0, stimulus, cycles, outputs) == model
        for m in result["mutants"]:
            got = pin_trace(backend, m["index"], stimulus, cycles, outputs)
            assert m["unit"]["caught"] == (got != model), m["describe"]
    finally:
        backend.close()


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_verilog_design_that_includes_a_header_is_mutated(tmp_path, capsys):
    """Yosys reads red_count.v with the header it `include`s next to it: the header's
    `define values reach the mutant netlist and the mutants are red_count.v's."""
    data = Path(__file__).parent / "data" / "red_count"
    out = tmp_path / "m"
    argv = ["--design", f"verilog:{data / 'red_count.v'}", "--ports"]
    argv += [str(data / "red_count_ports.toml"), "--mutants", "3", "--cycles", "2000"]
    code, text, _ = _cli(["mutate", *argv, "--out", str(out), "--quiet"], capsys)
    assert code == 0
    assert text.splitlines()[0].startswith("3 mutants of red_count (seed 1)")
    netlist = (out / "mutants.v").read_text()
    # `SPEED (16'sd200) and `MIN_PIXELS (17'd20) from red_count_defs.vh
    assert "16'h00c8" in netlist and "17'h00014" in netlist
    result = json.loads((out / "mutants.json").read_text())
    assert len(result["mutants"]) == 3
    assert all("red_count.v:" in m["describe"] for m in result["mutants"])


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_bom_port_map_and_a_latin1_verilog_file_are_mutated(tmp_path, capsys):
    """A port map saved with a UTF-8 byte-order mark (Windows editors) and Verilog with a
    Latin-1 comment are read as Yosys reads them; the copied map has no mark."""
    data = Path(__file__).parent / "data"
    ports, verilog = tmp_path / "ports.toml", tmp_path / "bump_stop.v"
    ports.write_bytes(b"\xef\xbb\xbf" + (data / "bump_stop_ports.toml").read_bytes())
    verilog.write_bytes(b"// (c) caf\xe9\n" + (data / "bump_stop.v").read_bytes())
    out = tmp_path / "m"
    argv = ["--design", f"verilog:{verilog}", "--ports", str(ports), "--mutants", "2"]
    code, _, err = _cli(["mutate", *argv, "--cycles", "500", "--out", str(out)], capsys)
    assert code == 0, err
    assert len(json.loads((out / "mutants.json").read_text())["mutants"]) == 2
    assert not (out / "mutants_ports.toml").read_bytes().startswith(b"\xef\xbb\xbf")


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_verilog_camera_design_s_unit_judge_streams_frames(tmp_path, capsys):
    """red_count.v counts a frame's red pixels at the last pixel of its 120th line: only a
    stream framed as the camera frames it (first, last of each line) ever gives it a count.
    Its unmutated netlist drives on from the end of the first frame, as counted by hand."""
    from fpga_robotics.designs.builtin import connector_kinds
    from fpga_robotics.sim.backends.foreign import ForeignDesign
    from fpga_robotics.sim.pins.compiled import VerilatorPins
    from fpga_robotics.sim.pins.verilog import VerilogPinSource

    data = Path(__file__).parent / "data" / "red_count"
    out, cycles, (width, height) = tmp_path / "m", 3000, (8, 120)
    argv = ["--design", f"verilog:{data / 'red_count.v'}", "--ports"]
    argv += [str(data / "red_count_ports.toml"), "--mutants", "8", "--cycles", str(cycles)]
    argv += ["--resolution", f"{width}x{height}", "--out", str(out), "--quiet"]
    code, _, _ = _cli(["mutate", *argv], capsys)
    assert code == 0
    result = json.loads((out / "mutants.json").read_text())
    assert result["stimulus"]["frame"] == [width, height]
    assert {"pixels__valid", "pixels__payload"} <= set(result["stimulus"]["inputs"])
    source = VerilogPinSource(
        ForeignDesign(
            [out / "mutants.v"], out / "mutants_ports.toml", pins=True,
            connector_kinds=connector_kinds(),
        ),
        stream=False,
    )  # fmt: skip
    backend = VerilatorPins(source)
    try:
        ports = {p: port for p, port in backend.ports.items() if p != "mutsel"}
        stimulus = pin_stimulus(ports, cycles, 0, (width, height))
        # The first frame's pixels are edges 1 .. W*H; red: the red nibble at least 8.
        last = width * height
        first_frame = [v for e, p, v in stimulus if p == "pixels__payload" and e <= last]
        red = sum((v >> 8) & 0xF >= 8 for v in first_frame)
        assert len(first_frame) == last and red > 20  # MIN_PIXELS
        model = {name: [(0, 0), (last, 200)] for name in ("motor_left", "motor_right")}
        assert pin_trace(backend, 0, stimulus, cycles, list(model)) == model
        for m in result["mutants"]:
            got = pin_trace(backend, m["index"], stimulus, cycles, list(model))
            assert m["unit"]["caught"] == (got != model), m["describe"]
    finally:
        backend.close()


@pytest.mark.slow  # a Verilator build of the mutant netlist, closed-loop runs of its mutants
def test_robot_judge_of_a_camera_design(tmp_path, capsys):
    """``mutate --design REF --campaign C`` of NearRed, a camera design of one's own: the
    mutants run the campaign in closed loop on rendered frames; a verdict is the one the
    replayed run gives, and a mutant that never drives fails the distance check."""
    from fpga_robotics.sweep import runner

    for name in ("near_red.py", "near_red.toml"):
        (tmp_path / name).write_text((DESIGNS / name).read_text())
    # Unmutated, NearRed closes in to a mean 1.6 m; standing at its start, 2.5 m.
    with open(tmp_path / "near_red.toml", "a") as f:
        f.write("mean_distance_max_m = 2.0\n")
    campaign = tmp_path / "near.toml"
    campaign.write_text(
        'description = "near_red closing in"\nscenarios = ["near_red.toml"]\nseeds = "0"\n'
        'backend = "auto"\n'
    )
    out = tmp_path / "m"
    argv = ["mutate", "--design", f"{tmp_path}/near_red.py:NearRed", "--param", "speed=400"]
    argv += ["--param", "near_pixels=300", "--mutants", "3", "--cycles", "20000"]
    argv += ["--campaign", str(campaign), "--workers", "1", "--out", str(out), "--quiet"]
    code, text, _ = _cli(argv, capsys)
    assert code == 0
    result = json.loads((out / "mutants.json").read_text())
    assert result["baseline"]["statuses"] == ["pass"]
    unit_caught = {m["index"] for m in result["mutants"] if m["unit"]["caught"]}
    judged = {m["index"]: m["robot"] for m in result["mutants"] if m["robot"] is not None}
    assert set(judged) == unit_caught and unit_caught
    robot_caught = sum(v["caught"] for v in judged.values())
    assert f"{robot_caught} of {len(judged)} unit-caught mutants caught" in text
    for index, v in judged.items():
        again = runner.execute(v["argv"])
        assert again["status"] == v["status"], index

    # A mutant whose frame count comes out 2048 or more above the design's (seed 1's third:
    # bit 11 of the count's sum stuck at 1) is near from its first frame on (near_pixels
    # 300), so the robot never drives: it stays 2.5 m away.
    def count_raised(effect):
        found = re.search(r"red_count (\d+) -> (\d+)", effect)
        return found is not None and int(found[2]) - int(found[1]) >= 2048

    never_drives = [
        m for m in result["mutants"] if m["unit"]["caught"] and count_raised(m["unit"]["effect"])
    ]
    assert never_drives
    for m in never_drives:
        assert judged[m["index"]]["failed_checks"] == ["mean_distance_max_m"]


@pytest.mark.slow  # a Verilator build of the mutant netlist, closed-loop runs of its mutants
def test_a_design_s_blind_spots_are_recorded_and_reported(tmp_path, capsys):
    """``mutate --design verilog:... --campaign C --recordings 1``, as FollowTarget's: the
    closest run of the first blind spot is recorded, report.html lists every blind spot. In
    3 s the robot never reaches the wall, so every unit-caught mutant is a blind spot. The
    unit judge of 100 cycles takes far under 0.01 s: its rate is still the mutants over its
    time, at least the mutants over the whole command's."""
    import time

    from bump_mutate import DATA, mutate_bump_stop

    campaign = tmp_path / "bump.toml"
    campaign.write_text(f'scenarios = ["{DATA / "bump_wall.toml"}"]\nseeds = "0"\nduration = 3.0\n')
    out = tmp_path / "m"
    more = ["--mutants", "6", "--cycles", "100", "--campaign", str(campaign), "--workers", "1"]
    t0 = time.perf_counter()
    code, text, _ = mutate_bump_stop(out, capsys, *more, "--recordings", "1")
    elapsed = time.perf_counter() - t0
    assert code == 0
    rate = int(re.search(r"unit judge (\d+) mutants/min", text)[1])
    assert rate >= 60 * 6 / elapsed
    result = json.loads((out / "mutants.json").read_text())
    blind = [m for m in result["mutants"] if m["robot"] and not m["robot"]["caught"]]
    assert len(blind) >= 2 and len(blind) == result["robot"]["judged"]
    first = f"recordings/mutant{blind[0]['index']}.rrd"
    assert [p.name for p in (out / "recordings").iterdir()] == [Path(first).name]
    assert (out / first).stat().st_size > 0
    assert text.count("  (recording ") == 1 and f"(recording {first})" in text
    assert f"report: {out / 'report.html'}" in text
    page = (out / "report.html").read_text()
    assert "Mutation coverage of bump_stop" in page and f'<a href="{first}">' in page
    for m in blind:
        assert html.escape(m["describe"]) in page and html.escape(m["unit"]["effect"]) in page


@pytest.mark.parametrize(
    "campaign, message",
    [
        ('scenarios = ["nowhere.toml"]', "scenario file 'nowhere.toml' does not exist"),
        (
            'scenarios = ["wall_stop.toml"]\n[grid]\n"robot.mas" = [1.0]',
            "robot.mas is not a known key (did you mean 'mass'?)",
        ),
        (
            'scenarios = ["wall_stop.toml"]\nset = ["design.params.speed=100"]',
            "may not override design.* values",
        ),
        ('scenarios = ["wall_stop.toml"]\ndesign = "wall_stop.py:WallStop"', "may not give design"),
        ('scenarios = ["wall_stop.toml"]\nbackend = "pysim"', "backend 'pysim'"),
    ],
)
def test_a_campaign_the_robot_judge_cannot_run_is_refused_first(
    campaign, message, tmp_path, capsys, monkeypatch
):
    # Checked before the netlist is built or the output folder made: one line, nothing written.
    for name in ("wall_stop.py", "wall_stop.toml"):
        (tmp_path / name).write_text((DESIGNS / name).read_text())
    (tmp_path / "c.toml").write_text(campaign + "\n")
    monkeypatch.chdir(tmp_path)
    argv = ["mutate", "--design", "wall_stop.py:WallStop", "--campaign", "c.toml"]
    code, _, err = _cli([*argv, "--out", "m"], capsys)
    assert code == 2 and message in err and err.count("\n") == 1, err
    assert not (tmp_path / "m").exists()


class _Histogram(wiring.Component):
    """A memory with initial data, written every cycle and read combinationally: Yosys's
    ``mutate -list`` names places on its constant ports (the initial data, the read port's
    reset), where no mutant can be built."""

    x: In(4)
    y: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.submodules.mem = mem = Memory(shape=8, depth=4, init=[3, 1, 4, 1])
        wp, rp = mem.write_port(), mem.read_port(domain="comb")
        m.d.comb += [wp.addr.eq(self.x[:2]), wp.data.eq(self.x), wp.en.eq(self.x[3])]
        m.d.comb += rp.addr.eq(self.x[2:])
        m.d.sync += self.y.eq(rp.data + self.x)
        return m


@pytest.mark.slow
def test_mutants_on_a_memorys_constant_ports_are_replaced():
    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.sim.mutation import (
        _CLOCK_PORTS,
        MutationError,
        _builds,
        _mutate_list,
        _parse,
        mutant_netlist,
    )

    design = {
        "rtlil_text": component_rtlil(_Histogram()),
        "verilog": None,
        "top": "follow_target",
        "includes": None,
        "overrides": None,
    }
    params = FollowTargetParams()
    # The first seed whose raw list holds a mutant Yosys cannot build (there is one).
    for seed in range(1, 20):
        lines, memories, _ = _mutate_list(params, 12, seed, design)
        on_memories = [line for line in lines if any(f"-cell {c} " in line for c in memories)]
        bad = [line for line in on_memories if not _builds(params, [line], design)]
        if bad:
            break
    else:
        pytest.fail("no seed lists a mutant on the memory's constant ports")
    with pytest.raises(MutationError):  # the raw list, as mutate took it before
        mutant_netlist(params, [_parse(1, bad[0])], **design)
    mutants = list_mutants(params, 12, seed, rtlil_text=design["rtlil_text"])
    commands = [m.command for m in mutants]
    assert len(mutants) == 12 and [m.index for m in mutants] == list(range(1, 13))
    assert not set(bad) & set(commands)
    # The buildable ones of the raw list keep their order (places on a clock input are never
    # kept); the rest come after.
    good = [line for line in lines if line not in bad and _parse(0, line).port not in _CLOCK_PORTS]
    assert commands[: len(good)] == good
    mutant_netlist(params, mutants, **design)  # every mutant together builds
    again = list_mutants(params, 12, seed, rtlil_text=design["rtlil_text"])
    assert again == mutants  # the same arguments, the same list


FB_COUNT_V = """\
// Framebuffer style: counts the red pixels written; at each new frame, motor_left = 16 * count.
module fb_count (input clk, input we, input [5:0] addr, input [11:0] data, input nf,
                 output reg [15:0] ml = 16'd0, output reg [15:0] mr = 16'd0,
                 output reg done = 1'b0);
  reg [5:0] n = 6'd0;
  wire red = we && data[11:8] >= 4'd8;
  always @(posedge clk) begin
    done <= nf;
    if (nf) begin
      ml <= {6'd0, n, 4'd0};
      mr <= 16'd100;
      n <= red ? 6'd1 : 6'd0;
    end else if (red)
      n <= n + 6'd1;
  end
endmodule
"""
FB_COUNT_MAP = """\
style = "framebuffer"
top = "fb_count"
clock = { port = "clk" }
pixels = { write_enable = "we", address = "addr", data = "data", new_frame = "nf" }
result = { strobe = "done", latency = 1, timeout = 1000 }
[outputs]
motor_left = { port = "ml", width = 16 }
motor_right = { port = "mr", width = 16 }
"""


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_framebuffer_design_is_mutated_at_its_own_frame_size(tmp_path, capsys):
    """A 6-bit address (48 pixels: the 8x6 frames asked for, not 160x120's 19,200): the
    wrapper addresses and ends the frames at the size given. Before, the port map was checked
    at 160x120 (refused), and with a wider address no frame ever ended in the unit judge."""
    from fpga_robotics.designs.builtin import connector_kinds
    from fpga_robotics.sim.backends.foreign import ForeignDesign
    from fpga_robotics.sim.pins.compiled import VerilatorPins
    from fpga_robotics.sim.pins.verilog import VerilogPinSource

    (tmp_path / "fb_count.v").write_text(FB_COUNT_V)
    (tmp_path / "fb_count.toml").write_text(FB_COUNT_MAP)
    out, cycles, (width, height) = tmp_path / "m", 400, (8, 6)
    argv = ["mutate", "--design", f"verilog:{tmp_path / 'fb_count.v'}", "--ports"]
    argv += [str(tmp_path / "fb_count.toml"), "--mutants", "6", "--seed", "3"]
    argv += ["--cycles", str(cycles), "--resolution", f"{width}x{height}"]
    code, text, err = _cli([*argv, "--out", str(out)], capsys)
    assert code == 0, err
    # Its frames ended in the unit judge: no "nothing changed" note.
    assert "no output of the unmutated design changed" not in text
    result = json.loads((out / "mutants.json").read_text())
    assert result["stimulus"]["outputs_changed"] is True
    assert result["stimulus"]["frame"] == [width, height]
    design = ForeignDesign(
        [out / "mutants.v"], out / "mutants_ports.toml", pins=True,
        connector_kinds=connector_kinds(), frame_size=(width, height),
    )  # fmt: skip
    backend = VerilatorPins(VerilogPinSource(design, stream=False))
    try:
        ports = {p: port for p, port in backend.ports.items() if p != "mutsel"}
        stimulus = pin_stimulus(ports, cycles, 0, (width, height))
        pixels = [v for _, p, v in sorted(stimulus) if p == "pixels__payload"]
        frames = len(pixels) // (width * height)
        assert frames >= 2
        # Each whole frame's count of red pixels (red nibble >= 8), shown as 16 * count.
        counts = [
            sum((v >> 8) & 0xF >= 8 for v in pixels[k * width * height : (k + 1) * width * height])
            for k in range(frames)
        ]
        trace = pin_trace(backend, 0, stimulus, cycles, ["motor_left"])["motor_left"]
        shown = [value for _, value in trace]
        expected = [0]
        for count in counts:
            if 16 * count != expected[-1]:
                expected.append(16 * count)
        assert shown[: len(expected)] == expected
    finally:
        backend.close()


@pytest.mark.slow  # a Verilator build of the mutant netlist
def test_a_stimulus_that_changes_no_output_is_said(tmp_path, capsys):
    (tmp_path / "fb_count.v").write_text(FB_COUNT_V)
    (tmp_path / "fb_count.toml").write_text(FB_COUNT_MAP)
    # Frames of 8x8 = 64 pixels, a pixel a cycle: 40 cycles end none, so no output changes.
    argv = ["mutate", "--design", f"verilog:{tmp_path / 'fb_count.v'}", "--ports"]
    argv += [str(tmp_path / "fb_count.toml"), "--mutants", "4", "--cycles", "40"]
    argv += ["--resolution", "8x8", "--out", str(tmp_path / "m")]
    code, out, err = _cli(argv, capsys)
    assert code == 0, err
    assert "note: no output of the unmutated design changed in the 40 cycles" in out
    result = json.loads((tmp_path / "m" / "mutants.json").read_text())
    assert result["stimulus"]["outputs_changed"] is False
