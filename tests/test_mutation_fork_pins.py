"""The robot judge's forked runs in real-clock timing: a Verilog design's mutants forked from
the unmutated netlist's run (``PinReferenceRun``) give their full runs' summaries, and a
mutant whose watch bit never rose there (it never acted) is given that run without its design
being run."""

import pytest
from bump_mutate import DATA, mutate_bump_stop
from run_equality import TIMING_FIELDS

from fpga_robotics.mutation import forked_runs
from fpga_robotics.mutation.design import PORTS_NAME, WATCH_PORTS_NAME
from fpga_robotics.mutation.forked_runs import execute_forked, reference_share
from fpga_robotics.mutation.robot_judge import mutant_argv
from fpga_robotics.sweep import runner


def _without_timing(summary):
    return {k: v for k, v in summary.items() if k not in TIMING_FIELDS}


@pytest.mark.slow  # Verilator builds of the mutant netlist (its map, and with its watch)
def test_pin_mutants_forked_with_the_watch_equal_their_full_runs(tmp_path, capsys):
    out = tmp_path / "m"
    code, _, err = mutate_bump_stop(out, capsys, "--mutants", "12")
    assert code == 0, err
    netlist, ports, watched = out / "mutants.v", out / PORTS_NAME, out / WATCH_PORTS_NAME
    # 3 s: the robot drives 0.5 m of the 1.5 m to the wall, so the bumper never closes and
    # the mutants of the stop path (bump_i, hit) never act; those of the speeds do.
    run = ["--scenario", str(DATA / "bump_wall.toml"), "--seed", "0", "--set", "sim.duration=3"]
    ref_argv = mutant_argv(run, netlist, watched, 0, None)
    forked_runs._references.clear()
    shared = reference_share(ref_argv)
    assert shared["outcome"]["status"] == "pass", shared["outcome"]["message"]
    ran = {True: 0, False: 0}
    for k in range(1, 13):
        argv = mutant_argv(run, netlist, ports, k, None)
        full = runner.execute(argv)
        forked = execute_forked(argv, ref_argv, shared=shared, watch_bit=k - 1)
        assert (forked["status"], forked["message"]) == (full["status"], full["message"]), k
        assert _without_timing(forked["summary"]) == _without_timing(full["summary"]), k
        design_ran = forked["fork"]["design_ran"]
        ran[design_ran] += 1
        if not design_ran:  # never acted: the unmutated run's world and outputs throughout
            assert forked["fork"]["parted_at"] is None
            reference = shared["outcome"]["summary"]
            assert _without_timing(full["summary"]) == _without_timing(reference), k
    forked_runs._references.clear()
    assert ran[True] and ran[False], ran  # both ways compared
