"""A campaign of a foreign Verilog design (issue 14): the rows come from the same runs as
``run --design verilog:... --ports ...``, outputs the port map leaves out are absent (None and
``absent_outputs``), not 0, and the replay command reproduces the row."""

import json
import shlex
import subprocess
import sys

import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.sim.backends import available_backends
from fpga_robotics.sim.backends.port_map import follow_target_port_map
from fpga_robotics.sweep import load_campaign, run_campaign

pytestmark = pytest.mark.skipif(
    "verilator" not in available_backends(), reason="no Verilator toolchain"
)


@pytest.mark.slow
def test_a_foreign_design_without_found_in_a_campaign(tmp_path):
    params = FollowTargetParams(width=80, height=60)
    (tmp_path / "ft.v").write_text(generate_verilog(params))
    keep = [
        line
        for line in follow_target_port_map(params).splitlines()
        if not line.startswith(("found", "centroid", "filtered"))
    ]
    (tmp_path / "ft.toml").write_text("\n".join(keep) + "\n")
    campaign = load_campaign(
        {
            "scenarios": ["follow_person"],
            "seeds": "0-1",
            "resolution": "80x60",
            "duration": 1.0,
            "design": f"verilog:{tmp_path / 'ft.v'}",
            "ports": str(tmp_path / "ft.toml"),
        }
    )
    rows = run_campaign(campaign, tmp_path / "out", workers=1, record="none")
    assert sorted(r["seed"] for r in rows) == [0, 1]
    for row in rows:
        # backend auto: CXXRTL, which reads this Verilog (sim/backends/foreign_choice.py).
        assert row["backend"] == "cxxrtl-foreign"
        assert json.loads(row["absent_outputs"]) == ["found", "centroid_x", "centroid_leds"]
        assert row["found_fraction"] is None and row["acquired_at_s"] is None
        assert row["check_acquired_within_s"] is None  # not measured, not failed
        # The replay command is the same run.
        argv = shlex.split(row["replay"])
        summary = tmp_path / f"replay{row['seed']}.json"
        done = subprocess.run(
            [sys.executable, *argv[1:], "--rerun", "off", "--quiet", "--summary", str(summary)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        assert done.returncode in (0, 1), done.stderr
        replayed = json.loads(summary.read_text())
        for key in (
            "frames",
            "min_distance_m",
            "mean_distance_m",
            "path_length_m",
            "verdict",
            "absent_outputs",
            "found_fraction",
        ):
            want = json.loads(row[key]) if key == "absent_outputs" else row[key]
            assert replayed[key] == want, key
